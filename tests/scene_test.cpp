// Scenes: generated levels of placed, rotated, scaled and
// mirrored instances, at the origin and 10^6 and 10^7 units from it,
// against the double-precision scene oracle (check/scene_oracle.h); the
// closed sphere and the grid far away; edits and commits; bad input.
// gpu_scene_test (MESHCAST_TEST_GPU) walks the same levels and probes
// through the Vulkan scene method (gpu/scene.h) on the recommended layout,
// on the machine's device (lavapipe in CI) with the validation layers on,
// and checks it against the CPU bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <string>

#include "builder/error_bounds.h"
#include "check/generate.h"
#include "check/scene_oracle.h"
#include "layout/message_text.h"
#include "meshcast/scene.h"
#include "tests/testing.h"
#ifdef MESHCAST_TEST_GPU
#include <map>

#include "gpu/scene.h"
#include "gpu/vulkan.h"
#include "layout/queries.h"
#endif

namespace meshcast::testing {
namespace {

#ifdef MESHCAST_TEST_GPU
constexpr bool kGpu = true;
gpu::Context& context() {
  static gpu::Context ctx(gpu::DeviceChoice{"", true});
  return ctx;
}
// The scene method for a query, culling and outputs, made once.
gpu::SceneMethod& scene_method(Query query, Cull cull, HitOutputs outputs) {
  gpu::Context& ctx = context();  // made before the methods, so gone after them at exit
  static std::map<uint32_t, std::unique_ptr<gpu::SceneMethod>> made;
  const uint32_t flags = layout::query_bits(query, cull) | (has(outputs, HitOutputs::Uv) ? MC_HIT_UV : 0u);
  std::unique_ptr<gpu::SceneMethod>& m = made[flags];
  if (!m) m = std::make_unique<gpu::SceneMethod>(ctx, flags);
  return *m;
}
#else
constexpr bool kGpu = false;
#endif

// The layouts the levels are built in: the GPU build walks the ones its
// scene method reads.
std::vector<std::string> walked_layouts() {
  if (kGpu) return {"OctTreeCompressed/ClusterBitPackSOA8", "OctTreeCompressed/ClusterFloat3SOA8"};
  return {"OctTreeCompressed/ClusterBitPackSOA8", "AABBTree/Float3", "QuadTreeHalfFloat/Indexed8BitPackSOA4"};
}

// A level: its meshes (as their blobs store them), blobs and instances.
struct Level {
  std::vector<Mesh> meshes;  // as stored (the oracle's)
  std::vector<std::vector<uint8_t>> blobs;
  std::vector<OracleInstance> instances;
  std::vector<bool> enabled;
  double offset = 0;  // added to every translation and ray origin
};

// A random rotation (a unit quaternion from 4 normals) times a scale per
// axis; `mirror` negates the first column.
Transform random_transform(std::mt19937& rng, double spread, double offset, bool uniform, bool mirror) {
  const std::array<double, 9> r = random_rotation(rng);
  std::uniform_real_distribution<double> s(0.5, 3.0), u(-spread, spread);
  const double base = s(rng);
  const double scale[3] = {base, uniform ? base : s(rng), uniform ? base : s(rng)};
  Transform t;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col)
      t.rotation_scale[3 * row + col] = float(r[3 * row + col] * scale[col] * (mirror && col == 0 ? -1 : 1));
  for (int a = 0; a < 3; ++a) t.translation[a] = offset + std::round(u(rng));
  return t;
}

// `count` instances of a sphere, a terrain patch and an unwelded sphere
// (every triangle its own corners), built with `layout`, spread over a cube
// of 2 `spread` around `offset`: every 3rd mirrored, every 4th scaled
// unevenly, every 5th with its faces flipped, masks 1, 2, 4 or all, every
// 7th disabled.
Level make_level(const std::string& layout, size_t count, double spread, double offset, uint32_t seed) {
  Level level;
  level.offset = offset;
  const BuildOptions options = parse_layout(layout);
  for (const Mesh& m : {make_sphere(10, 14, 1.0f, {0, 0, 0}), make_terrain(8, 8, 5), unwelded(make_sphere(6, 9, 1.5f, {0.5f, 0, 0}))}) {
    level.blobs.push_back(build_blob(m, options, "level mesh"));
    level.meshes.push_back(moves_vertices(uint32_t(options.layout.triangles)) ? stored_mesh(level.blobs.back()) : m);
  }
  std::mt19937 rng(seed);
  const uint8_t masks[4] = {1, 2, 4, 0xFF};
  for (uint32_t i = 0; i < count; ++i) {
    const Transform t = random_transform(rng, spread, offset, i % 4 != 0, i % 3 == 0);
    level.instances.push_back({i, i % 3, t, masks[i % 4], i % 5 == 2});
    level.enabled.push_back(i % 7 != 6);
  }
  return level;
}

// The scene's mesh and instance at an index (the oracle's numbers).
MeshId mesh_of(const Scene& scene, uint32_t index) { return {index, scene.number()}; }
InstanceId instance_of(const Scene& scene, uint32_t index) { return {index, scene.number()}; }

Scene make_scene(const Level& level) {
  Scene scene;
  for (size_t m = 0; m < level.blobs.size(); ++m) scene.add_mesh(level.blobs[m], "level mesh " + std::to_string(m));
  for (size_t i = 0; i < level.instances.size(); ++i) {
    const OracleInstance& o = level.instances[i];
    EXPECT_EQ(scene.add_instance(mesh_of(scene, o.mesh), o.transform, o.mask, o.flip_facing).index, o.id);
    if (!level.enabled[i]) scene.set_enabled(instance_of(scene, o.id), false);
  }
  scene.commit();
  return scene;
}

SceneOracle oracle_of(const Level& level) {
  std::vector<const Mesh*> meshes;
  for (const Mesh& m : level.meshes) meshes.push_back(&m);
  std::vector<OracleInstance> enabled;
  for (size_t i = 0; i < level.instances.size(); ++i)
    if (level.enabled[i]) enabled.push_back(level.instances[i]);
  return SceneOracle(meshes, enabled);
}

// Rays from random points of the level's cube towards random instances'
// places (a unit's jitter), a third of them with a finite t_max.
std::vector<RayD> level_rays(const Level& level, size_t count, double spread, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-spread, spread), jitter(-1.5, 1.5), reach(5, 400);
  std::vector<RayD> rays(count);
  for (size_t i = 0; i < count; ++i) {
    const Transform& target = level.instances[rng() % level.instances.size()].transform;
    RayD& r = rays[i];
    for (int a = 0; a < 3; ++a) {
      r.org[a] = level.offset + u(rng);
      r.dir[a] = float(target.translation[a] + jitter(rng) - r.org[a]);
    }
    r.tmax = i % 3 == 0 ? float(reach(rng) / 400) : INFINITY;
  }
  return rays;
}

// One ray's rules, check/agreement.h's compare() for scenes: how far a
// scene hit may stray from the oracle's where only rounding decides (1e-5 of
// the distance from the ray's origin to the hit plus the instance's scale:
// the ray's place in an instance's frame is rounded to float, about 2^-22 of
// that distance; a layout's own error is in the stored mesh the oracle
// uses), and which differences are ties.
struct RayRules {
  RayRules(const SceneOracle& o, const RayD& ray)
      : oracle(o), r(ray),
        len(std::sqrt(double(r.dir[0]) * r.dir[0] + double(r.dir[1]) * r.dir[1] + double(r.dir[2]) * r.dir[2])) {}
  const SceneOracle& oracle;
  const RayD& r;
  const double len;
  double slack(double t) const { return 1e-5 * (t * len + 4); }
  bool same_t(double t, double oracle_t) const { return std::fabs(t - oracle_t) * len <= slack(oracle_t); }
  // At t_min (the origin when it is 0) or t_max, where rounding decides
  // whether a hit is on the segment.
  bool at_start(double t) const { return std::fabs(t - r.tmin) * len <= slack(t); }
  bool near_end(double t) const { return at_start(t) || std::fabs(t - r.tmax) * len <= slack(t); }
  // The hit's triangle meets the ray at its t.
  bool meets(const SceneHit& h) const {
    return oracle.distance_to(oracle.index_of(h.instance), h.triangle, r, h.t) <= slack(h.t);
  }
  // A hit the oracle does not have: on the ray, at its triangle's edge or
  // at the segment's ends.
  bool extra_is_tie(const SceneHit& h) const {
    return meets(h) && (oracle.distance_to_edge(oracle.index_of(h.instance), h.triangle, r, h.t) <= slack(h.t) ||
                        near_end(h.t));
  }
  // An oracle hit the walk does not have: a graze of its edge, or at the
  // segment's ends.
  bool missing_is_tie(const SceneOracleHit& o) const {
    return oracle.distance_to_edge(oracle.index_of(o.instance), o.triangle, r, o.t) <= slack(o.t) || near_end(o.t);
  }
};

struct Judged {
  size_t hits = 0, ties = 0, wrong = 0;
  std::string first_problem;
  void fail(const std::string& why) {
    if (wrong++ == 0) first_problem = why;
  }
};

std::string named(uint32_t instance, uint32_t triangle) {
  return "instance " + std::to_string(instance) + " triangle " + std::to_string(triangle);
}

