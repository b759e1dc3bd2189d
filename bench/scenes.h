// `meshcast bench scenes`: a generated level of placed copies of
// the test meshes, rotated, scaled and mirrored, spread over 10 km, beside
// Embree's instancing in one run: ns a ray (interleaved rounds, medians,
// one thread), bytes (blobs and top level against Embree's scenes and the
// meshes it keeps), the update a frame (moving instances and committing),
// and the same level moved 10^6 and 10^7 units from the origin, where each
// contender's answers are compared with its own at the origin.
#pragma once
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast::bench {

struct ScenesOptions {
  std::vector<size_t> counts = {1000, 10000};  // instances a level
  std::vector<double> offsets = {0, 1e6, 1e7};  // the level moved this far along every axis
  std::string layout = "OctTreeCompressed/ClusterBitPackSOA8";
  size_t rays = 100000;  // a round of 10,000 took 4-7 ms: one interruption moved its median
  uint32_t rounds = 5;
};

struct SceneRow {
  size_t instances = 0;
  double offset = 0;
  std::string contender;
  double ns_per_ray = 0;          // median of the rounds
  double bytes = 0;               // all included (meshcast: the blobs and Scene::top_level_bytes)
  double update_ms = 0;           // a tenth of the instances moved, then commit (median)
  double update_all_ms = 0;       // every instance moved, then commit (median)
  double hits = 0;                // fraction of rays that hit
  double same_as_origin = 0;      // fraction of rays answered as at the origin (same instance and triangle)
};

std::vector<SceneRow> bench_scenes(const std::vector<Mesh>& meshes, const ScenesOptions& options);

}  // namespace meshcast::bench
