// meshcast: build blobs, cast rays, inspect layouts, run the main job.
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "cpu/mesh.h"
#include "cpu/rays.h"
#include "gpu/vulkan.h"
#include "tools/commands.h"

int main(int argc, char** argv) {
  CLI::App app{"meshcast: closest-hit ray casts against static triangle meshes"};
  app.require_subcommand(1);
  meshcast::tools::add_trace(app);
  meshcast::tools::add_build(app);
  meshcast::tools::add_info(app);
  meshcast::tools::add_rays(app);
  meshcast::tools::add_demo(app);
  meshcast::tools::add_bench(app);
  meshcast::tools::add_render(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every refused option or value is the input's fault: 2.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const meshcast::InputError& e) {
    std::fprintf(stderr, "meshcast: %s\n", e.what());
    return 2;
  } catch (const meshcast::OutputError& e) {  // an output file not written (a full disk, no permission)
    std::fprintf(stderr, "meshcast: %s\n", e.what());
    return 4;
  } catch (const meshcast::gpu::GpuError& e) {  // no Vulkan, no such device: the CPU path still works
    std::fprintf(stderr, "meshcast: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "meshcast: %s\n", e.what());
    return 1;
  }
  // What was printed must have reached stdout (`info --json >/dev/full`).
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "meshcast: standard output: cannot write (%s)\n", std::strerror(errno));
    return 4;
  }
  return 0;
}
