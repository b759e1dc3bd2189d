// What the C API's casts share: the query read from the caller's struct,
// the caller's rays and hits seen as the library's own records (the same
// bytes: checked below), batches cut into chunks on the library's threads,
// and every-hit rows scattered into the caller's fixed rows.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "capi/status.h"
#include "host/shared_pool.h"
#include "meshcast/ray.h"
#include "meshcast/scene.h"

namespace meshcast::capi {

static_assert(sizeof(meshcast_ray) == sizeof(Ray) && offsetof(meshcast_ray, dir) == offsetof(Ray, dir) &&
              offsetof(meshcast_ray, tmax) == offsetof(Ray, tmax) && offsetof(meshcast_ray, tmin) == offsetof(Ray, tmin));
static_assert(sizeof(meshcast_hit) == sizeof(Hit) && offsetof(meshcast_hit, triangle) == offsetof(Hit, triangle) &&
              offsetof(meshcast_hit, u) == offsetof(Hit, u) && offsetof(meshcast_hit, point) == offsetof(Hit, point));
static_assert(sizeof(meshcast_ray_d) == sizeof(RayD) && offsetof(meshcast_ray_d, dir) == offsetof(RayD, dir) &&
              offsetof(meshcast_ray_d, tmax) == offsetof(RayD, tmax) && offsetof(meshcast_ray_d, tmin) == offsetof(RayD, tmin));
static_assert(sizeof(meshcast_scene_hit) == sizeof(SceneHit) &&
              offsetof(meshcast_scene_hit, instance) == offsetof(SceneHit, instance) &&
              offsetof(meshcast_scene_hit, triangle) == offsetof(SceneHit, triangle) &&
              offsetof(meshcast_scene_hit, u) == offsetof(SceneHit, u));
static_assert(sizeof(meshcast_scene_closest_point) == sizeof(SceneClosestPoint) &&
              offsetof(meshcast_scene_closest_point, distance) == offsetof(SceneClosestPoint, distance) &&
              offsetof(meshcast_scene_closest_point, instance) == offsetof(SceneClosestPoint, instance) &&
              offsetof(meshcast_scene_closest_point, u) == offsetof(SceneClosestPoint, u));

inline std::span<const Ray> rays_of(const meshcast_ray* rays, uint64_t n) {
  return {reinterpret_cast<const Ray*>(rays), size_t(n)};
}
inline std::span<Hit> hits_of(meshcast_hit* hits, uint64_t n) { return {reinterpret_cast<Hit*>(hits), size_t(n)}; }
inline std::span<const RayD> rays_of(const meshcast_ray_d* rays, uint64_t n) {
  return {reinterpret_cast<const RayD*>(rays), size_t(n)};
}
inline std::span<SceneHit> hits_of(meshcast_scene_hit* hits, uint64_t n) {
  return {reinterpret_cast<SceneHit*>(hits), size_t(n)};
}

// A caller's meshcast_query, checked.
struct CastQuery {
  Query query = Query::Closest;
  Cull cull = Cull::None;
  HitOutputs outputs = HitOutputs::None;
  uint8_t mask = 0xFF;
  uint32_t threads = 1;
};
CastQuery cast_query(const meshcast_query* query);
meshcast_query query_defaults();

// max_hits of an every-hit cast: 1..kMaxHitsLimit.
void check_max_hits(uint32_t max_hits);
// The records of `rays` rows of max_hits (UsageError past 2^64).
uint64_t row_records(uint64_t rays, uint32_t max_hits);

// walk(begin, n) over [0, count) in chunks on `threads` threads (1: the
// calling thread, one call); returns the sum of what the calls returned.
template <class Walk>
uint64_t in_chunks(uint64_t count, uint32_t threads, const Walk& walk) {
  if (threads <= 1 || count <= 1) return walk(size_t(0), size_t(count));
  const host::Chunks plan = host::plan_chunks(size_t(count), threads);
  std::atomic<uint64_t> sum{0};
  host::for_each_chunk(plan, threads, [&](size_t c) { sum += walk(plan.begin(c), plan.end(c) - plan.begin(c)); });
  return sum.load();
}

// Compact rows of the rays from `first` into the caller's rows of
// max_hits records each and their counts.
template <class Lists, class Record>
void scatter_rows(const Lists& lists, size_t first, uint32_t max_hits, uint32_t* found, Record* rows) {
  for (size_t i = 0; i < lists.rays(); ++i) {
    found[first + i] = lists.found[i];
    const auto row = lists.row(i);
    std::memcpy(static_cast<void*>(rows + (first + i) * max_hits), row.data(), row.size() * sizeof(Record));
  }
}

// A batch of closest or any hits: the checks every cast makes, the rays
// in chunks on the query's threads, each chunk walked by trace(rays, hits,
// query), and the rays not walkable written where asked for.
template <class CRay, class CHit, class Trace>
void cast_batch(const CRay* rays, uint64_t ray_count, const meshcast_query* query, CHit* hits, uint64_t hit_capacity,
                uint64_t* not_walkable, const Trace& trace) {
  const CastQuery q = cast_query(query);
  check_capacity(hit_capacity, ray_count, "hits");
  const auto r = rays_of(array(rays, ray_count, "rays"), ray_count);
  const auto h = hits_of(array(hits, ray_count, "hits"), ray_count);
  const uint64_t skipped = in_chunks(ray_count, q.threads, [&](size_t begin, size_t n) {
    return trace(r.subspan(begin, n), h.subspan(begin, n), q);
  });
  if (not_walkable) *not_walkable = skipped;
}

// A batch of every hit, each chunk's compact rows (`Lists`, filled by
// trace_all(rays, lists, query)) scattered into the caller's fixed rows.
template <class Lists, class CRay, class CHit, class TraceAll>
void cast_rows(const CRay* rays, uint64_t ray_count, const meshcast_query* query, uint32_t max_hits, uint32_t* found,
               CHit* hits, uint64_t hit_capacity, uint64_t* not_walkable, const TraceAll& trace_all) {
  const CastQuery q = cast_query(query);
  check_max_hits(max_hits);
  check_capacity(hit_capacity, row_records(ray_count, max_hits), "hits");
  const auto r = rays_of(array(rays, ray_count, "rays"), ray_count);
  array(found, ray_count, "found");
  auto* rows = hits_of(array(hits, ray_count, "hits"), 0).data();
  const uint64_t skipped = in_chunks(ray_count, q.threads, [&](size_t begin, size_t n) {
    Lists lists;
    lists.max_hits = max_hits;
    const uint64_t walked = trace_all(r.subspan(begin, n), lists, q);
    scatter_rows(lists, begin, max_hits, found, rows);
    return walked;
  });
  if (not_walkable) *not_walkable = skipped;
}

}  // namespace meshcast::capi
