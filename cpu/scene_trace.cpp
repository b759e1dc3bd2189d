// A snapshot's walk: the top level in double, each instance it reaches
// walked by its blob's own walker on the ray brought into its frame.
#include <algorithm>
#include <cfloat>
#include <cmath>

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
  double inv[3];  // 1 / dir, +-inf for a zero component
  float dir[3];
  float tmax;
  double pad;  // kBoxSlack of the farthest the ray's origin is from the scene's box
};

// The ray's entry into a widened box before `cut`, or false.
bool enters(const WorldRay& r, const layout::TopNode& n, double cut, double* entry) {
  double tn = 0, tf = cut * (1 + kBoxSlack);
  for (int a = 0; a < 3; ++a) {
    const double lo = n.min[a] - r.pad - r.org[a], hi = n.max[a] + r.pad - r.org[a];
    if (r.dir[a] == 0) {
      if (lo > 0 || hi < 0) return false;  // beside the slab, parallel to it
      continue;
    }
    const double t0 = lo * r.inv[a], t1 = hi * r.inv[a];
    tn = std::max(tn, std::min(t0, t1)), tf = std::min(tf, std::max(t0, t1));
  }
  *entry = tn;
  return tn <= tf;
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

// One ray. Returns false when some instance's frame could not take it (its
// local ray not walkable): that instance is not walked and the ray counted.
bool walk(const SceneSnapshot& s, const RayD& rd, SceneHit& best, HitOutputs outputs, Query query, Cull cull,
          uint8_t mask) {
  WorldRay r;
  for (int a = 0; a < 3; ++a) r.org[a] = rd.org[a], r.dir[a] = rd.dir[a], r.inv[a] = 1.0 / double(rd.dir[a]);
  r.tmax = rd.tmax;
  const layout::TopNode& root = s.top.nodes[0];
  double far = 0;
  for (int a = 0; a < 3; ++a) far = std::max({far, std::fabs(rd.org[a] - root.min[a]), std::fabs(rd.org[a] - root.max[a])});
  r.pad = far * kBoxSlack;
  bool complete = true;
  float cut = rd.tmax;  // the closest hit's t so far
  constexpr int kStack = 128;
  uint32_t stack[kStack];
  int top = 0;
  uint32_t node = 0;
  double entry;
  if (!enters(r, s.top.nodes[0], cut, &entry)) return true;
  for (;;) {
    const layout::TopNode& n = s.top.nodes[node];
    if (n.count == 0) {
      const uint32_t kids[2] = {node + 1, n.right};
      double e[2];
      const bool hit0 = enters(r, s.top.nodes[kids[0]], cut, &e[0]), hit1 = enters(r, s.top.nodes[kids[1]], cut, &e[1]);
      if (hit0 && hit1) {
        const int near = e[1] < e[0] ? 1 : 0;
        if (top < kStack) stack[top++] = kids[near ^ 1];
        else complete = false;  // deeper than a median split makes: not reached
        node = kids[near];
        continue;
      }
      if (hit0 || hit1) {
        node = kids[hit0 ? 0 : 1];
        continue;
      }
    } else {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        const layout::PlacedInstance& p = s.top.placed[i];
        if ((p.mask & mask) == 0) continue;
        Ray local = to_local(r, p);
        local.tmax = cut;
        Hit h;
        // A local ray the walkers refuse (its direction scaled past their
        // range) is counted, not walked.
        if (s.meshes[p.mesh]->view.trace(std::span(&local, 1), std::span(&h, 1), outputs, query,
                                         as_instance_sees(cull, p.mirrored != 0)) != 0)
          complete = false;
        // Equal t: the lower instance id, as the oracle breaks ties.
        if (h.triangle != kNoHit && (h.t < cut || best.instance == kNoHit || (h.t == cut && p.id < best.instance))) {
          best = {h.t, p.id, h.triangle, h.u, h.v};
          cut = h.t;
          if (query == Query::Any) return complete;
        }
      }
    }
    // Pop the next box still entered before the cut.
    for (;;) {
      if (top == 0) return complete;
      node = stack[--top];
      if (enters(r, s.top.nodes[node], cut, &entry)) break;
    }
  }
}

}  // namespace

uint64_t trace_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, std::span<SceneHit> hits,
                        HitOutputs outputs, Query query, Cull cull, uint8_t mask) {
  if (hits.size() < rays.size())
    throw UsageError("Scene::trace: " + std::to_string(rays.size()) + " rays but " + std::to_string(hits.size()) +
                     " hits; the hits span must hold one hit a ray");
  if (query == Query::All) throw UsageError("Scene::trace: Query::All is not answered on scenes yet");
  if (has(outputs, HitOutputs::Point)) throw UsageError("Scene::trace: a scene hit carries no point (HitOutputs::Point)");
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    hits[i] = SceneHit{};
    if (snapshot.top.nodes.empty()) continue;
    if (!world_ray_walkable(rays[i])) {
      ++skipped;
      continue;
    }
    if (!walk(snapshot, rays[i], hits[i], outputs, query, cull, mask)) ++skipped;
  }
  return skipped;
}

}  // namespace meshcast
