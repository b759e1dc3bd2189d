// meshcast: build blobs, cast rays, inspect layouts, run the main job.
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "meshcast/mesh.h"
#include "check/ray_files.h"
#include "gpu/vulkan.h"
#include "tools/commands.h"
#include "tools/progress.h"

int main(int argc, char** argv) {
  CLI::App app{"meshcast: closest-hit ray casts against static triangle meshes"};
  app.require_subcommand(1);
  meshcast::tools::add_trace(app);
  meshcast::tools::add_build(app);
  meshcast::tools::add_info(app);
  meshcast::tools::add_layouts(app);
  meshcast::tools::add_rays(app);
  meshcast::tools::add_generate(app);
  meshcast::tools::add_demo(app);
  meshcast::tools::add_bench(app);
  meshcast::tools::add_render(app);
  meshcast::tools::add_distance(app);
  // Exit codes (README): 2 the input, 3 no Vulkan or no such device, 4 an
  // output not written, 1 anything else.
  auto report = [](const std::exception& e, int code) {
    meshcast::tools::end_command_progress();
    std::fprintf(stderr, "meshcast: %s\n", e.what());
    return code;
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    meshcast::tools::end_command_progress();
    // --help and --version exit 0; every refused option or value is the input's fault: 2.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const meshcast::InputError& e) {
    return report(e, 2);
  } catch (const meshcast::OutputError& e) {
    return report(e, 4);
  } catch (const meshcast::gpu::GpuError& e) {  // the CPU path still works
    return report(e, 3);
  } catch (const std::exception& e) {
    return report(e, 1);
  }
  meshcast::tools::end_command_progress();
  // What was printed must have reached stdout (`info --json >/dev/full`).
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "meshcast: standard output: cannot write (%s)\n", std::strerror(errno));
    return 4;
  }
  return 0;
}