// The oracle's instance, triangle and t; where only rounding decides
// (another triangle at the same place, a graze of the hit triangle's edge,
// the segment's ends) a tie. `any`: a hit is one of the oracle's hits under
// the same culling and mask (or a tie), any of them.
Judged judge(const SceneOracle& oracle, const std::vector<RayD>& rays, const std::vector<SceneHit>& hits, Cull cull,
             uint8_t mask, bool any) {
  Judged j;
  for (size_t i = 0; i < rays.size(); ++i) {
    const RayRules rules(oracle, rays[i]);
    const SceneHit& h = hits[i];
    const SceneOracleHit o = oracle.closest(rays[i], cull, mask);
    const std::string where = "ray " + std::to_string(i) + ": ";
    if (h.instance == kNoHit && o.instance == kNoHit) continue;
    if (h.instance != kNoHit) ++j.hits;
    if (h.instance != kNoHit && o.instance != kNoHit) {
      if (any) {
        const std::vector<SceneOracleHit> every = oracle.all(rays[i], cull, mask);
        const auto m = std::find_if(every.begin(), every.end(), [&](const SceneOracleHit& e) {
          return e.instance == h.instance && e.triangle == h.triangle;
        });
        if (m != every.end() ? !rules.same_t(h.t, m->t) : !rules.extra_is_tie(h))
          j.fail(where + "any-hit's " + named(h.instance, h.triangle) + " at " + std::to_string(h.t) +
                 " is not a hit under this culling and mask");
        continue;
      }
      const bool same = h.instance == o.instance && h.triangle == o.triangle;
      // One of them at t_min > 0, where rounding decides whether it is on
      // the segment: the other is the next hit along.
      if (!same && rays[i].tmin > 0 && (rules.at_start(h.t) || rules.at_start(o.t)) && rules.meets(h)) ++j.ties;
      else if (!rules.same_t(h.t, o.t)) j.fail(where + "t " + std::to_string(h.t) + " against " + std::to_string(o.t));
      else if (!same && !rules.meets(h)) j.fail(where + named(h.instance, h.triangle) + " against " + named(o.instance, o.triangle));
      else if (!same) ++j.ties;
    } else if (h.instance == kNoHit) {
      if (rules.missing_is_tie(o)) ++j.ties;
      else j.fail(where + "a miss where the oracle hits " + named(o.instance, o.triangle) + " at " + std::to_string(o.t));
    } else {
      if (rules.extra_is_tie(h)) ++j.ties;
      else j.fail(where + "a hit of " + named(h.instance, h.triangle) + " where the oracle misses");
    }
  }
  return j;
}

// Query::All: each row against the oracle's set, under the same rules
// pair by pair; rows in order of t, found[i] the row's length (rows long
// enough for every hit).
Judged judge_all(const SceneOracle& oracle, const std::vector<RayD>& rays, const SceneHitLists& lists, Cull cull,
                 uint8_t mask) {
  Judged j;
  for (size_t i = 0; i < rays.size(); ++i) {
    const RayRules rules(oracle, rays[i]);
    const std::vector<SceneOracleHit> want = oracle.all(rays[i], cull, mask);
    const std::span<const SceneHit> row = lists.row(i);
    const std::string where = "ray " + std::to_string(i) + ": ";
    if (lists.found[i] != row.size()) j.fail(where + "found " + std::to_string(lists.found[i]) + " hits for a row of " + std::to_string(row.size()));
    for (size_t k = 1; k < row.size(); ++k)
      if (row[k].t < row[k - 1].t) j.fail(where + "the row is not in order of t");
    j.hits += row.size();
    for (const SceneOracleHit& o : want) {
      const auto m = std::find_if(row.begin(), row.end(), [&](const SceneHit& h) { return h.instance == o.instance && h.triangle == o.triangle; });
      if (m != row.end() ? !rules.same_t(m->t, o.t) : !rules.missing_is_tie(o))
        j.fail(where + named(o.instance, o.triangle) + (m != row.end() ? " at t " + std::to_string(m->t) + " against " + std::to_string(o.t) : " missing"));
      else if (m == row.end()) ++j.ties;
    }
    for (const SceneHit& h : row) {
      if (std::any_of(want.begin(), want.end(), [&](const SceneOracleHit& o) { return o.instance == h.instance && o.triangle == h.triangle; }))
        continue;
      if (rules.extra_is_tie(h)) ++j.ties;
      else j.fail(where + named(h.instance, h.triangle) + " is no hit");
    }
  }
  return j;
}

// The scene's answers: the CPU's, or in the GPU build the Vulkan scene
// method's on the committed snapshot.
std::vector<SceneHit> trace(const Scene& scene, const std::vector<RayD>& rays, Query query = Query::Closest,
                            Cull cull = Cull::None, uint8_t mask = 0xFF, HitOutputs outputs = HitOutputs::None) {
  std::vector<SceneHit> hits(rays.size());
#ifdef MESHCAST_TEST_GPU
  EXPECT_EQ(scene_method(query, cull, outputs).trace(*scene.snapshot(), rays, hits, mask), 0u);
#else
  EXPECT_EQ(scene.trace(rays, hits, outputs, query, cull, mask), 0u);
#endif
  return hits;
}

// A snapshot's answers: trace_snapshot's, or in the GPU build the Vulkan
// scene method's.
std::vector<SceneHit> trace_snapshot_here(const SceneSnapshot& snapshot, const std::vector<RayD>& rays) {
  std::vector<SceneHit> hits(rays.size());
#ifdef MESHCAST_TEST_GPU
  EXPECT_EQ(scene_method(Query::Closest, Cull::None, HitOutputs::None).trace(snapshot, rays, hits), 0u);
#else
  EXPECT_EQ(trace_snapshot(snapshot, rays, hits), 0u);
#endif
  return hits;
}

class SceneVsOracle : public ::testing::TestWithParam<std::tuple<std::string, double>> {};

