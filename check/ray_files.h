// The two files exchanged with the outside (ARCHITECTURE.md):
//   rays: "RAYS", uint32 count, per ray 7 float32 (origin, direction, t_max)
//   hits: "HITS", uint32 count, per ray float32 t (inf: miss), uint32 triangle
// All little-endian.
#pragma once
#include <string>
#include <vector>

#include "builder/ray_sets.h"
#include "layout/files.h"
#include "meshcast/ray.h"

namespace meshcast {

// Throw InputError naming the file on a bad magic, short or oversized file.
std::vector<Ray> read_rays(const std::string& path);
void write_rays(const std::string& path, const std::vector<Ray>& rays);
std::vector<Hit> read_hits(const std::string& path);
void write_hits(const std::string& path, const std::vector<Hit>& hits);

// Most rays a rays file may hold, and `meshcast rays --count` make: 2^27
// (3.5 GiB of records).
constexpr size_t kMaxRayCount = size_t(1) << 27;

}  // namespace meshcast
