// A snapshot's walk: the top level's float boxes near its anchor (the
// chosen instruction set's walk_top, cpu/walk_top.h), each instance it reaches
// walked by its blob's own walker on the ray brought into its frame.
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstddef>

#include "scene/snapshot.h"
#include "cpu/scratch.h"
#include "cpu/walk.h"
#include "cpu/walk_top.h"
#include "layout/blob_format.h"
#include "layout/queries.h"
#include "meshcast/errors.h"
#include "meshcast/scene.h"

namespace meshcast {

TopRay::TopRay(const float rel[3], const float dir[3], float pad) {
  constexpr uint32_t kRow = sizeof(float) * layout::kTopWidth;
  constexpr uint32_t kLoAt = offsetof(layout::TopWideNode, lo), kHiAt = offsetof(layout::TopWideNode, hi);
  for (int a = 0; a < 3; ++a) {
    const uint32_t negative = std::signbit(dir[a]);
    inv[a] = 1.0f / dir[a];
    // Without a branch or a blend: a ray's signs are as likely as not.
    near_at[a] = kRow * a + kLoAt + negative * (kHiAt - kLoAt);
    far_at[a] = kRow * a + kHiAt - negative * (kHiAt - kLoAt);
    // The lo plane moves down by the pad, the hi plane up.
    const float signed_pad = std::copysign(pad, dir[a]);
    near_shift[a] = rel[a] + signed_pad;
    far_shift[a] = rel[a] - signed_pad;
  }
}

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

// The origin relative to the top level's anchor, rounded to float.
std::array<float, 3> relative_origin(const layout::TopLevel& top, const RayD& rd) {
  return {float(rd.org[0] - top.anchor[0]), float(rd.org[1] - top.anchor[1]), float(rd.org[2] - top.anchor[2])};
}

// What the top level's boxes are widened by for the ray: kBoxSlack of the
// farthest its origin is from the scene's box (which also covers the
// rounding of the origin and the boxes to float).
float box_pad(const layout::TopLevel& top, const RayD& rd) {
  double far = 0;
  for (int a = 0; a < 3; ++a)
    far = std::max({far, std::fabs(rd.org[a] - top.min[a]), std::fabs(rd.org[a] - top.max[a])});
  return float(far * kBoxSlack);
}

// A world ray and the top level's view of it (cpu/walk_top.h). `dir` is
// the direction as walked (walked_direction, meshcast/ray.h): the top
// level's box test and every instance's frame take it.
struct WorldRay {
  const RayD& ray;
  float dir[3];
  TopRay top;
  WorldRay(const layout::TopLevel& t, const RayD& rd)
      : ray(rd),
        dir{walked_direction(rd.dir[0]), walked_direction(rd.dir[1]), walked_direction(rd.dir[2])},
        top(relative_origin(t, rd).data(), dir, box_pad(t, rd)) {}
};

// The world ray in the instance's frame: the translation subtracted in
// double, the difference rounded to float, then the float inverse.
Ray to_local(const WorldRay& r, const layout::PlacedInstance& p) {
  float rel[3];
  for (int a = 0; a < 3; ++a) rel[a] = float(r.ray.org[a] - p.translation[a]);
  Ray local;
  local.tmin = r.ray.tmin;  // t is the same number in both frames
  const float* dir = r.dir;
  for (int i = 0; i < 3; ++i) {
    const float* row = p.to_local + 3 * i;
    local.org[i] = row[0] * rel[0] + row[1] * rel[1] + row[2] * rel[2];
    local.dir[i] = row[0] * dir[0] + row[1] * dir[1] + row[2] * dir[2];
  }
  return local;
}

// The culling a flip_facing instance's walker takes: its front face is the
// mesh's back. (A mirroring transform changes nothing: the walk is in the
// mesh's frame, where the corners run as the mesh has them.)
Cull turned(Cull cull) {
  return cull == Cull::Back ? Cull::Front : cull == Cull::Front ? Cull::Back : cull;
}

bool world_ray_walkable(const RayD& r) {
  Ray probe{{0, 0, 0}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax, r.tmin};
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(r.org[a]) <= double(kMaxCoordinate))) return false;
  return ray_is_walkable(probe);
}

// The chosen instruction set's top-level walk (cpu/walk_top.h) for one
// ray, each instance it reaches handed to visit(instance, its local ray
// with t_max the cut and the world ray's t_min), which returns the cut from
// then on, or a negative number to end the walk. The cut never falls below
// t_min (it is t_max or a hit's t), so every local ray keeps t_min <= t_max.
template <class Visit>
void walk_top(const layout::TopLevel& top, const WorldRay& r, uint8_t mask, WalkTopFn walk, Visit&& visit) {
  struct Context {
    const layout::TopLevel& top;
    const WorldRay& r;
    Visit& visit;
  } context{top, r, visit};
  walk(top, r.top, r.ray.tmax, mask,
       [](void* c, uint32_t placed, float cut) {
         Context& x = *static_cast<Context*>(c);
         const layout::PlacedInstance& p = x.top.placed[placed];
         Ray local = to_local(x.r, p);
         local.tmax = cut;
         return x.visit(p, local);
       },
       &context);
}

