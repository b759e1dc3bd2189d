#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include "meshcast/build.h"
#include "meshcast/blob.h"
#include "bench/peer.h"
#include "check/generate.h"
#include "builder/layout_names.h"
#include "builder/ray_sets.h"
#include "meshcast/read.h"
using namespace meshcast;
int main(int argc, char** argv) {
  std::string in = argv[1];
  int rounds = atoi(argv[2]);
  std::string kind = argv[3];
  Query q = argc > 4 && std::string(argv[4]) == "any" ? Query::Any : Query::Closest;
  Mesh m = in == "terrain_2M" ? make_terrain(1024, 1024, 5) : in == "city_1M" ? make_city(1000000, 7) : read_mesh(in);
  std::vector<uint8_t> b = build_blob(m, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "m");
  uint8_t* al = (uint8_t*)std::aligned_alloc(64, (b.size() + 63) / 64 * 64); std::memcpy(al, b.data(), b.size());
  BlobView view(std::span<const uint8_t>(al, b.size()), "m");
  std::vector<Ray> rays = make_rays(m, parse_ray_kind(kind), 50000, 19);
  std::vector<Hit> h1(rays.size()), h2(rays.size()), h3(rays.size());
  auto peer = bench::make_embree(m, bench::EmbreeMode::Default, 1);
  std::vector<double> tq, tf, te;
  auto ns = [&](auto f) { auto t0 = std::chrono::steady_clock::now(); f(); return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / rays.size(); };
  for (int p = 0; p < rounds; ++p) {
    unsetenv("MC_FLOAT_NODES");
    tq.push_back(ns([&] { view.trace(rays, h1, HitOutputs::None, q, Cull::None); }));
    setenv("MC_FLOAT_NODES", "1", 1);
    tf.push_back(ns([&] { view.trace(rays, h2, HitOutputs::None, q, Cull::None); }));
    te.push_back(ns([&] { peer->trace(rays, h3, q); }));
  }
  auto med = [](std::vector<double> v) { std::sort(v.begin(), v.end()); return v[v.size() / 2]; };
  size_t same = 0; for (size_t i = 0; i < rays.size(); ++i) same += h1[i].triangle == h2[i].triangle;
  std::printf("%-12s %-7s %s quant %6.1f  float %6.1f  embree %6.1f   q/e %.2f f/e %.2f  same %zu/%zu\n", in.substr(in.rfind('/') + 1).c_str(), kind.c_str(), q == Query::Any ? "any" : "closest",
              med(tq), med(tf), med(te), med(tq) / med(te), med(tf) / med(te), same, rays.size());
}
