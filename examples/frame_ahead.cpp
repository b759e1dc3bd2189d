// A game's frame loop with the host Caster: each frame submits its rays and
// collects the previous frame's hits, which are ready by then. The CPU
// backend here; Backend::Vulkan or Automatic put big batches on the GPU.
#include <meshcast/meshcast.h>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  // A single large triangle in the plane z = 0 (one far from the origin
  // would do the same).
  const std::vector<float> xyz = {-100, -100, 0, 100, -100, 0, 0, 100, 0};
  const std::vector<uint32_t> indices = {0, 1, 2};
  const meshcast::MeshView mesh(xyz, 3, indices);

  try {
    const std::vector<uint8_t> blob = meshcast::build_blob(mesh, {}, "level");
    meshcast::host::CasterOptions options;
    options.backend = meshcast::host::Backend::Cpu;
    options.frames = 2;
    meshcast::host::Caster caster(blob, "level", options);  // reads `blob`, which outlives it

    std::vector<meshcast::Ray> rays(1000);
    std::vector<meshcast::Hit> hits(rays.size());
    meshcast::host::Ticket in_flight{};
    bool pending = false;
    int wrong = 0;
    for (int frame = 0; frame < 10; ++frame) {
      if (pending) {  // last frame's batch: its rays started at height frame
        caster.wait(in_flight, hits);
        for (const meshcast::Hit& h : hits) wrong += h.triangle != 0 || std::fabs(h.t - float(frame)) > 1e-4f;
      }
      for (size_t i = 0; i < rays.size(); ++i)  // this frame's rays, from height frame + 1 straight down
        rays[i] = {{float(i % 40) - 20, float(i / 40) - 20, float(frame + 1)}, {0, 0, -1}, INFINITY};
      in_flight = caster.submit(rays);  // copies the rays, returns at once
      pending = true;
    }
    caster.wait(in_flight, hits);
    const meshcast::host::Percentiles p = caster.percentiles(meshcast::host::Backend::Cpu);
    std::printf("%s: %zu batches, median latency %.3f ms on %u CPU threads\n", wrong ? "WRONG" : "ok", p.batches,
                p.p50_ms, caster.cpu_threads());
    return wrong ? 1 : 0;
  } catch (const meshcast::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
