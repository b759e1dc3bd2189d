// meshcast: build blobs, cast rays, inspect layouts, run the main job.
#include <cstdio>

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
    return app.exit(e);
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
  return 0;
}