// What a trace asks of each instance's walker: for an instance that faces
// as its mesh and for a flip_facing one (its culling turned). Closest and
// any hit keep their slots (looked up by finish_scene_hits); Query::All's
// rows name the caller's triangles, the instance's row written to `row`
// (max_hits records), its count to *found.
struct InstanceRequests {
  WalkRequest as_mesh, flipped;
  bool any;
  InstanceRequests(HitOutputs outputs, Query query, Cull cull, uint32_t max_hits = 0, uint32_t* found = nullptr,
                   Hit* row = nullptr)
      : any(query == Query::Any) {
    const uint32_t uv = uint32_t(outputs) & MC_HIT_UV;
    as_mesh.flags = uv | layout::query_bits(query, cull);
    flipped.flags = uv | layout::query_bits(query, turned(cull));
    as_mesh.keep_slots = flipped.keep_slots = true;
    for (WalkRequest* r : {&as_mesh, &flipped}) r->max_hits = max_hits, r->found = found, r->lists = row;
  }
  const WalkRequest& of(const layout::PlacedInstance& p) const { return p.flip_facing ? flipped : as_mesh; }
};

// Closest or any hit of one ray, its triangle a slot of *hit_mesh (left
// alone on a miss). Returns false when some instance's frame could not
// take it (its local ray not walkable): that instance is not walked and
// the ray counted.
bool walk(const SceneSnapshot& s, const RayD& rd, SceneHit& best, const SceneMesh*& hit_mesh,
          const InstanceRequests& requests, uint8_t mask, WalkTopFn walk_fn) {
  bool complete = true;
  walk_top(s.top, WorldRay(s.top, rd), mask, walk_fn, [&](const layout::PlacedInstance& p, const Ray& local) {
    const SceneMesh& mesh = *s.meshes[p.mesh];
    Hit h;
    uint64_t skipped = 0;
    // A local ray the walkers refuse (its direction scaled past their
    // range) is counted, not walked.
    mesh.walk(mesh.bytes.data(), &local, &h, 1, &skipped, requests.of(p));
    if (skipped != 0) complete = false;
    // Equal t: the lower instance id, as the oracle breaks ties.
    if (h.triangle != kNoHit &&
        (h.t < local.tmax || best.instance == kNoHit || (h.t == local.tmax && p.id < best.instance))) {
      best = {h.t, p.id, h.triangle, h.u, h.v};
      hit_mesh = &mesh;
      return requests.any ? -1.0f : h.t;
    }
    return local.tmax;
  });
  return complete;
}

// The slots of hits[i] (hit in *meshes[i]) to the caller's triangles. Each
// lookup may miss the cache twice; made side by side for many rays, the
// misses overlap (as the walkers' finish_hits).
void finish_scene_hits(std::span<SceneHit> hits, std::span<const SceneMesh* const> meshes) {
  for (size_t i = 0; i < hits.size(); ++i)
    if (const SceneMesh* m = meshes[i]) {
      const uint8_t* blob = m->bytes.data();
      hits[i].triangle = layout::remap_entry(blob, layout::header_of(blob), hits[i].triangle);
    }
}

// Query::All's rows of one ray in a thread's scratch (cpu/scratch.h):
// `own`, the row an instance's walker writes (max_hits records, its count
// in own_found), and `row`, the ray's nearest max_hits over every instance
// so far.
struct ListWalk {
  std::span<Hit> own;
  std::span<SceneHit> row;
  uint32_t own_found = 0;
  InstanceRequests requests;
  ListWalk(HitOutputs outputs, Cull cull, uint32_t max_hits)
      : own(thread_scratch<Hit>(max_hits)),
        row(thread_scratch<SceneHit>(max_hits)),
        requests(outputs, Query::All, cull, max_hits, &own_found, own.data()) {}
};