// Every query and culling, masks, on a level of 60 instances over a
// cube of 200 units, against the oracle; the level 10^6 and 10^7 units away
// answers as at the origin.
TEST_P(SceneVsOracle, GeneratedLevel) {
  const auto& [layout, offset] = GetParam();
  constexpr double kSpread = 100;
  const Level level = make_level(layout, 60, kSpread, offset, 7);
  const Scene scene = make_scene(level);
  const SceneOracle oracle = oracle_of(level);
  const std::vector<RayD> rays = level_rays(level, quick() ? 400 : 1500, kSpread, 11);
  struct Case {
    Query query;
    Cull cull;
    uint8_t mask;
  };
  for (const Case c : {Case{Query::Closest, Cull::None, 0xFF}, Case{Query::Closest, Cull::Back, 0xFF},
                       Case{Query::Closest, Cull::Front, 0x02}, Case{Query::Any, Cull::None, 0xFF},
                       Case{Query::Any, Cull::Back, 0x05}}) {
    const std::vector<SceneHit> hits = trace(scene, rays, c.query, c.cull, c.mask);
    const Judged j = judge(oracle, rays, hits, c.cull, c.mask, c.query == Query::Any);
    const std::string what = layout + " at " + std::to_string(offset) + ", query " + std::to_string(int(c.query)) +
                             ", cull " + std::to_string(int(c.cull)) + ", mask " + std::to_string(c.mask);
    EXPECT_EQ(j.wrong, 0u) << what << ": " << j.first_problem;
    EXPECT_LE(j.ties, rays.size() / 100) << what;
    EXPECT_GT(j.hits, rays.size() / (c.mask == 0xFF ? 5 : 10)) << what << ": too few hits to show anything";
  }
  // t_min, the rule of a blob's walk (meshcast/scene.h): each ray from a
  // fraction of its closest hit's t on (half of it, 1.001 and 1.02 times
  // it: a world unit or so past the hit, inside the instance, in turn by
  // threes, as the finite t_max go by ones; a ray that misses from half
  // its t_max, or 1), so some keep their first hit and some find the next
  // one along (the instance's far side); closest, any and every hit.
  std::vector<RayD> offset_rays = rays;
  size_t skipped_first = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    RayD& r = offset_rays[i];
    const SceneOracleHit o = oracle.closest(rays[i]);
    const size_t turn = i / 3 % 3;
    if (o.instance == kNoHit) r.tmin = std::isfinite(r.tmax) ? r.tmax * 0.5f : 1.0f;
    else r.tmin = std::min(r.tmax, float(o.t * (turn == 0 ? 0.5 : turn == 1 ? 1.001 : 1.02)));
    const SceneOracleHit next = oracle.closest(r);
    skipped_first += o.instance != kNoHit && next.instance != kNoHit && (next.instance != o.instance || next.triangle != o.triangle);
  }
  EXPECT_GT(skipped_first, rays.size() / 50) << layout << " at " << offset << ", t_min: too few rays find a next hit";
  for (const Query q : {Query::Closest, Query::Any}) {
    const Judged j = judge(oracle, offset_rays, trace(scene, offset_rays, q), Cull::None, 0xFF, q == Query::Any);
    const std::string what = layout + " at " + std::to_string(offset) + ", t_min, query " + std::to_string(int(q));
    EXPECT_EQ(j.wrong, 0u) << what << ": " << j.first_problem;
    EXPECT_LE(j.ties, rays.size() / 100) << what;
    EXPECT_GT(j.hits, rays.size() / 10) << what << ": too few hits to show anything";
  }
  SceneHitLists offset_lists;
  offset_lists.max_hits = 256;
  EXPECT_EQ(scene.trace_all_hits(offset_rays, offset_lists), 0u);
  const Judged offset_all = judge_all(oracle, offset_rays, offset_lists, Cull::None, 0xFF);
  EXPECT_EQ(offset_all.wrong, 0u) << layout << " at " << offset << ", t_min, Query::All: " << offset_all.first_problem;
  EXPECT_LE(offset_all.ties, offset_all.hits / 100 + 2) << layout << " at " << offset << ", t_min, Query::All";
  // Every hit, front faces culled and mask 3, rows long enough for all.
  SceneHitLists lists;
  lists.max_hits = 256;
  EXPECT_EQ(scene.trace_all_hits(rays, lists, HitOutputs::None, Cull::Front, 0x03), 0u);
  const Judged all = judge_all(oracle, rays, lists, Cull::Front, 0x03);
  EXPECT_EQ(all.wrong, 0u) << layout << " at " << offset << ", Query::All: " << all.first_problem;
  EXPECT_LE(all.ties, all.hits / 100 + 2) << layout << " at " << offset << ", Query::All";
  EXPECT_GT(all.hits, rays.size() / 5) << layout << " at " << offset << ", Query::All: too few hits to show anything";
  // Rows of 2 where more are hit: the nearest 2 of the full rows (judged
  // above, here two-sided), every hit still counted. The full rows keep up
  // to kMaxHitsLimit a ray and hold the hits found alone (compact rows:
  // their memory follows the hits, not rays x max_hits).
  SceneHitLists full, short_rows;
  full.max_hits = kMaxHitsLimit, short_rows.max_hits = 2;
  EXPECT_EQ(scene.trace_all_hits(rays, full), 0u);
  EXPECT_EQ(scene.trace_all_hits(rays, short_rows), 0u);
  ASSERT_EQ(full.found.size(), rays.size());
  size_t kept = 0;
  for (uint32_t found : full.found) kept += std::min(found, kMaxHitsLimit);
  ASSERT_EQ(full.hits.size(), kept) << layout << " at " << offset << ": rows holding more than the hits found";
  EXPECT_LE(full.hits.capacity(), 2 * kept + kMaxHitsLimit) << layout << " at " << offset;
  size_t overflowing = 0, differ = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    overflowing += full.found[i] > 2;
    differ += short_rows.found[i] != full.found[i];
    for (size_t k = 0; k < std::min<size_t>(2, full.found[i]); ++k)
      differ += short_rows.row(i)[k].instance != full.row(i)[k].instance ||
                short_rows.row(i)[k].triangle != full.row(i)[k].triangle || short_rows.row(i)[k].t != full.row(i)[k].t;
  }
  EXPECT_EQ(differ, 0u) << layout << " at " << offset << ": rows of 2 against rows of 256";
  EXPECT_GT(overflowing, rays.size() / 50) << layout << " at " << offset << ": too few rays hit more than twice";
  // u, v: the hit's point on its triangle's world corners.
  const std::vector<SceneHit> uv = trace(scene, rays, Query::Closest, Cull::None, 0xFF, HitOutputs::Uv);
  size_t off_triangle = 0, with_uv = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (uv[i].instance == kNoHit) continue;
    ++with_uv;
    const RayRules rules(oracle, rays[i]);
    off_triangle += oracle.distance_to_uv(oracle.index_of(uv[i].instance), uv[i].triangle, rays[i], uv[i].t, uv[i].u,
                                          uv[i].v) > rules.slack(uv[i].t);
  }
  EXPECT_EQ(off_triangle, 0u) << layout << " at " << offset << ": u, v away from the hit's point";
  EXPECT_GT(with_uv, rays.size() / 5) << layout << " at " << offset;
  if (offset != 0) {
    // The same level at the origin: the same instance and triangle for every
    // ray but a rounding's worth, the same t to float rounding.
    Level home = make_level(layout, 60, kSpread, 0, 7);
    const Scene at_home = make_scene(home);
    std::vector<RayD> home_rays = rays;
    for (RayD& r : home_rays)
      for (double& o : r.org) o -= offset;
    const std::vector<SceneHit> far = trace(scene, rays), near = trace(at_home, home_rays);
    size_t differ = 0;
    for (size_t i = 0; i < rays.size(); ++i)
      differ += far[i].instance != near[i].instance || far[i].triangle != near[i].triangle ||
                std::fabs(far[i].t - near[i].t) > 1e-5f * (1 + near[i].t);
    EXPECT_LE(differ, rays.size() / 200) << layout << " at " << offset << " against the origin";
  }
}

INSTANTIATE_TEST_SUITE_P(Layouts, SceneVsOracle,
                         ::testing::Combine(::testing::ValuesIn(walked_layouts()), ::testing::Values(0.0, 1e6, 1e7)));

// A closed sphere 10^7 units away, plain and mirrored, rays from all
// around it through its inside: every ray hits, under every query and
// culling (the near side's outer face where the front is kept, the far
// side's inner face where the back is: a mirror turns nothing).
TEST(Scene, ClosedSphereFarAwayLeaksNothing) {
  const Mesh sphere = make_sphere(24, 32, 2.0f, {0, 0, 0});
  for (const std::string& layout : walked_layouts()) {
    if (layout.rfind("QuadTree", 0) == 0) continue;  // the octtree and the AABB tree suffice
    Scene scene;
    const MeshId m = scene.add_mesh(build_blob(sphere, parse_layout(layout), "sphere"), "sphere");
    std::mt19937 rng(3);
    Transform plain = random_transform(rng, 0, 1e7, true, false), mirrored = random_transform(rng, 0, 1e7, false, true);
    mirrored.translation[0] += 20;
    scene.add_instance(m, plain);
    scene.add_instance(m, mirrored);
    scene.commit();
    std::normal_distribution<double> n(0, 1);
    std::uniform_real_distribution<double> inside(-0.5, 0.5);
    const size_t count = quick() ? 2000 : 10000;
    std::vector<RayD> rays(count);
    for (size_t i = 0; i < count; ++i) {
      const Transform& at = i % 2 ? mirrored : plain;
      double d[3] = {n(rng), n(rng), n(rng)};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (int a = 0; a < 3; ++a) {
        const double target = at.translation[a] + inside(rng);
        rays[i].org[a] = target + 9 * d[a] / len;
        rays[i].dir[a] = float(target - rays[i].org[a]);
      }
      rays[i].tmax = INFINITY;
    }
    // Each ray aims at a point inside its sphere at t = 1: it enters
    // before and leaves after. The sphere's outside is its front on both
    // instances: facing is decided in the mesh's frame (Transform).
    for (Query q : {Query::Closest, Query::Any})
      for (Cull c : {Cull::None, Cull::Back, Cull::Front}) {
        const std::vector<SceneHit> hits = trace(scene, rays, q, c);
        size_t leaks = 0, wrong_side = 0;
        // Past its sphere a ray may go on to the other: any hit may be there.
        for (size_t i = 0; i < count; ++i) {
          leaks += q == Query::Any ? hits[i].instance == kNoHit : hits[i].instance != (i % 2 ? 1u : 0u);
          if (q == Query::Closest && c != Cull::None) wrong_side += c == Cull::Back ? !(hits[i].t < 1) : !(hits[i].t > 1);
          if (q == Query::Closest && c == Cull::None) wrong_side += !(hits[i].t < 1);
        }
        EXPECT_EQ(leaks, 0u) << layout << ", query " << int(q) << ", cull " << int(c);
        EXPECT_EQ(wrong_side, 0u) << layout << ", query " << int(q) << ", cull " << int(c);
      }
  }
}

