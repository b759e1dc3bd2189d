// `meshcast bench error`: error against run time. For every tree x
// encoding (and, with a Vulkan device, every GPU method) on each mesh: time a
// ray and bytes a triangle against the error measured against the
// double-precision oracle over the input mesh:
//   max and mean |dt| / diagonal   rays where both hit
//   surface error / diagonal       the walker's hit point from the input
//                                  triangle it names, less 4 ulps of t along
//                                  the ray (float t's own rounding): the
//                                  quantity a lossy format's stated bound
//                                  (displacement_bound) holds, since a point
//                                  of the stored triangle lies within the
//                                  corners' largest move of the input
//                                  triangle at the same barycentrics
//   false misses, false hits       the oracle hits and the walker does not,
//                                  and the other way round
//   wrong triangles                both hit, other triangles, |dt| beyond
//                                  1e-5 of the diagonal (not a tie)
#pragma once
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast::bench {

struct ErrorRow {
  std::string mesh, backend, layout;
  double us_per_ray = 0, bytes_per_tri = 0;
  double max_dt = 0, mean_dt = 0, max_surface = 0, bound = 0;  // relative to the diagonal
  uint64_t rays = 0, false_misses = 0, false_hits = 0, wrong_triangles = 0;
};

struct NamedInput {
  std::string name;
  Mesh mesh;
};

// `device`: "" for the CPU alone, else the Vulkan device to add the GPU
// methods on ("any" for the default choice).
std::vector<ErrorRow> bench_error(const std::vector<NamedInput>& meshes, size_t rays, uint32_t repeat,
                                  const std::string& device);

}  // namespace meshcast::bench
