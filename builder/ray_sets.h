// Ray sets for measuring and checking: deterministic rays of three kinds
// around a mesh. The automatic layout times its candidates on them; the
// tests, benchmarks and the `meshcast rays` command cast them too.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "meshcast/mesh.h"
#include "meshcast/ray.h"

namespace meshcast {

enum class RayKind { Long, Probe, Radial };

// Throws InputError for an unknown name, listing the valid ones.
RayKind parse_ray_kind(const std::string& name);

// Deterministic for a given mesh, kind, count and seed.
//  Long:   origins on a sphere around the mesh (radius = box diagonal) aimed at
//          random points inside its box; t_max infinite.
//  Probe:  short rays (t_max = 5% of the diagonal) from just off a random
//          point of a random triangle, in random directions.
//  Radial: from the centre of the box in random directions; t_max infinite.
std::vector<Ray> make_rays(const Mesh& mesh, RayKind kind, size_t count, uint64_t seed);

}  // namespace meshcast
