// The two files exchanged with the outside (ARCHITECTURE.md):
//   rays: "RAYS", uint32 count, per ray 7 float32 (origin, direction, t_max)
//   hits: "HITS", uint32 count, per ray float32 t (inf: miss), uint32 triangle
//   every hit (Query::All): "HITC", uint32 count, uint32 N, then per ray
//         uint32 hits found, then per ray its min(found, N) kept records
//         of float32 t, uint32 triangle, nearest first: 12 + 4 count + 8
//         (kept hits) bytes, the size following the hits, not count x N
//   the fixed rows before HITC (read, no longer written): "HITN", uint32
//         count, uint32 N, per ray uint32 hits found, then N records, the
//         unused ones t = inf, triangle 0xFFFFFFFF
//   scene rays: "RAYD", uint32 count, per ray 3 float64 origin, 3 float32
//         direction, float32 t_max (40 bytes)
//   scene hits: "HITI", uint32 count, per ray float32 t (inf: miss),
//         uint32 instance, uint32 triangle (a miss: 0xFFFFFFFF twice)
// All little-endian. Neither rays file holds a t_min: rays read have t_min
// 0, and the writers refuse a ray with another (UsageError naming it).
#pragma once
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "builder/ray_sets.h"
#include "io/files.h"
#include "meshcast/ray.h"
#include "meshcast/scene.h"

namespace meshcast {

// Throw InputError naming the file on a bad magic (naming the file's kind
// where it is another of these), short or oversized file.
std::vector<Ray> read_rays(const std::string& path);
void write_rays(const std::string& path, const std::vector<Ray>& rays);
// A RAYS file of `count` rays that make() writes a chunk at a time, in
// order: a file of kMaxRayCount rays (3.5 GiB) is never held whole.
void write_rays(const std::string& path, size_t count, const std::function<void(std::span<Ray>)>& make);
std::vector<Hit> read_hits(const std::string& path);
void write_hits(const std::string& path, const std::vector<Hit>& hits);
// Every-hit files, HITC or HITN, into compact rows: InputError naming the
// file for a bad magic, an N outside 1..kMaxHitsLimit or a size that is
// not the header's (and, for HITC, the counts').
HitLists read_hit_lists(const std::string& path);
// A HITC file. InputError beyond kMaxRayCount rays; UsageError for rows
// that do not keep min(found, max_hits) records each.
void write_hit_lists(const std::string& path, const HitLists& lists);
// Scenes' files, with read_rays' refusals.
std::vector<RayD> read_scene_rays(const std::string& path);
void write_scene_rays(const std::string& path, const std::vector<RayD>& rays);
std::vector<SceneHit> read_scene_hits(const std::string& path);
void write_scene_hits(const std::string& path, const std::vector<SceneHit>& hits);
// Whether the file starts with RAYD (else it is read as a RAYS file); a
// file too short to tell, by its name's .rayd.
bool is_scene_rays_file(const std::string& path);

// Most rays a rays file may hold, and `meshcast rays --count` make: 2^27
// (3.5 GiB of records).
constexpr size_t kMaxRayCount = size_t(1) << 27;

}  // namespace meshcast
