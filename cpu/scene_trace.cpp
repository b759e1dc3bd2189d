// A snapshot's walk: the top level's float boxes near its anchor (the
// chosen instruction set's walk_top, cpu/walk_top.h), each instance it reaches
// walked by its blob's own walker on the ray brought into its frame.
#include <algorithm>
#include <cfloat>
#include <cmath>

#include "cpu/scene.h"
#include "cpu/walk_top.h"
#include "layout/queries.h"
#include "meshcast/errors.h"
#include "meshcast/scene.h"

namespace meshcast {

namespace {

// How much every box is widened for one ray: the ray reaches each
// instance rounded (its origin relative to the instance in float, then the
// float inverse), so where a walker meets a triangle can lie off the world
// ray by about 2^-22 of the distance from the ray's origin (more for
// strongly non-uniform scales). 2^-16 of the farthest the origin is from
// the whole scene's box's planes, axis by axis, covers every instance the ray can reach
// (worked out once a ray: a few centimetres for a ray inside a level 10 km
// across, far inside the smallest instance a game places).
constexpr double kBoxSlack = MC_TOP_BOX_SLACK;  // 2^-16
static_assert(kBoxSlack == 0x1p-16);

struct WorldRay {
  double org[3];
  float dir[3];
  float tmax;
  TopRay top;  // for the top level's float boxes (cpu/walk_top.h)
};

// The world ray in the instance's frame: the translation subtracted in
// double, the difference rounded to float, then the float inverse.
Ray to_local(const WorldRay& r, const layout::PlacedInstance& p) {
  float rel[3];
  for (int a = 0; a < 3; ++a) rel[a] = float(r.org[a] - p.translation[a]);
  Ray local;
  for (int i = 0; i < 3; ++i) {
    const float* row = p.to_local + 3 * i;
    local.org[i] = row[0] * rel[0] + row[1] * rel[1] + row[2] * rel[2];
    local.dir[i] = row[0] * r.dir[0] + row[1] * r.dir[1] + row[2] * r.dir[2];
  }
  return local;
}

Cull as_instance_sees(Cull cull, bool mirrored) {
  if (!mirrored || cull == Cull::None) return cull;
  return cull == Cull::Back ? Cull::Front : Cull::Back;
}

bool world_ray_walkable(const RayD& r) {
  Ray probe{{0, 0, 0}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax};
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(r.org[a]) <= double(kMaxCoordinate))) return false;
  return ray_is_walkable(probe);
}

// The world ray as the top level reads it; the pad is kBoxSlack of the
// farthest the origin is from the scene's box (which also covers the
// rounding of the origin and the boxes to float).
WorldRay world_ray(const layout::TopLevel& top, const RayD& rd) {
  WorldRay r;
  double far = 0;
  for (int a = 0; a < 3; ++a) {
    r.org[a] = rd.org[a], r.dir[a] = rd.dir[a];
    r.top.rel[a] = float(rd.org[a] - top.anchor[a]);
    r.top.inv[a] = 1.0f / rd.dir[a];
    r.top.negative[a] = std::signbit(rd.dir[a]);
    far = std::max({far, std::fabs(rd.org[a] - top.min[a]), std::fabs(rd.org[a] - top.max[a])});
  }
  r.tmax = rd.tmax;
  r.top.pad = float(far * kBoxSlack);
  return r;
}

// The chosen instruction set's top-level walk (cpu/walk_top.h) for one
// ray, each instance it reaches handed to visit(instance, its local ray
// with t_max the cut), which returns the cut from then on, or a negative
// number to end the walk.
template <class Visit>
void walk_top(const layout::TopLevel& top, const WorldRay& r, uint8_t mask, WalkTopFn walk, Visit&& visit) {
  struct Context {
    const layout::TopLevel& top;
    const WorldRay& r;
    Visit& visit;
  } context{top, r, visit};
  walk(top, r.top, r.tmax, mask,
       [](void* c, uint32_t placed, float cut) {
         Context& x = *static_cast<Context*>(c);
         const layout::PlacedInstance& p = x.top.placed[placed];
         Ray local = to_local(x.r, p);
         local.tmax = cut;
         return x.visit(p, local);
       },
       &context);
}

// Closest or any hit of one ray. Returns false when some instance's frame
// could not take it (its local ray not walkable): that instance is not
// walked and the ray counted.
bool walk(const SceneSnapshot& s, const RayD& rd, SceneHit& best, HitOutputs outputs, Query query, Cull cull,
          uint8_t mask, WalkTopFn walk_fn) {
  bool complete = true;
  walk_top(s.top, world_ray(s.top, rd), mask, walk_fn, [&](const layout::PlacedInstance& p, const Ray& local) {
    Hit h;
    // A local ray the walkers refuse (its direction scaled past their
    // range) is counted, not walked.
    if (s.meshes[p.mesh]->view.trace(std::span(&local, 1), std::span(&h, 1), outputs, query,
                                     as_instance_sees(cull, p.mirrored != 0)) != 0)
      complete = false;
    // Equal t: the lower instance id, as the oracle breaks ties.
    if (h.triangle != kNoHit &&
        (h.t < local.tmax || best.instance == kNoHit || (h.t == local.tmax && p.id < best.instance))) {
      best = {h.t, p.id, h.triangle, h.u, h.v};
      return query == Query::Any ? -1.0f : h.t;
    }
    return local.tmax;
  });
  return complete;
}

