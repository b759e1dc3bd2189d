// A snapshot's walk: the top level's float boxes near its anchor, each instance it reaches
// walked by its blob's own walker on the ray brought into its frame.
#include <algorithm>
#include <cfloat>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "cpu/scene.h"
#include "meshcast/errors.h"
#include "meshcast/scene.h"

namespace meshcast {

namespace {

// How much every box is widened for one ray: the ray reaches each
// instance rounded (its origin relative to the instance in float, then the
// float inverse), so where a walker meets a triangle can lie off the world
// ray by about 2^-22 of the distance from the ray's origin (more for
// strongly non-uniform scales). 2^-16 of the origin's distance to the far
// corner of the whole scene's box covers every instance the ray can reach
// (worked out once a ray: a few centimetres for a ray inside a level 10 km
// across, far inside the smallest instance a game places).
constexpr double kBoxSlack = 0x1p-16;

struct WorldRay {
  double org[3];
  float dir[3];
  float tmax;
  // For the top level's float boxes: the origin relative to the anchor
  // (rounded), 1 / dir (+-inf for a zero component), and the pad every box
  // is widened by, kBoxSlack of the farthest the origin is from the scene's
  // box (which also covers the rounding of the origin and the boxes).
  float rel[3], inv[3], pad;
  bool negative[3];  // dir's sign bit: the box's hi plane is met first
};

// The entries into the 4 slots' widened boxes before `cut`: a bit a slot
// entered, its entry distance in entry[slot]. Written as straight loops
// over 4 lanes. Near and far planes go by the direction's sign, so a zero
// component (an infinite inverse) gives -inf or +inf on the right sides,
// and NaN (0 * inf) only for a ray in a slab's plane, which the min and max
// below drop (they keep their second operand on NaN, as the walkers' box
// tests do): the closed box holds that ray.
int enter_slots(const WorldRay& r, const layout::TopWideNode& n, float cut, float entry[4]) {
#if defined(__SSE2__)
  // Every x86-64 processor has SSE2: the 4 slots in one register (the
  // library's own code is built for the baseline; the walkers are the part
  // built for each instruction set).
  __m128 tn = _mm_setzero_ps(), tf = _mm_set1_ps(cut * (1 + float(kBoxSlack)));
  const __m128 pad = _mm_set1_ps(r.pad);
  for (int a = 0; a < 3; ++a) {
    const __m128 rel = _mm_set1_ps(r.rel[a]), inv = _mm_set1_ps(r.inv[a]);
    const __m128 t0 = _mm_mul_ps(_mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(n.lo[a]), pad), rel), inv);
    const __m128 t1 = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(_mm_loadu_ps(n.hi[a]), pad), rel), inv);
    tn = _mm_max_ps(r.negative[a] ? t1 : t0, tn);  // NaN: the second operand kept
    tf = _mm_min_ps(r.negative[a] ? t0 : t1, tf);
  }
  _mm_storeu_ps(entry, tn);
  return _mm_movemask_ps(_mm_cmple_ps(tn, tf));
#else
  float tn[4], tf[4];
  for (int k = 0; k < 4; ++k) tn[k] = 0, tf[k] = cut * (1 + float(kBoxSlack));
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 4; ++k) {
      const float t0 = (n.lo[a][k] - r.pad - r.rel[a]) * r.inv[a], t1 = (n.hi[a][k] + r.pad - r.rel[a]) * r.inv[a];
      const float near = r.negative[a] ? t1 : t0, far = r.negative[a] ? t0 : t1;
      tn[k] = near > tn[k] ? near : tn[k];
      tf[k] = far < tf[k] ? far : tf[k];
    }
  int bits = 0;
  for (int k = 0; k < 4; ++k) {
    entry[k] = tn[k];
    bits |= int(tn[k] <= tf[k]) << k;
  }
  return bits;
#endif
}

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

// The world ray as the top level reads it.
WorldRay world_ray(const layout::TopLevel& top, const RayD& rd) {
  WorldRay r;
  double far = 0;
  for (int a = 0; a < 3; ++a) {
    r.org[a] = rd.org[a], r.dir[a] = rd.dir[a];
    r.rel[a] = float(rd.org[a] - top.anchor[a]);
    r.inv[a] = 1.0f / rd.dir[a];
    r.negative[a] = std::signbit(rd.dir[a]);
    far = std::max({far, std::fabs(rd.org[a] - top.min[a]), std::fabs(rd.org[a] - top.max[a])});
  }
  r.tmax = rd.tmax;
  r.pad = float(far * kBoxSlack);
  return r;
}

