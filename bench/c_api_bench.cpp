// The C API's cost beside the C++ library's own calls, on one thread:
//   c_api_bench MESH [RAYS_A_SET] [ROUNDS]
// A batch of each ray kind cast by BlobView::trace and by
// meshcast_blob_cast on the same blob bytes and rays (interleaved rounds,
// the median of each), and a one-ray call of each in a loop, with a ray
// that misses the mesh's box (the call's own cost) and a long ray that
// hits. Prints a Markdown table, and writes the blob and the two rays
// (c_api_bench.blob, c_api_one_ray.rays) for the C# and Rust one-ray calls.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/timing.h"
#include "builder/ray_sets.h"
#include "meshcast/blob.h"
#include "meshcast/build.h"
#include "meshcast/meshcast_c.h"
#include "meshcast/read.h"

namespace {

// The seconds fn() takes.
template <class Fn>
double seconds(const Fn& fn) {
  const auto start = std::chrono::steady_clock::now();
  fn();
  return meshcast::bench::ms_since(start) / 1e3;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace meshcast;
  using bench::median;
  if (argc < 2) {
    std::fprintf(stderr, "usage: c_api_bench MESH [RAYS_A_SET] [ROUNDS]\n");
    return 2;
  }
  const size_t n = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 100000;
  const int rounds = argc > 3 ? std::atoi(argv[3]) : 11;
  const Mesh mesh = read_mesh(argv[1]);
  const std::vector<uint8_t> bytes = build_blob(mesh, BuildOptions{}, argv[1]);
  const BlobView view(bytes, argv[1]);
  meshcast_blob* blob = nullptr;
  if (meshcast_blob_from_memory(bytes.data(), bytes.size(), MESHCAST_MEMORY_BORROW, argv[1], &blob) != MESHCAST_OK) {
    std::fprintf(stderr, "%s\n", meshcast_last_error());
    return 1;
  }
  std::printf("%s, %zu triangles, %s; one thread, %zu rays a set, median of %d interleaved rounds\n\n", argv[1],
              mesh.triangles.size(), layout_name(view.layout()).c_str(), n, rounds);
  std::printf("| rays | C++ BlobView::trace ns/ray | C API meshcast_blob_cast ns/ray | C API / C++ |\n|---|---:|---:|---:|\n");
  for (const RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial, RayKind::Segment}) {
    const std::vector<Ray> rays = make_rays(mesh, kind, uint32_t(n), 1);
    std::vector<Hit> a(rays.size()), b(rays.size());
    std::vector<double> cpp, c;
    for (int r = 0; r < rounds; ++r) {
      const auto by_cpp = [&] { view.trace(rays, a); };
      const auto by_c = [&] {
        meshcast_blob_cast(blob, reinterpret_cast<const meshcast_ray*>(rays.data()), rays.size(), nullptr,
                           reinterpret_cast<meshcast_hit*>(b.data()), b.size(), nullptr);
      };
      if (r % 2) {
        cpp.push_back(seconds(by_cpp)), c.push_back(seconds(by_c));
      } else {
        c.push_back(seconds(by_c)), cpp.push_back(seconds(by_cpp));
      }
    }
    for (size_t i = 0; i < rays.size(); ++i)
      if (a[i].triangle != b[i].triangle || a[i].t != b[i].t) {
        std::fprintf(stderr, "ray %zu: the C API answers otherwise\n", i);
        return 1;
      }
    const double x = median(cpp) / double(n) * 1e9, y = median(c) / double(n) * 1e9;
    std::printf("| %s | %.1f | %.1f | %.3f |\n", ray_kind_names()[size_t(kind)].c_str(), x, y, y / x);
  }
  // One ray a call: a miss outside the mesh's box (the call alone), and a
  // long ray that hits.
  std::printf("\n| one ray a call | C++ ns/call | C API ns/call | C API - C++ ns |\n|---|---:|---:|---:|\n");
  const Box3 box = mesh.bounds();
  const Ray miss{{box.max.x + 1, box.max.y + 1, box.max.z + 1}, {1, 1, 1}, INFINITY};
  const Ray hit = make_rays(mesh, RayKind::Long, 1, 7)[0];
  for (const auto& [label, ray] : {std::pair<const char*, Ray>{"a miss outside the box", miss}, {"a long ray", hit}}) {
    const int calls = 200000;
    Hit h;
    std::vector<double> cpp, c;
    for (int r = 0; r < rounds; ++r) {
      cpp.push_back(seconds([&] {
        for (int i = 0; i < calls; ++i) view.trace({&ray, 1}, {&h, 1});
      }));
      c.push_back(seconds([&] {
        for (int i = 0; i < calls; ++i)
          meshcast_blob_cast(blob, reinterpret_cast<const meshcast_ray*>(&ray), 1, nullptr,
                             reinterpret_cast<meshcast_hit*>(&h), 1, nullptr);
      }));
    }
    const double x = median(cpp) / calls * 1e9, y = median(c) / calls * 1e9;
    std::printf("| %s | %.1f | %.1f | %.1f |\n", label, x, y, y - x);
  }
  // The blob and the two rays, for the same one-ray calls from C# and
  // Rust (their tests' bench modes): c_api_bench.blob, c_api_one_ray.rays.
  save_blob("c_api_bench.blob", bytes);
  FILE* f = std::fopen("c_api_one_ray.rays", "wb");
  const uint32_t two = 2;
  std::fwrite("RAYS", 1, 4, f);
  std::fwrite(&two, 4, 1, f);
  for (const Ray& r : {miss, hit}) {
    const float record[7] = {r.org[0], r.org[1], r.org[2], r.dir[0], r.dir[1], r.dir[2], r.tmax};
    std::fwrite(record, 4, 7, f);
  }
  std::fclose(f);
  meshcast_blob_release(blob);
  return 0;
}