// Facing is the mesh's own (Transform): a closed sphere whose outside is
// its front, scaled unevenly, placed 10^7 units away plain and mirrored
// (the same rotation and scales, the first column negated: the same
// surface, its corners running the other way in the world), and both again
// with flip_facing; rays from outside aimed at a point inside, ending
// there (an occlusion probe, t_max 1) or going on. Without flip_facing
// both show their outside as front: Cull::Back keeps the near side (t <
// 1), so every probe is occluded and nothing leaks through a mirrored
// prop; Cull::Front keeps the far side's inside (t > 1, a probe sees
// nothing). With flip_facing the other way round. Every answer also
// against the oracle, which reads facing off the world corners' winding
// and the determinant's sign.
TEST(Scene, MirroredInstancesFaceAsTheirMesh) {
  const Mesh sphere = make_sphere(24, 32, 2.0f, {0, 0, 0});
  for (const std::string& layout : walked_layouts()) {
    Level level;
    level.meshes.push_back(sphere);
    level.blobs.push_back(build_blob(sphere, parse_layout(layout), "sphere"));
    if (moves_vertices(uint32_t(parse_layout(layout).layout.triangles))) level.meshes[0] = stored_mesh(level.blobs[0]);
    std::mt19937 rng(41);
    const Transform plain = random_transform(rng, 0, 1e7, false, false);
    Transform mirrored = plain;
    for (int row = 0; row < 3; ++row) mirrored.rotation_scale[3 * row] = -mirrored.rotation_scale[3 * row];
    mirrored.translation[0] += 20;
    // 0 plain, 1 mirrored, 2 and 3 the same with their faces flipped.
    for (uint32_t k = 0; k < 4; ++k) {
      Transform t = k % 2 ? mirrored : plain;
      t.translation[2] += k / 2 * 20.0;
      level.instances.push_back({k, 0, t, 0xFF, false});
      level.enabled.push_back(true);
    }
    Scene scene = make_scene(level);
    // Flipped after the first commit; a new transform keeps the flag.
    for (uint32_t k : {2u, 3u}) {
      level.instances[k].flip_facing = true;
      scene.set_flip_facing(instance_of(scene, k), true);
    }
    scene.set_transform(instance_of(scene, 3), level.instances[3].transform);
    scene.commit();
    const SceneOracle oracle = oracle_of(level);
    std::normal_distribution<double> n(0, 1);
    std::uniform_real_distribution<double> inside(-0.5, 0.5);
    const size_t count = quick() ? 800 : 4000;
    std::vector<RayD> probes(count), through(count);
    for (size_t i = 0; i < count; ++i) {
      const Transform& at = level.instances[i % 4].transform;
      double d[3] = {n(rng), n(rng), n(rng)};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (int a = 0; a < 3; ++a) {
        const double target = at.translation[a] + inside(rng);  // the sphere's half axes are 1 at least
        probes[i].org[a] = target + 9 * d[a] / len;
        probes[i].dir[a] = float(target - probes[i].org[a]);
      }
      probes[i].tmax = 1;
      through[i] = probes[i];
      through[i].tmax = INFINITY;
    }
    for (const Query q : {Query::Closest, Query::Any})
      for (const Cull c : {Cull::None, Cull::Back, Cull::Front})
        for (const std::vector<RayD>* rays : {&probes, &through}) {
          const bool probe = rays == &probes;
          const std::vector<SceneHit> hits = trace(scene, *rays, q, c);
          size_t wrong = 0, ends_inside_hit = 0;
          std::string first;
          for (size_t i = 0; i < count; ++i) {
            const uint32_t own = uint32_t(i % 4);
            const bool outside_is_front = own < 2;  // flip_facing turns it; the mirror does not
            const bool near_kept = c == Cull::None || (c == Cull::Back) == outside_is_front;
            const SceneHit& h = hits[i];
            bool right;
            if (probe)  // it ends inside: only its own sphere's near side is on the segment
              right = near_kept ? h.instance == own && (q == Query::Any || h.t < 1) : h.instance == kNoHit;
            else if (q == Query::Any)
              right = h.instance != kNoHit;  // past its sphere it may reach another
            else
              right = h.instance == own && (near_kept ? h.t < 1 : h.t > 1);
            ends_inside_hit += probe && h.instance != kNoHit;
            if (!right && wrong++ == 0)
              first = "ray " + std::to_string(i) + " at instance " + std::to_string(own) + ": instance " +
                      std::to_string(h.instance) + " at t " + std::to_string(h.t);
          }
          const std::string what = layout + ", query " + std::to_string(int(q)) + ", cull " + std::to_string(int(c)) +
                                   (probe ? ", probes ending inside" : ", rays going through");
          EXPECT_EQ(wrong, 0u) << what << ": " << first;
          const Judged j = judge(oracle, *rays, hits, c, 0xFF, q == Query::Any);
          EXPECT_EQ(j.wrong, 0u) << what << " against the oracle: " << j.first_problem;
          EXPECT_LE(j.ties, count / 100) << what;
          // Two of the four instances keep their near side under culling.
          if (probe) {
            EXPECT_EQ(ends_inside_hit, c == Cull::None ? count : count / 2) << what;
          }
        }
    // Every hit, back faces culled: the near side alone on the plain and
    // the mirrored sphere, the far side's inside alone on the flipped ones.
    SceneHitLists lists;
    lists.max_hits = 16;
    EXPECT_EQ(scene.trace_all_hits(through, lists, HitOutputs::None, Cull::Back), 0u);
    size_t wrong_rows = 0;
    for (size_t i = 0; i < count; ++i) {
      const std::span<const SceneHit> row = lists.row(i);
      wrong_rows += row.empty() || row[0].instance != uint32_t(i % 4) || (i % 4 < 2 ? !(row[0].t < 1) : !(row[0].t > 1));
    }
    EXPECT_EQ(wrong_rows, 0u) << layout << ", Query::All";
    const Judged all = judge_all(oracle, through, lists, Cull::Back, 0xFF);
    EXPECT_EQ(all.wrong, 0u) << layout << ", Query::All against the oracle: " << all.first_problem;
  }
}

// A grid of unit cells 10^7 units away, rays straight down through its
// vertices and edge midpoints (the shared places): every one hits, the
// same triangle as the grid at the origin.
TEST(Scene, GridFarAwayLeaksNothingThroughSharedEdgesAndVertices) {
  const Mesh grid = make_grid_plane(16, 16);
  for (const std::string& layout : walked_layouts()) {
    if (layout.rfind("QuadTree", 0) == 0) continue;  // the octtree and the AABB tree suffice
    const std::vector<uint8_t> blob = build_blob(grid, parse_layout(layout), "grid");
    std::vector<SceneHit> answers[2];
    for (int far = 0; far < 2; ++far) {
      const double offset = far ? 1e7 : 0;
      Scene scene;
      Transform t;
      for (double& x : t.translation) x = offset;
      scene.add_instance(scene.add_mesh(blob, "grid"), t);
      scene.commit();
      std::vector<RayD> rays;
      for (int y = 1; y < 32; ++y)
        for (int x = 1; x < 32; ++x)
          rays.push_back({{offset + x * 0.5, offset + y * 0.5, offset + 3}, {0, 0, -1}, INFINITY});
      answers[far] = trace(scene, rays);
      size_t leaks = 0;
      for (const SceneHit& h : answers[far]) leaks += h.instance != 0 || h.t != 3.0f;
      EXPECT_EQ(leaks, 0u) << layout << " at " << offset;
    }
    for (size_t i = 0; i < answers[0].size(); ++i) EXPECT_EQ(answers[0][i].triangle, answers[1][i].triangle) << layout << ", ray " << i;
  }
}

// A plane 4 mm across 10^7 units away, at one end of a level 10 km long
// (the anchor 5 km from it), rays from 5 km off aimed at its edges. The
// instance walks the local ray the issue defines (the translation
// subtracted in double, rounded to float, scaled by the exact 1024 here);
// wherever that walk hits, the scene must give the same hit: the top
// level's float boxes and the ray's float origin against the anchor are
// each rounded by about 2^-24 of 5 km, more than the plane's own box is
// padded, and the walk's pad must cover that.
TEST(Scene, TopLevelCullsNoInstanceItsWalkWouldHit) {
  const std::vector<uint8_t> blob = build_blob(make_grid_plane(4, 4), parse_layout(walked_layouts()[0]), "plane");
  Scene scene;
  const MeshId m = scene.add_mesh(blob, "plane");
  Transform tiny, far_end;
  for (int a = 0; a < 3; ++a) tiny.rotation_scale[4 * a] = 0x1p-10f, tiny.translation[a] = far_end.translation[a] = 1e7;
  far_end.translation[0] += 1e4;
  scene.add_instance(m, tiny);
  scene.add_instance(m, far_end);
  scene.commit();
  const BlobView view(blob, "plane");
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> along(0, 4), up(0.2, 1), around(-1, 1);
  std::vector<RayD> rays;
  std::vector<Ray> local;
  for (int i = 0; i < 4000; ++i) {
    // A point on one of the plane's 4 edges, in its frame and the world.
    const double s = along(rng), edge[4][2] = {{s, 0}, {s, 4}, {0, s}, {4, s}};
    const double x = edge[i % 4][0], y = edge[i % 4][1];
    double d[3] = {around(rng), around(rng), up(rng)};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    RayD r;
    const double target[3] = {1e7 + x * 0x1p-10, 1e7 + y * 0x1p-10, 1e7};
    for (int a = 0; a < 3; ++a) {
      r.org[a] = target[a] + 5e3 * d[a] / len;
      r.dir[a] = float(target[a] - r.org[a]);
    }
    r.tmax = INFINITY;
    rays.push_back(r);
    Ray l;
    for (int a = 0; a < 3; ++a) l.org[a] = float(r.org[a] - 1e7) * 1024.0f, l.dir[a] = r.dir[a] * 1024.0f;
    l.tmax = INFINITY;
    local.push_back(l);
  }
  const std::vector<Hit> walked = trace_all(view, local);
  const std::vector<SceneHit> got = trace(scene, rays);
  size_t hits = 0, differ = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    hits += walked[i].triangle != kNoHit;
    // The GPU's walk may take the other triangle of an edge both meet at
    // the same t (gpu_test's rule for the blob methods).
    const bool same_triangle = got[i].triangle == walked[i].triangle || kGpu;
    differ += walked[i].triangle != kNoHit ? got[i].instance != 0 || !same_triangle || got[i].t != walked[i].t
                                           : got[i].instance != kNoHit;
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(hits, rays.size() / 5);  // aimed at the edges: about half hit
}

