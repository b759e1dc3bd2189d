// Ray sets and the two files exchanged with the outside (ARCHITECTURE.md):
//   rays: "RAYS", uint32 count, per ray 7 float32 (origin, direction, t_max)
//   hits: "HITS", uint32 count, per ray float32 t (inf: miss), uint32 triangle
// All little-endian.
#pragma once
#include <string>
#include <vector>

#include "cpu/ray.h"
#include "layout/files.h"
#include "meshcast/mesh.h"

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

// Throw InputError naming the file on a bad magic, short or oversized file.
std::vector<Ray> read_rays(const std::string& path);
void write_rays(const std::string& path, const std::vector<Ray>& rays);
std::vector<Hit> read_hits(const std::string& path);
void write_hits(const std::string& path, const std::vector<Hit>& hits);

// Most rays a rays file may hold, and `meshcast rays --count` make: 2^27
// (3.5 GiB of records).
constexpr size_t kMaxRayCount = size_t(1) << 27;

}  // namespace meshcast