// The top level's walk for one ray: every instance whose box the ray
// enters before the cut, nearest entry first, whose mask shares a bit
// with `mask`, goes to visit(instance, its local ray with t_max the cut),
// which returns the cut from then on (a nearer hit's t, or the same), or
// a negative number to end the walk.
template <class Visit>
void walk_top(const layout::TopLevel& top, const WorldRay& r, uint8_t mask, Visit&& visit) {
  float cut = r.tmax;
  // A wide node leaves at most 3 entries behind a level, and the binary
  // tree under it is at most 64 deep (median splits of fewer than 2^32):
  // the stack cannot fill.
  constexpr int kStack = 3 * 64 + 4;
  uint32_t stack[kStack];
  float entries[kStack];
  int top_of = 0;
  stack[top_of] = 0, entries[top_of++] = 0;  // the root node
  while (top_of > 0) {
    --top_of;
    if (entries[top_of] > cut * (1 + float(kBoxSlack))) continue;
    const uint32_t item = stack[top_of];
    if (item & layout::kTopInstance) {
      const layout::PlacedInstance& p = top.placed[item & ~layout::kTopInstance];
      if ((p.mask & mask) == 0) continue;
      Ray local = to_local(r, p);
      local.tmax = cut;
      cut = visit(p, local);
      if (cut < 0) return;
      continue;
    }
    const layout::TopWideNode& n = top.wide[item];
    float entry[4];
    int bits = enter_slots(r, n, cut, entry);
    // Pushed farthest first, so the nearest is walked next.
    int order[4], count = 0;
    for (; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(unsigned(bits));
      int at = count++;
      for (; at > 0 && entry[order[at - 1]] < entry[k]; --at) order[at] = order[at - 1];
      order[at] = k;
    }
    for (int i = 0; i < count; ++i) stack[top_of] = n.slot[order[i]], entries[top_of++] = entry[order[i]];
  }
}

// Closest or any hit of one ray. Returns false when some instance's frame
// could not take it (its local ray not walkable): that instance is not
// walked and the ray counted.
bool walk(const SceneSnapshot& s, const RayD& rd, SceneHit& best, HitOutputs outputs, Query query, Cull cull,
          uint8_t mask) {
  bool complete = true;
  walk_top(s.top, world_ray(s.top, rd), mask, [&](const layout::PlacedInstance& p, const Ray& local) {
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
                  HitOutputs outputs, Cull cull, uint8_t mask, bool& complete) {
  const uint32_t cap = uint32_t(row.size());
  uint32_t found = 0, kept = 0;
  auto before = [](const SceneHit& a, const SceneHit& b) {
    return a.t < b.t || (a.t == b.t && (a.instance < b.instance || (a.instance == b.instance && a.triangle < b.triangle)));
  };
  walk_top(s.top, world_ray(s.top, rd), mask, [&](const layout::PlacedInstance& p, const Ray& local) {
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

}  // namespace

uint64_t trace_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, std::span<SceneHit> hits,
                        HitOutputs outputs, Query query, Cull cull, uint8_t mask) {
  if (hits.size() < rays.size())
    throw UsageError("Scene::trace: " + std::to_string(rays.size()) + " rays but " + std::to_string(hits.size()) +
                     " hits; the hits span must hold one hit a ray");
  if (query == Query::All)
    throw UsageError("Scene::trace: Query::All has a list of hits a ray: Scene::trace_all_hits answers it");
  if (has(outputs, HitOutputs::Point)) throw UsageError("Scene::trace: a scene hit carries no point (HitOutputs::Point)");
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    hits[i] = SceneHit{};
    if (snapshot.top.wide.empty()) continue;
    if (!world_ray_walkable(rays[i])) {
      ++skipped;
      continue;
    }
    if (!walk(snapshot, rays[i], hits[i], outputs, query, cull, mask)) ++skipped;
  }
  return skipped;
}

uint64_t trace_all_hits_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, SceneHitLists& lists,
                                 HitOutputs outputs, Cull cull, uint8_t mask) {
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
  if (has(outputs, HitOutputs::Point))
    throw UsageError("Scene::trace_all_hits: a scene hit carries no point (HitOutputs::Point)");
  std::vector<Hit> scratch(max_hits);
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const std::span<SceneHit> row = rows.subspan(i * max_hits, max_hits);
    std::fill(row.begin(), row.end(), SceneHit{});
    found[i] = 0;
    if (snapshot.top.wide.empty()) continue;
    if (!world_ray_walkable(rays[i])) {
      ++skipped;
      continue;
    }
    bool complete = true;
    found[i] = walk_all(snapshot, rays[i], row, scratch, outputs, cull, mask, complete);
    skipped += !complete;
  }
  return skipped;
}

}  // namespace meshcast