// Spheres of radius 1 and 10^-3 placed 10^12 to 10^30 units out, where
// half an ulp of the translation dwarfs the sphere (at 10^16 it is 1, at
// 10^30 about 7e13): the world box must still hold the instance. Rays from
// 5 radii around each sphere (the origin's offset rounded into the double
// as it may be) aimed inside it. Wherever the instance's own walk of the
// ray the scene defines (the offset from the translation in double,
// rounded to float) hits, the scene must give that hit; and aimed inside
// as they are, nearly all of them do.
TEST(Scene, SmallInstancesFarOutKeepTheirHits) {
  std::mt19937 rng(29);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> inside(-0.5, 0.5);
  for (const std::string& layout : walked_layouts()) {
    for (const float radius : {1.0f, 1e-3f}) {
      const std::vector<uint8_t> blob = build_blob(make_sphere(10, 14, radius, {0, 0, 0}), parse_layout(layout), "sphere");
      const BlobView view(blob, "sphere");
      for (const double far : {1e12, 1e16, 1e20, 1e25, 1e30}) {
        // On one axis, and on all three (a sign each), each a scene of its
        // own: the top level's pad grows with the scene's box, and two
        // instances far apart would hide a box too small by padding it.
        Transform on_x, diagonal;
        on_x.translation[0] = far;
        diagonal.translation[0] = far, diagonal.translation[1] = -far, diagonal.translation[2] = far;
        Scene scenes[2];
        for (int k = 0; k < 2; ++k) {
          scenes[k].add_instance(scenes[k].add_mesh(blob, "sphere"), k ? diagonal : on_x);
          scenes[k].commit();
        }
        std::vector<RayD> rays;
        std::vector<Ray> local;
        for (int i = 0; i < 200; ++i) {
          const Transform& at = i < 100 ? on_x : diagonal;
          double d[3] = {n(rng), n(rng), n(rng)};
          const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
          RayD r;
          Ray l;
          for (int a = 0; a < 3; ++a) {
            r.org[a] = at.translation[a] + 5 * radius * d[a] / len;
            const double offset = r.org[a] - at.translation[a];  // exact: the two are within a factor of 2
            r.dir[a] = float(radius * inside(rng) - offset);
            l.org[a] = float(offset), l.dir[a] = r.dir[a];
          }
          r.tmax = l.tmax = INFINITY;
          rays.push_back(r);
          local.push_back(l);
        }
        const std::vector<Hit> walked = trace_all(view, local);
        std::vector<SceneHit> got = trace(scenes[0], std::vector<RayD>(rays.begin(), rays.begin() + 100));
        const std::vector<SceneHit> second = trace(scenes[1], std::vector<RayD>(rays.begin() + 100, rays.end()));
        got.insert(got.end(), second.begin(), second.end());
        size_t hits = 0, differ = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
          hits += walked[i].triangle != kNoHit;
          const uint32_t expected = walked[i].triangle != kNoHit ? 0 : kNoHit;
          // The GPU's walk may take the other triangle of an edge both
          // meet at one t (gpu_test's rule for the blob methods).
          const bool same = got[i].instance == expected &&
                            (expected == kNoHit || ((got[i].triangle == walked[i].triangle || kGpu) && got[i].t == walked[i].t));
          differ += !same;
        }
        const std::string what = layout + ", radius " + number_text(radius) + " at " + number_text(far);
        EXPECT_EQ(differ, 0u) << what;
        EXPECT_GT(hits, rays.size() * 9 / 10) << what;
      }
    }
  }
}

// A direction component below FLT_MIN is read as 0 (walked_direction)
// on every path of a scene ray, by the oracle too. Rays along z through a
// grid in the plane z = 0 whose y, 2e-39 a unit of t, would carry them
// from just off the grid's edge y = 0 onto it by t = 5: read as 0, those
// from y = -1e-41 miss and those from y = +1e-41 hit, everywhere alike.
// (Its reciprocal overflowed to infinity, and the walkers culled what the
// oracle, in double, hit.)
TEST(Scene, DenormalDirectionComponentsAreReadAsZero) {
  for (const std::string& layout : walked_layouts()) {
    Level level;
    level.meshes.push_back(make_grid_plane(16, 16));
    level.blobs.push_back(build_blob(level.meshes[0], parse_layout(layout), "grid"));
    if (moves_vertices(uint32_t(parse_layout(layout).layout.triangles))) level.meshes[0] = stored_mesh(level.blobs[0]);
    level.instances.push_back({0, 0, Transform{}, 0xFF});
    level.enabled.push_back(true);
    const Scene scene = make_scene(level);
    const SceneOracle oracle = oracle_of(level);
    std::vector<RayD> rays;
    for (int i = 0; i < 64; ++i) {
      const double side = i % 2 ? 1e-41 : -1e-41;
      rays.push_back({{0.5 + 0.23 * i, side, -5}, {0, i % 4 < 2 ? 2e-39f : -2e-39f, 1}, INFINITY});
    }
    const std::vector<SceneHit> hits = trace(scene, rays);
    size_t wrong = 0;
    for (size_t i = 0; i < rays.size(); ++i) wrong += (hits[i].instance == 0) != (rays[i].org[1] > 0);
    EXPECT_EQ(wrong, 0u) << layout;
    const Judged j = judge(oracle, rays, hits, Cull::None, 0xFF, false);
    EXPECT_EQ(j.wrong, 0u) << layout << ": " << j.first_problem;
  }
}

// Edits show only after commit(); a snapshot keeps the frame it was taken
// at; each state against the oracle over the instances it has.
TEST(Scene, EditsShowAfterCommitAndSnapshotsKeepTheirFrame) {
  Level level = make_level("OctTreeCompressed/ClusterBitPackSOA8", 30, 40, 0, 21);
  Scene scene = make_scene(level);
  const std::vector<RayD> rays = level_rays(level, quick() ? 300 : 1000, 40, 5);
  const std::vector<SceneHit> before = trace(scene, rays);
  std::vector<SceneHit> last = before;  // the last committed frame's answers
  const std::shared_ptr<const SceneSnapshot> frame0 = scene.snapshot();
  std::mt19937 rng(9);
  for (int frame = 0; frame < 4; ++frame) {
    // Move a few, hide one, show one, remask one, remove one, add one.
    for (int k = 0; k < 5; ++k) {
      const uint32_t id = rng() % uint32_t(level.instances.size());
      if (level.instances[id].mask == 0) continue;  // removed
      level.instances[id].transform = random_transform(rng, 40, 0, k % 2 == 0, k == 3);
      scene.set_transform(instance_of(scene, id), level.instances[id].transform);
    }
    const uint32_t hide = rng() % uint32_t(level.instances.size()), show = rng() % uint32_t(level.instances.size());
    if (level.instances[hide].mask != 0) scene.set_enabled(instance_of(scene, hide), false), level.enabled[hide] = false;
    if (level.instances[show].mask != 0) scene.set_enabled(instance_of(scene, show), true), level.enabled[show] = true;
    const uint32_t gone = rng() % uint32_t(level.instances.size());
    if (level.instances[gone].mask != 0) {
      scene.remove_instance(instance_of(scene, gone));
      level.instances[gone].mask = 0, level.enabled[gone] = false;  // an oracle instance no ray mask reaches
      EXPECT_THROW(scene.set_mask(instance_of(scene, gone), 1), UsageError);
    }
    const OracleInstance added{uint32_t(level.instances.size()), uint32_t(frame % 3), random_transform(rng, 40, 0, true, false), 0xFF};
    EXPECT_EQ(scene.add_instance(mesh_of(scene, added.mesh), added.transform), instance_of(scene, added.id));
    level.instances.push_back(added), level.enabled.push_back(true);
    // Not committed yet: the last frame's answers, every one.
    const std::vector<SceneHit> uncommitted = trace(scene, rays);
    for (size_t i = 0; i < rays.size(); ++i) {
      EXPECT_EQ(uncommitted[i].instance, last[i].instance) << "frame " << frame << ", ray " << i;
      EXPECT_EQ(uncommitted[i].triangle, last[i].triangle) << "frame " << frame << ", ray " << i;
    }
    scene.commit();
    last = trace(scene, rays);
    const Judged j = judge(oracle_of(level), rays, last, Cull::None, 0xFF, false);
    EXPECT_EQ(j.wrong, 0u) << "frame " << frame << ": " << j.first_problem;
  }
  // The first frame's snapshot still answers as it did.
  std::vector<SceneHit> again(rays.size());
  trace_snapshot(*frame0, rays, again);
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(again[i].instance, before[i].instance) << "ray " << i;
    EXPECT_EQ(again[i].triangle, before[i].triangle) << "ray " << i;
  }
}

