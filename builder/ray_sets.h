// Ray sets for measuring and checking: deterministic rays of four kinds
// around a mesh. The automatic layout times its candidates on them; the
// tests, benchmarks and the `meshcast rays` command cast them too.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "meshcast/mesh.h"
#include "meshcast/ray.h"

namespace meshcast {

enum class RayKind { Long, Probe, Radial, Segment };

// The kinds' names in RayKind's order: long, probe, radial, segment.
const std::vector<std::string>& ray_kind_names();
// Throws InputError for an unknown name, listing the valid ones.
RayKind parse_ray_kind(const std::string& name);

// Deterministic for a given mesh, kind, count and seed.
//  Long:   origins on a sphere around the mesh (radius = box diagonal) aimed at
//          random points inside its box; t_max infinite.
//  Probe:  short rays (t_max = 5% of the diagonal) from just off a random
//          point of a random triangle, in random directions.
//  Radial: from the centre of the box in random directions; t_max infinite.
//  Segment: line of sight between two points just off random points of
//          random triangles (as Probe's origins): the direction is the
//          second point less the first, t_max 1.
std::vector<Ray> make_rays(const Mesh& mesh, RayKind kind, size_t count, uint64_t seed);

// The same rays a part at a time: fill() writes the next rays of the set
// make_rays(mesh, kind, any count, seed) starts with, so a file of 2^27 rays
// is written a chunk at a time rather than held whole. Holds the mesh by
// reference.
class RaySource {
 public:
  RaySource(const Mesh& mesh, RayKind kind, uint64_t seed);
  void fill(std::span<Ray> rays);

 private:
  const Mesh& mesh_;
  RayKind kind_;
  uint64_t state_;
  Box3 box_;
  double diagonal_;
};

}  // namespace meshcast