// Every hit of one ray into its row (max_hits long, filled with misses):
// each instance's own hits (its walker's rows, `scratch` max_hits long)
// merged in, the nearest kept in order of t, instance, triangle. Returns
// the hits found, or with `complete` false a ray some frame could not take.
uint32_t walk_all(const SceneSnapshot& s, const RayD& rd, std::span<SceneHit> row, std::vector<Hit>& scratch,
                  HitOutputs outputs, Cull cull, uint8_t mask, WalkTopFn walk_fn, bool& complete) {
  const uint32_t cap = uint32_t(row.size());
  uint32_t found = 0, kept = 0;
  auto before = [](const SceneHit& a, const SceneHit& b) {
    return a.t < b.t || (a.t == b.t && (a.instance < b.instance || (a.instance == b.instance && a.triangle < b.triangle)));
  };
  walk_top(s.top, world_ray(s.top, rd), mask, walk_fn, [&](const layout::PlacedInstance& p, const Ray& local) {
    uint32_t own = 0;
    if (s.meshes[p.mesh]->view.trace_all_hits(std::span(&local, 1), cap, std::span(&own, 1), scratch, outputs,
                                              as_instance_sees(cull, p.mirrored != 0)) != 0)
      complete = false;
    found += own;
    for (uint32_t k = 0; k < std::min(own, cap); ++k) {
      const SceneHit h{scratch[k].t, p.id, scratch[k].triangle, scratch[k].u, scratch[k].v};
      uint32_t at = std::min(kept, cap);
      if (at == cap) {
        if (!before(h, row[cap - 1])) break;  // this instance's rest is farther still
        --at;
      } else {
        ++kept;
      }
      for (; at > 0 && before(h, row[at - 1]); --at) row[at] = row[at - 1];
      row[at] = h;
    }
    return local.tmax;  // every hit along the segment: the cut stays
  });
  return found;
}

// UsageError naming `who` for what a scene's walk cannot answer, checked
// before any ray is walked (an empty scene refuses it too).
void check_request(const char* who, HitOutputs outputs, Query query, Cull cull) {
  layout::check_query(who, query, cull);
  if (has(outputs, HitOutputs::Point)) throw UsageError(std::string(who) + ": a scene hit carries no point (HitOutputs::Point)");
}

}  // namespace

uint64_t trace_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, std::span<SceneHit> hits,
                        HitOutputs outputs, Query query, Cull cull, uint8_t mask) {
  if (hits.size() < rays.size())
    throw UsageError("Scene::trace: " + std::to_string(rays.size()) + " rays but " + std::to_string(hits.size()) +
                     " hits; the hits span must hold one hit a ray");
  if (query == Query::All)
    throw UsageError("Scene::trace: Query::All has a list of hits a ray: Scene::trace_all_hits answers it");
  check_request("Scene::trace", outputs, query, cull);
  const WalkTopFn walk_fn = walk_top_fn();
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    hits[i] = SceneHit{};
    // Refused whatever the scene holds (an empty one too).
    if (!world_ray_walkable(rays[i])) {
      ++skipped;
      continue;
    }
    if (snapshot.top.wide.empty()) continue;
    if (!walk(snapshot, rays[i], hits[i], outputs, query, cull, mask, walk_fn)) ++skipped;
  }
  return skipped;
}

uint64_t trace_all_hits_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, SceneHitLists& lists,
                                 HitOutputs outputs, Cull cull, uint8_t mask) {
  check_request("Scene::trace_all_hits", outputs, Query::All, cull);
  if (lists.max_hits < 1 || lists.max_hits > kMaxHitsLimit)
    throw UsageError("Scene::trace_all_hits: max_hits " + std::to_string(lists.max_hits) + " is not in 1.." +
                     std::to_string(kMaxHitsLimit));
  lists.found.assign(rays.size(), 0);
  lists.hits.assign(rays.size() * lists.max_hits, SceneHit{});
  return trace_scene_rows(snapshot, rays, lists.max_hits, lists.found, lists.hits, outputs, cull, mask);
}

uint64_t trace_scene_rows(const SceneSnapshot& snapshot, std::span<const RayD> rays, uint32_t max_hits,
                          std::span<uint32_t> found, std::span<SceneHit> rows, HitOutputs outputs, Cull cull,
                          uint8_t mask) {
  check_request("Scene::trace_all_hits", outputs, Query::All, cull);
  const WalkTopFn walk_fn = walk_top_fn();
  std::vector<Hit> scratch(max_hits);
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const std::span<SceneHit> row = rows.subspan(i * max_hits, max_hits);
    std::fill(row.begin(), row.end(), SceneHit{});
    found[i] = 0;
    if (!world_ray_walkable(rays[i])) {
      ++skipped;
      continue;
    }
    if (snapshot.top.wide.empty()) continue;
    bool complete = true;
    found[i] = walk_all(snapshot, rays[i], row, scratch, outputs, cull, mask, walk_fn, complete);
    skipped += !complete;
  }
  return skipped;
}

}  // namespace meshcast