// A scene over blobs it does not own answers as one over its own copies:
// a level's blobs saved and mapped (MappedBlob), given shared and as
// BlobViews, the same hits bit for bit under every query and culling on
// the CPU and (gpu_scene_test) the Vulkan scene method, which uploads them
// from the mapping. The bytes are held once: the scene walks the mapped
// pages themselves and counts no copy of them, the shared mapping lives on
// in the scene (and in a snapshot outliving the scene) after the caller
// lets go, and a corrupted file is refused as a corrupted copy is.
TEST(Scene, ReferencedBlobsAnswerAsCopies) {
  const Level level = make_level("OctTreeCompressed/ClusterBitPackSOA8", 40, 60, 1e6, 19);
  std::vector<std::shared_ptr<const MappedBlob>> files;
  size_t blob_bytes = 0;
  for (size_t m = 0; m < level.blobs.size(); ++m) {
    const std::string path = (scratch_dir() / ("scene_mesh_" + std::to_string(m) + ".mcb")).string();
    save_blob(path, level.blobs[m]);
    files.push_back(std::make_shared<const MappedBlob>(path));
    blob_bytes += level.blobs[m].size();
  }
  const Scene copied = make_scene(level);
  Scene shared, viewed;
  for (size_t m = 0; m < files.size(); ++m) {
    const std::string name = "level mesh " + std::to_string(m);
    EXPECT_EQ(shared.add_mesh(std::shared_ptr(files[m]), name), mesh_of(shared, uint32_t(m)));
    EXPECT_EQ(viewed.add_mesh(BlobView(files[m]->bytes(), name), name), mesh_of(viewed, uint32_t(m)));
  }
  for (Scene* s : {&shared, &viewed}) {
    for (size_t i = 0; i < level.instances.size(); ++i) {
      const OracleInstance& o = level.instances[i];
      s->add_instance(mesh_of(*s, o.mesh), o.transform, o.mask, o.flip_facing);
      if (!level.enabled[i]) s->set_enabled(instance_of(*s, o.id), false);
    }
    s->commit();
  }
  // Held once: the scenes walk the mapped pages; only the copy counts bytes.
  for (size_t m = 0; m < files.size(); ++m) {
    EXPECT_EQ(shared.mesh_blob(mesh_of(shared, uint32_t(m))).data(), files[m]->bytes().data()) << m;
    EXPECT_EQ(viewed.mesh_blob(mesh_of(viewed, uint32_t(m))).data(), files[m]->bytes().data()) << m;
    EXPECT_EQ(viewed.mesh_blob(mesh_of(viewed, uint32_t(m))).size(), level.blobs[m].size()) << m;
    EXPECT_NE(copied.mesh_blob(mesh_of(copied, uint32_t(m))).data(), files[m]->bytes().data()) << m;
  }
  EXPECT_GE(copied.owned_blob_bytes(), blob_bytes);
  {  // A vector moved in is kept where it lies.
    std::vector<uint8_t> moved_in = level.blobs[0];
    const uint8_t* at = moved_in.data();
    Scene owner;
    EXPECT_EQ(owner.mesh_blob(owner.add_mesh(std::move(moved_in), "moved")).data(), at);
    EXPECT_EQ(owner.owned_blob_bytes(), level.blobs[0].size());
  }
  EXPECT_EQ(shared.owned_blob_bytes(), 0u);
  EXPECT_EQ(viewed.owned_blob_bytes(), 0u);
  EXPECT_THROW(viewed.mesh_blob(mesh_of(viewed, uint32_t(files.size()))), UsageError);
  EXPECT_THROW(viewed.mesh_blob(mesh_of(shared, 0)), UsageError);  // another scene's
  // The caller lets go of its mappings: the shared scene keeps its own.
  std::vector<const uint8_t*> mapped_at;
  for (const auto& f : files) mapped_at.push_back(f->bytes().data());
  std::vector<std::weak_ptr<const MappedBlob>> watched(files.begin(), files.end());
  const std::vector<RayD> rays = level_rays(level, quick() ? 400 : 1200, 60, 23);
  for (const Query q : {Query::Closest, Query::Any})
    for (const Cull c : {Cull::None, Cull::Back, Cull::Front}) {
      const std::vector<SceneHit> want = trace(copied, rays, q, c, 0xFF, HitOutputs::Uv);
      size_t hits = 0;
      for (const SceneHit& h : want) hits += h.instance != kNoHit;
      EXPECT_GT(hits, rays.size() / 10) << "query " << int(q) << ", cull " << int(c);
      for (const Scene* s : {&shared, &viewed}) {
        const std::vector<SceneHit> got = trace(*s, rays, q, c, 0xFF, HitOutputs::Uv);
        size_t differ = 0;
        for (size_t i = 0; i < rays.size(); ++i) differ += std::memcmp(&got[i], &want[i], sizeof(SceneHit)) != 0;
        EXPECT_EQ(differ, 0u) << (s == &shared ? "shared" : "viewed") << ", query " << int(q) << ", cull " << int(c);
      }
    }
  // Query::All (the CPU's) likewise.
  SceneHitLists want_rows, got_rows;
  want_rows.max_hits = got_rows.max_hits = 64;
  EXPECT_EQ(copied.trace_all_hits(rays, want_rows, HitOutputs::Uv, Cull::Back), 0u);
  EXPECT_EQ(viewed.trace_all_hits(rays, got_rows, HitOutputs::Uv, Cull::Back), 0u);
  ASSERT_EQ(got_rows.hits.size(), want_rows.hits.size());
  EXPECT_EQ(std::memcmp(got_rows.hits.data(), want_rows.hits.data(), want_rows.hits.size() * sizeof(SceneHit)), 0);
  EXPECT_EQ(got_rows.found, want_rows.found);
  files.clear();
  for (const auto& w : watched) EXPECT_FALSE(w.expired()) << "the shared scene let a mapping go";
  const std::vector<SceneHit> want = trace(copied, rays);
  {
    Scene moved = std::move(shared);
    const std::shared_ptr<const SceneSnapshot> frame = moved.snapshot();
    moved = Scene();  // the scene is gone; its snapshot keeps the mappings
    for (const auto& w : watched) EXPECT_FALSE(w.expired()) << "a snapshot let a mapping go";
    const std::vector<SceneHit> got = trace_snapshot_here(*frame, rays);
    size_t differ = 0;
    for (size_t i = 0; i < rays.size(); ++i) differ += std::memcmp(&got[i], &want[i], sizeof(SceneHit)) != 0;
    EXPECT_EQ(differ, 0u) << "the snapshot of a scene gone";
  }
  // A GPU scene method holds the meshes it uploaded until it uploads
  // others (gpu/scene.h): the copy's, here.
  trace_snapshot_here(*copied.snapshot(), rays);
  for (const auto& w : watched) EXPECT_TRUE(w.expired()) << "a mapping outlived every scene and snapshot holding it";
  // The same validation as a copy's: a flipped byte in the file is refused
  // with the copy's message.
  std::vector<uint8_t> corrupted = level.blobs[0];
  corrupted[corrupted.size() / 2] ^= 0x40;
  const std::string path = (scratch_dir() / "scene_mesh_corrupted.mcb").string();
  save_blob(path, corrupted);
  std::string copy_says, mapped_says;
  try {
    Scene().add_mesh(corrupted, "rock");
  } catch (const InputError& e) {
    copy_says = e.what();
  }
  try {
    Scene().add_mesh(std::make_shared<const MappedBlob>(path), "rock");
  } catch (const InputError& e) {
    mapped_says = e.what();
  }
  EXPECT_NE(copy_says, "") << "a corrupted copy was taken";
  EXPECT_EQ(mapped_says, copy_says);
  EXPECT_THROW(Scene().add_mesh(std::shared_ptr<const MappedBlob>(), "none"), UsageError);
}

#ifdef MESHCAST_TEST_GPU
// The Vulkan scene method against the CPU on the same snapshot: the same
// instance and bits of t for every ray under every culling and mask, at
// the origin and 10^7 away, and the same triangle, u and v but where two
// triangles meet the ray at the same t (the GPU's walk may take the other
// one: gpu_test's rule for the blob methods). Query::Any may take another
// hit where two boxes are entered at the same distance: the same rays hit.
// The same again with a t_min, and the t_min the CPU refuses counted.
TEST(SceneOnTheGpu, AnswersAsTheCpu) {
  for (const double offset : {0.0, 1e7}) {
    const Level level = make_level("OctTreeCompressed/ClusterBitPackSOA8", 60, 100, offset, 7);
    const Scene scene = make_scene(level);
    const std::vector<RayD> rays = level_rays(level, 1500, 100, 11);
    for (const Cull cull : {Cull::None, Cull::Back, Cull::Front})
      for (const uint8_t mask : {uint8_t(0xFF), uint8_t(0x02)})
        for (const Query query : {Query::Closest, Query::Any}) {
          const std::vector<SceneHit> gpu = trace(scene, rays, query, cull, mask, HitOutputs::Uv);
          std::vector<SceneHit> cpu(rays.size());
          ASSERT_EQ(scene.trace(rays, cpu, HitOutputs::Uv, query, cull, mask), 0u);
          size_t differ = 0, hits = 0;
          for (size_t i = 0; i < rays.size(); ++i) {
            hits += cpu[i].instance != kNoHit;
            if (query == Query::Any) {
              differ += (gpu[i].instance == kNoHit) != (cpu[i].instance == kNoHit);
              continue;
            }
            const bool tie = gpu[i].triangle != cpu[i].triangle && gpu[i].instance == cpu[i].instance;
            differ += tie ? std::memcmp(&gpu[i].t, &cpu[i].t, 4) != 0 : std::memcmp(&gpu[i], &cpu[i], sizeof(SceneHit)) != 0;
          }
          EXPECT_EQ(differ, 0u) << "offset " << offset << ", cull " << int(cull) << ", mask " << int(mask)
                                << ", query " << int(query);
          EXPECT_GT(hits, rays.size() / 10);
        }
    // t_min: from half, 1.25 and 2 times each ray's closest hit t (the
    // CPU's), the GPU's hits the CPU's bit for bit.
    std::vector<SceneHit> first(rays.size());
    ASSERT_EQ(scene.trace(rays, first), 0u);
    std::vector<RayD> offset_rays = rays;
    for (size_t i = 0; i < rays.size(); ++i)
      if (first[i].instance != kNoHit)
        offset_rays[i].tmin = std::min(rays[i].tmax, first[i].t * (i % 3 == 0 ? 0.5f : i % 3 == 1 ? 1.25f : 2.0f));
    for (const Query query : {Query::Closest, Query::Any}) {
      const std::vector<SceneHit> gpu = trace(scene, offset_rays, query, Cull::None, 0xFF, HitOutputs::Uv);
      std::vector<SceneHit> cpu(rays.size());
      ASSERT_EQ(scene.trace(offset_rays, cpu, HitOutputs::Uv, query), 0u);
      size_t differ = 0, moved = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        moved += cpu[i].instance != first[i].instance || cpu[i].triangle != first[i].triangle;
        if (query == Query::Any) {
          differ += (gpu[i].instance == kNoHit) != (cpu[i].instance == kNoHit) ||
                    (gpu[i].instance != kNoHit && !(gpu[i].t >= offset_rays[i].tmin && gpu[i].t <= offset_rays[i].tmax));
          continue;
        }
        const bool tie = gpu[i].triangle != cpu[i].triangle && gpu[i].instance == cpu[i].instance;
        differ += tie ? std::memcmp(&gpu[i].t, &cpu[i].t, 4) != 0 : std::memcmp(&gpu[i], &cpu[i], sizeof(SceneHit)) != 0;
      }
      EXPECT_EQ(differ, 0u) << "offset " << offset << ", t_min, query " << int(query);
      if (query == Query::Closest) {
        EXPECT_GT(moved, rays.size() / 20) << "offset " << offset << ": t_min changed too few hits";
      }
    }
  }
  // t_min refused as the CPU refuses it: NaN, negative, past t_max.
  const Level level = make_level("OctTreeCompressed/ClusterBitPackSOA8", 4, 10, 0, 7);
  const Scene scene = make_scene(level);
  std::vector<RayD> bad = level_rays(level, 4, 10, 3);
  bad[1].tmin = NAN, bad[2].tmin = -1.0f, bad[3].tmin = 2.0f, bad[3].tmax = 1.0f;
  std::vector<SceneHit> hits(bad.size());
  EXPECT_EQ(scene_method(Query::Closest, Cull::None, HitOutputs::None).trace(*scene.snapshot(), bad, hits), 3u);
  for (size_t i = 1; i < bad.size(); ++i) EXPECT_EQ(hits[i].instance, kNoHit) << i;
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