// Every hit of one ray: each instance's own hits (its walker's row in
// w.own) merged into w.row, the nearest kept (`kept` of them, the first
// records of w.row) in order of t, instance, triangle. Returns the hits
// found, or with `complete` false a ray some frame could not take.
uint32_t walk_all(const SceneSnapshot& s, const RayD& rd, ListWalk& w, uint32_t& kept, uint8_t mask, WalkTopFn walk_fn,
                  bool& complete) {
  const uint32_t cap = uint32_t(w.row.size());
  uint32_t found = 0;
  kept = 0;
  auto before = [](const SceneHit& a, const SceneHit& b) {
    return a.t < b.t || (a.t == b.t && (a.instance < b.instance || (a.instance == b.instance && a.triangle < b.triangle)));
  };
  walk_top(s.top, WorldRay(s.top, rd), mask, walk_fn, [&](const layout::PlacedInstance& p, const Ray& local) {
    const SceneMesh& mesh = *s.meshes[p.mesh];
    uint64_t skipped = 0;
    // A local ray the walkers refuse (its direction scaled past their
    // range) is counted, not walked.
    mesh.walk(mesh.bytes.data(), &local, nullptr, 1, &skipped, w.requests.of(p));
    if (skipped != 0) complete = false;
    const uint32_t own = w.own_found;
    found += own;
    for (uint32_t k = 0; k < std::min(own, cap); ++k) {
      const SceneHit h{w.own[k].t, p.id, w.own[k].triangle, w.own[k].u, w.own[k].v};
      uint32_t at = std::min(kept, cap);
      if (at == cap) {
        if (!before(h, w.row[cap - 1])) break;  // this instance's rest is farther still
        --at;
      } else {
        ++kept;
      }
      for (; at > 0 && before(h, w.row[at - 1]); --at) w.row[at] = w.row[at - 1];
      w.row[at] = h;
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

// The frame of every ray both traces share, for rays [begin, end): its
// answer reset (reset(i)), then a world ray the walk cannot take counted
// (whatever the scene holds, an empty one too), an empty scene answering
// a miss, and walk(i), false when some instance's frame refused the ray,
// counted. Returns the rays counted.
template <class Reset, class Walk>
uint64_t for_each_world_ray(const SceneSnapshot& snapshot, std::span<const RayD> rays, size_t begin, size_t end,
                            Reset&& reset, Walk&& walk) {
  uint64_t skipped = 0;
  for (size_t i = begin; i < end; ++i) {
    reset(i);
    if (!world_ray_walkable(rays[i]))
      ++skipped;
    else if (!snapshot.top.wide.empty() && !walk(i))
      ++skipped;
  }
  return skipped;
}

}  // namespace

void check_scene_hits(size_t rays, size_t hits) {
  if (hits < rays)
    throw UsageError("Scene::trace: " + std::to_string(rays) + " rays but " + std::to_string(hits) +
                     " hits; the hits span must hold one hit a ray");
}

uint64_t trace_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, std::span<SceneHit> hits,
                        HitOutputs outputs, Query query, Cull cull, uint8_t mask) {
  check_scene_hits(rays.size(), hits.size());
  if (query == Query::All)
    throw UsageError("Scene::trace: Query::All has a list of hits a ray: Scene::trace_all_hits answers it");
  check_request("Scene::trace", outputs, query, cull);
  const WalkTopFn walk_fn = walk_top_fn();
  const InstanceRequests requests(outputs, query, cull);
  uint64_t skipped = 0;
  constexpr size_t kChunk = 32;
  const SceneMesh* hit_meshes[kChunk];
  for (size_t begin = 0; begin < rays.size(); begin += kChunk) {
    const size_t end = std::min(rays.size(), begin + kChunk);
    skipped += for_each_world_ray(
        snapshot, rays, begin, end, [&](size_t i) { hits[i] = SceneHit{}, hit_meshes[i - begin] = nullptr; },
        [&](size_t i) { return walk(snapshot, rays[i], hits[i], hit_meshes[i - begin], requests, mask, walk_fn); });
    finish_scene_hits(hits.subspan(begin, end - begin), std::span(hit_meshes, end - begin));
  }
  return skipped;
}

uint64_t trace_all_hits_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, SceneHitLists& lists,
                                 HitOutputs outputs, Cull cull, uint8_t mask) {
  check_request("Scene::trace_all_hits", outputs, Query::All, cull);
  if (lists.max_hits < 1 || lists.max_hits > kMaxHitsLimit)
    throw UsageError("Scene::trace_all_hits: max_hits " + std::to_string(lists.max_hits) + " is not in 1.." +
                     std::to_string(kMaxHitsLimit));
  lists.clear();
  lists.found.reserve(rays.size());
  lists.offsets.reserve(rays.size() + 1);
  const WalkTopFn walk_fn = walk_top_fn();
  ListWalk w(outputs, cull, lists.max_hits);
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    uint32_t found = 0, kept = 0;  // a ray not walked: an empty row
    skipped += for_each_world_ray(snapshot, rays, i, i + 1, [](size_t) {}, [&](size_t) {
      bool complete = true;
      found = walk_all(snapshot, rays[i], w, kept, mask, walk_fn, complete);
      return complete;
    });
    lists.add_row(found, w.row.first(kept));
  }
  return skipped;
}

}  // namespace meshcast
