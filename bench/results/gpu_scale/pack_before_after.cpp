// The host's share of a GPU batch before and after the rays went to the
// device as written: the old pack_rays (a 64-byte record a ray, its shear
// and reciprocals computed on the host; built from the tree before the
// change by pack_before_after.sh) against the copy begin() makes now
// (32 bytes a ray) and open()'s none, on the same 1M rays, interleaved
// rounds, medians.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "gpu/rays.h"  // the old one

int main() {
  const size_t n = size_t(1) << 20;
  std::vector<meshcast::Ray> rays(n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  for (meshcast::Ray& r : rays) r = {{u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, 1e30f};
  std::vector<uint32_t> packed(n * meshcast::gpu::kRayWords);
  std::vector<meshcast::Ray> copied(n);
  std::vector<double> pack_ms, copy_ms;
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  for (int round = 0; round < 9; ++round) {
    auto t0 = std::chrono::steady_clock::now();
    volatile uint64_t skipped = meshcast::gpu::pack_rays(rays, packed.data());
    auto t1 = std::chrono::steady_clock::now();
    std::memcpy(copied.data(), rays.data(), n * sizeof(meshcast::Ray));
    auto t2 = std::chrono::steady_clock::now();
    (void)skipped;
    pack_ms.push_back(ms(t0, t1)), copy_ms.push_back(ms(t1, t2));
  }
  std::sort(pack_ms.begin(), pack_ms.end()), std::sort(copy_ms.begin(), copy_ms.end());
  std::printf("1M rays, median of 9 interleaved rounds, one thread\n"
              "| host step | ms | ns a ray | bytes a ray |\n|---|---:|---:|---:|\n"
              "| before: pack_rays | %.3f | %.2f | 64 |\n| now: begin()'s copy | %.3f | %.2f | 32 |\n"
              "| now: open(), written in place | 0 | 0 | 32 |\n",
              pack_ms[4], pack_ms[4] * 1e6 / double(n), copy_ms[4], copy_ms[4] * 1e6 / double(n));
}