// Snapshots whose meshes are in another layout, every hit and the point:
// refused with the reason.
TEST(SceneOnTheGpu, RefusesWhatItDoesNotRead) {
  Scene scene;
  scene.add_instance(scene.add_mesh(build_blob(make_sphere(4, 6, 1, {0, 0, 0}), parse_layout("AABBTree/Float3"), "s"), "s"),
                     Transform{});
  scene.commit();
  const std::vector<RayD> rays = {{{0, 0, 5}, {0, 0, -1}, INFINITY}};
  std::vector<SceneHit> hits(1);
  EXPECT_THROW(scene_method(Query::Closest, Cull::None, HitOutputs::None).trace(*scene.snapshot(), rays, hits), InputError);
  EXPECT_THROW(gpu::SceneMethod(context(), MC_QUERY_ALL), UsageError);
  EXPECT_THROW(gpu::SceneMethod(context(), MC_HIT_POINT), UsageError);
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}
#else
// Frames that only move instances and change masks refit the top level
// (16 in a row, then a build): every frame against the oracle, moves large
// enough to carry instances across the level.
TEST(Scene, FramesOfMovesAlone) {
  Level level = make_level("AABBTree/Float3", 40, 60, 1e7, 33);
  Scene scene = make_scene(level);
  const std::vector<RayD> rays = level_rays(level, quick() ? 200 : 800, 60, 8);
  std::mt19937 rng(4);
  size_t hits = 0;  // over every frame (instances wander off the rays' targets)
  for (int frame = 0; frame < 20; ++frame) {
    for (int k = 0; k < 8; ++k) {
      const uint32_t id = rng() % uint32_t(level.instances.size());
      level.instances[id].transform = random_transform(rng, 60, 1e7, k % 2 == 0, k % 3 == 0);
      scene.set_transform(instance_of(scene, id), level.instances[id].transform);
    }
    const uint32_t remask = rng() % uint32_t(level.instances.size());
    level.instances[remask].mask = uint8_t(1u << (frame % 3));
    scene.set_mask(instance_of(scene, remask), level.instances[remask].mask);
    scene.commit();
    const Judged j = judge(oracle_of(level), rays, trace(scene, rays, Query::Closest, Cull::None, 0x03), Cull::None, 0x03, false);
    EXPECT_EQ(j.wrong, 0u) << "frame " << frame << ": " << j.first_problem;
    hits += j.hits;
  }
  EXPECT_GT(hits, 20 * rays.size() / 20) << "too few hits to show anything";
}

// Float rays (Scene's trace of Ray, widened 256 at a time on the stack)
// answer as the same rays given in double, across chunks; a short hits
// span is refused with the caller's sizes, an empty batch answers nothing.
TEST(Scene, FloatRaysAnswerAsTheirDoubleOrigins) {
  const Level level = make_level("OctTreeCompressed/ClusterBitPackSOA8", 40, 60, 0, 13);
  const Scene scene = make_scene(level);
  const std::vector<RayD> rays_d = level_rays(level, 700, 60, 14);
  std::vector<Ray> rays(rays_d.size());
  std::vector<RayD> widened_back(rays_d.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    for (int a = 0; a < 3; ++a) rays[i].org[a] = float(rays_d[i].org[a]), rays[i].dir[a] = rays_d[i].dir[a];
    rays[i].tmax = rays_d[i].tmax;
    widened_back[i] = widened(rays[i]);
  }
  // A chunk exactly, one past it, and 256 + 256 + 188.
  for (size_t n : {size_t(256), size_t(257), rays.size()}) {
    std::vector<SceneHit> from_float(n), from_double(n);
    EXPECT_EQ(scene.trace(std::span<const Ray>(rays).first(n), from_float, HitOutputs::Uv), 0u);
    EXPECT_EQ(scene.trace(std::span<const RayD>(widened_back).first(n), from_double, HitOutputs::Uv), 0u);
    size_t hits = 0;
    for (size_t i = 0; i < n; ++i) {
      hits += from_float[i].instance != kNoHit;
      EXPECT_EQ(std::bit_cast<uint32_t>(from_float[i].t), std::bit_cast<uint32_t>(from_double[i].t)) << n << ": " << i;
      EXPECT_EQ(from_float[i].instance, from_double[i].instance) << n << ": " << i;
      EXPECT_EQ(from_float[i].triangle, from_double[i].triangle) << n << ": " << i;
      EXPECT_EQ(from_float[i].u, from_double[i].u) << n << ": " << i;
      EXPECT_EQ(from_float[i].v, from_double[i].v) << n << ": " << i;
    }
    EXPECT_GT(hits, n / 4) << n;
  }
  std::vector<SceneHit> short_hits(rays.size() - 1);
  try {
    scene.trace(std::span<const Ray>(rays), short_hits);
    ADD_FAILURE() << "a short hits span was taken";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("700 rays but 699 hits"), std::string::npos) << e.what();
  }
  EXPECT_EQ(scene.trace(std::span<const Ray>(), std::span<SceneHit>()), 0u);
  EXPECT_THROW(scene.trace(std::span<const Ray>(), std::span<SceneHit>(), HitOutputs::Point), UsageError);
}

// Commits with nothing to walk (a new scene, every instance hidden) and
// moves of hidden instances, frame after frame: misses, no fault.
TEST(Scene, CommitsOfNothing) {
  Scene scene;
  scene.commit();
  scene.commit();
  std::vector<RayD> rays = {{{0, 0, 5}, {0, 0, -1}, INFINITY}};
  std::vector<SceneHit> hits(1);
  EXPECT_EQ(scene.trace(rays, hits), 0u);
  EXPECT_EQ(hits[0].instance, kNoHit);
  const MeshId m = scene.add_mesh(build_blob(make_sphere(4, 6, 1, {0, 0, 0}), parse_layout("AABBTree/Float3"), "s"), "s");
  const InstanceId a = scene.add_instance(m, Transform{});
  scene.set_enabled(a, false);
  for (int frame = 0; frame < 3; ++frame) {
    Transform t;
    t.translation[0] = frame;
    scene.set_transform(a, t);
    scene.set_mask(a, 3);
    scene.commit();
    EXPECT_EQ(scene.trace(rays, hits), 0u);
    EXPECT_EQ(hits[0].instance, kNoHit) << "frame " << frame;
  }
  scene.set_enabled(a, true);
  scene.set_transform(a, Transform{});  // back under the ray
  scene.commit();
  scene.trace(rays, hits);
  EXPECT_EQ(hits[0].instance, a.index);
}

// A scene given meshes and instances, cast before its first commit: every
// cast, point query and snapshot refused, saying to commit (its first frame
// holds none of them: every ray would miss); answered once committed. A
// scene nothing was added to is empty, committed or not.
TEST(Scene, CastsBeforeTheFirstCommitAreRefused) {
  Scene scene;
  const MeshId m = scene.add_mesh(build_blob(make_sphere(4, 6, 1, {0, 0, 0}), parse_layout("OctTreeCompressed/ClusterFloat3SOA8"), "s"), "s");
  const std::vector<RayD> rays = {{{0, 0, 5}, {0, 0, -1}, INFINITY}};
  const std::vector<Ray> float_rays = {{{0, 0, 5}, {0, 0, -1}, INFINITY}};
  std::vector<SceneHit> hits(1);
  SceneHitLists lists;
  lists.max_hits = 2;
  const std::vector<std::array<double, 3>> points = {{0, 0, 5}};
  std::vector<SceneClosestPoint> nearest(1);
  for (int added = 0; added < 2; ++added) {  // a mesh alone, then an instance of it
    const std::initializer_list<std::string> words = {"never committed", "commit it first"};
    expect_throws<UsageError>([&] { scene.trace(rays, hits); }, words);
    expect_throws<UsageError>([&] { scene.trace(float_rays, hits); }, words);
    expect_throws<UsageError>([&] { scene.trace_all_hits(rays, lists); }, words);
    expect_throws<UsageError>([&] { scene.closest_points(points, nearest); }, words);
    expect_throws<UsageError>([&] { scene.snapshot(); }, words);
    if (added == 0) scene.add_instance(m, Transform{});
  }
  scene.commit();
  EXPECT_EQ(scene.trace(rays, hits), 0u);
  EXPECT_FLOAT_EQ(hits[0].t, 4.0f);
  EXPECT_EQ(scene.closest_points(points, nearest), 0u);
  EXPECT_NEAR(nearest[0].distance, 4.0, 1e-3);
  Scene empty;
  hits[0] = SceneHit{0, 0, 0};
  EXPECT_EQ(empty.trace(rays, hits), 0u);
  EXPECT_EQ(hits[0].instance, kNoHit);
}

// An id is good with the scene that gave it alone: another scene refuses
// it by name, though its index is one the scene gave too, as it refuses a
// default-made id; a refused edit changes nothing. A moved scene keeps its
// number, so the ids it gave stay good.
TEST(Scene, RefusesIdsOfAnotherScene) {
  const std::vector<uint8_t> blob = build_blob(make_sphere(4, 6, 1, {0, 0, 0}), parse_layout("AABBTree/Float3"), "s");
  Scene scene, other;
  const MeshId mine = scene.add_mesh(blob, "s"), theirs = other.add_mesh(blob, "s");
  const InstanceId placed = scene.add_instance(mine, Transform{});
  const InstanceId their_placed = other.add_instance(theirs, Transform{});
  EXPECT_EQ(mine.index, theirs.index);
  EXPECT_EQ(placed.index, their_placed.index);
  EXPECT_NE(scene.number(), other.number());
  auto refused = [](const std::function<void()>& edit, const std::string& words) {
    try {
      edit();
      ADD_FAILURE() << "accepted: " << words;
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  const std::string given_by_other = "was given by another scene (scene " + std::to_string(other.number()) + ")";
  refused([&] { scene.add_instance(theirs, Transform{}); }, "Scene::add_instance: mesh 0 " + given_by_other);
  refused([&] { scene.mesh_blob(theirs); }, given_by_other);
  Transform moved;
  moved.translation[0] = 100;
  refused([&] { scene.set_transform(their_placed, moved); }, "Scene::set_transform: instance 0 " + given_by_other);
  refused([&] { scene.set_mask(their_placed, 0); }, given_by_other);
  refused([&] { scene.set_flip_facing(their_placed, true); }, given_by_other);
  refused([&] { scene.set_enabled(their_placed, false); }, given_by_other);
  refused([&] { scene.remove_instance(their_placed); }, given_by_other);
  refused([&] { scene.set_mask(InstanceId{}, 0); }, "no scene (a default-made id)");
  scene.commit();
  const std::vector<RayD> rays = {{{0, 0, 5}, {0, 0, -1}, INFINITY}};
  std::vector<SceneHit> hits(1);
  scene.trace(rays, hits);
  EXPECT_EQ(hits[0].instance, placed.index);
  EXPECT_FLOAT_EQ(hits[0].t, 4.0f);
  EXPECT_EQ(scene.instance_count(), 1u);
  // Moved, the scene keeps its number and its ids.
  Scene moved_to = std::move(scene);
  moved_to.set_transform(placed, moved);
  moved_to.commit();
  moved_to.trace(rays, hits);
  EXPECT_EQ(hits[0].instance, kNoHit);
}

TEST(Scene, RefusesBadInput) {
  Scene scene;
  EXPECT_THROW(scene.add_mesh({1, 2, 3}, "three bytes"), InputError);
  const MeshId m = scene.add_mesh(build_blob(make_sphere(4, 6, 1, {0, 0, 0}), parse_layout("AABBTree/Float3"), "s"), "s");
  Transform flat;
  flat.rotation_scale[8] = 0;  // not invertible
  EXPECT_THROW(scene.add_instance(m, flat), UsageError);
  Transform nan;
  nan.translation[1] = NAN;
  EXPECT_THROW(scene.add_instance(m, nan), UsageError);
  Transform far;
  far.translation[2] = 1e31;
  EXPECT_THROW(scene.add_instance(m, far), UsageError);
  EXPECT_THROW(scene.add_instance(MeshId{m.index + 1, m.scene}, Transform{}), UsageError);
  const InstanceId id = scene.add_instance(m, Transform{});
  EXPECT_THROW(scene.set_transform(id, flat), UsageError);
  EXPECT_THROW(scene.set_enabled(InstanceId{id.index + 1, id.scene}, false), UsageError);
  scene.commit();
  // The refused transform left the instance where it was.
  std::vector<RayD> rays = {{{0, 0, 5}, {0, 0, -1}, INFINITY}, {{NAN, 0, 5}, {0, 0, -1}, INFINITY},
                            {{0, 0, 1e31}, {0, 0, -1}, INFINITY}, {{0, 0, 5}, {0, 0, 0}, INFINITY},
                            {{0, 0, 5}, {0, 0, -1}, INFINITY, NAN}, {{0, 0, 5}, {0, 0, -1}, 4.0f, 4.5f}};
  std::vector<SceneHit> hits(rays.size());
  // The NaN origin, the far origin, the zero direction, the NaN t_min and
  // t_min past t_max.
  EXPECT_EQ(scene.trace(rays, hits), 5u);
  EXPECT_EQ(hits[0].instance, id.index);
  EXPECT_FLOAT_EQ(hits[0].t, 4.0f);
  for (size_t i = 1; i < rays.size(); ++i) EXPECT_EQ(hits[i].instance, kNoHit);
  std::vector<SceneHit> short_hits(1);
  EXPECT_THROW(scene.trace(rays, short_hits), UsageError);
  EXPECT_THROW(scene.trace(rays, hits, HitOutputs::None, Query::All), UsageError);
  SceneHitLists lists;
  lists.max_hits = 0;
  EXPECT_THROW(scene.trace_all_hits(rays, lists), UsageError);
  lists.max_hits = 2;
  EXPECT_EQ(scene.trace_all_hits(rays, lists), 5u);
  EXPECT_GE(lists.found[0], 2u);  // through both poles: every triangle around each, once
  EXPECT_EQ(lists.row(0)[0].instance, id.index);
  EXPECT_FLOAT_EQ(lists.row(0)[0].t, 4.0f);
  // The rays not walked: empty rows, nothing held for them.
  for (size_t i = 1; i < rays.size(); ++i) EXPECT_EQ(lists.found[i], 0u) << "ray " << i;
  for (size_t i = 1; i < rays.size(); ++i) EXPECT_TRUE(lists.row(i).empty()) << "ray " << i;
  EXPECT_EQ(lists.hits.size(), 2u);
  // A query or culling outside its enum, a point asked of a scene hit:
  // refused before any ray is walked, on an empty scene too.
  Scene empty;
  empty.commit();
  for (const Scene* s : {&scene, &empty}) {
    EXPECT_THROW(s->trace(rays, hits, HitOutputs::None, Query(7)), UsageError);
    EXPECT_THROW(s->trace(rays, hits, HitOutputs::None, Query::Closest, Cull(9)), UsageError);
    EXPECT_THROW(s->trace(rays, hits, HitOutputs::Point), UsageError);
    EXPECT_THROW(s->trace_all_hits(rays, lists, HitOutputs::None, Cull(9)), UsageError);
  }
  // The rays no scene walks are counted whatever the scene holds.
  EXPECT_EQ(empty.trace(rays, hits), 5u);
  // A 3x3 entry beyond 2^40; a world box beyond 2^100 (a sphere 10^18
  // across scaled by 2^40, 2^99 from the origin).
  Transform huge;
  huge.rotation_scale[0] = 0x1p41f;
  EXPECT_THROW(scene.add_instance(m, huge), UsageError);
  const MeshId big = scene.add_mesh(build_blob(make_sphere(4, 6, 1e18f, {0, 0, 0}), parse_layout("AABBTree/Float3"), "big"), "big");
  Transform wide;
  wide.rotation_scale[0] = wide.rotation_scale[4] = wide.rotation_scale[8] = 0x1p40f;
  EXPECT_NO_THROW(scene.add_instance(big, wide));
  wide.translation[0] = 0x1p99;
  EXPECT_THROW(scene.add_instance(big, wide), UsageError);
  // A moved-from scene refuses every call.
  Scene moved = std::move(empty);
  EXPECT_THROW(empty.commit(), UsageError);
  EXPECT_THROW(empty.add_instance(m, Transform{}), UsageError);
  EXPECT_THROW(empty.instance_count(), UsageError);
  EXPECT_THROW(empty.trace(rays, hits), UsageError);
}

#endif  // MESHCAST_TEST_GPU

}  // namespace
}  // namespace meshcast::testing
