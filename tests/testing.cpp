#include "tests/testing.h"

#include <bit>
#include <cmath>
#include <random>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <set>
#include <stdexcept>

#include <gtest/gtest.h>
#include <filesystem>

#include "check/generate.h"
#include "meshcast/read.h"
#include "layout/blob_format.h"

namespace meshcast::testing {

std::optional<Mesh> data_mesh(const std::string& name) {
  const char* dir = std::getenv("MESHCAST_DATA");
  std::string path = std::string(dir ? dir : "data") + "/" + name + ".off";
  if (!std::filesystem::exists(path)) return std::nullopt;
  return read_mesh(path);
}

bool quick() { return std::getenv("MESHCAST_TEST_QUICK") != nullptr; }

std::vector<std::string> covering_layouts(const std::vector<std::string>& names) {
  return quick() ? covering_subset(names) : names;
}

std::vector<std::string> covering_subset(const std::vector<std::string>& names) {
  // Three passes: layouts whose tree and triangle format are both new first
  // (so the trees take different formats, not all the first one), then
  // those with a new triangle format, then those with a new tree.
  std::vector<std::string> chosen;
  std::set<uint32_t> trees, triangles;
  for (int pass = 0; pass < 3; ++pass)
    for (const std::string& n : names) {
      const BuildOptions o = parse_layout(n.substr(0, n.find_first_of("+@")));
      const uint32_t tree = uint32_t(o.layout.tree), tri = uint32_t(o.layout.triangles);
      const bool new_tree = !trees.count(tree), new_triangles = !triangles.count(tri);
      if (pass == 0 ? new_tree && new_triangles : pass == 1 ? new_triangles : new_tree) {
        trees.insert(tree), triangles.insert(tri);
        chosen.push_back(n);
      }
    }
  return chosen;
}

namespace {

// Made on first use, removed with everything in it when the process exits.
struct Scratch {
  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("meshcast_test_" + std::to_string(::getpid()));
  Scratch() { std::filesystem::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

}  // namespace

std::filesystem::path scratch_dir() {
  static Scratch scratch;
  return scratch.dir;
}

std::string make_file(const std::string& name, const std::string& bytes) {
  const std::string path = (scratch_dir() / name).string();
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

namespace {
constexpr const char* kQuickPublicMesh = "ChineseDragon-10kv";
}  // namespace

bool is_chosen_public_mesh(const std::string& name) { return name == (quick() ? kQuickPublicMesh : "bunny00"); }
bool is_smallest_public_mesh(const std::string& name) { return name == kQuickPublicMesh; }

std::vector<NamedMesh> test_meshes(bool large) {
  static std::map<std::string, std::shared_ptr<const Mesh>> cache;
  auto get = [&](const std::string& name, auto make) {
    if (!cache.count(name)) cache[name] = std::make_shared<const Mesh>(make());
    return NamedMesh{name, cache[name]};
  };
  std::vector<NamedMesh> out;
  out.push_back(get("sphere", [] { return make_sphere(48, 96, 2.0f, {0.5f, -0.25f, 1.0f}); }));
  out.push_back(get("grid_plane", [] { return make_grid_plane(40, 30); }));
  // Quick: the sphere, the grid and the smallest public mesh (a quarter of
  // bunny00's triangles, the same code paths; under ASan the builds of
  // bunny00 for every layout were most of the stage).
  if (!quick()) out.push_back(get("terrain_64k", [] { return make_terrain(256, 128, 7); }));
  for (const char* name : {"bunny00", "armadillo", "refined_elephant", "ChineseDragon-10kv"}) {
    if (quick() && std::string(name) != kQuickPublicMesh) continue;
    if (!cache.count(name)) {
      std::optional<Mesh> m = data_mesh(name);
      if (!m) continue;
      cache[name] = std::make_shared<const Mesh>(std::move(*m));
    }
    out.push_back({name, cache[name]});
  }
  if (large) out.push_back(get("terrain_1M", [] { return make_terrain(1024, 512, 11); }));
  return out;
}

const std::vector<Ray>& test_rays(const NamedMesh& m, RayKind kind, size_t count) {
  static std::map<std::tuple<std::string, int, size_t>, std::vector<Ray>> cache;
  auto key = std::make_tuple(m.name, int(kind), count);
  if (!cache.count(key)) cache[key] = make_rays(*m.mesh, kind, count, 1234);
  return cache[key];
}

namespace {
// The tree reads the mesh it was built over: the cache holds that mesh too
// (a stored mesh made for one test may be gone by the next that names it).
const OracleTree& oracle_tree(const NamedMesh& m) {
  struct Built {
    std::shared_ptr<const Mesh> mesh;
    std::unique_ptr<OracleTree> tree;
  };
  static std::map<std::string, Built> trees;
  Built& b = trees[m.name];
  if (!b.tree) b.mesh = m.mesh, b.tree = std::make_unique<OracleTree>(*b.mesh);
  return *b.tree;
}
}  // namespace

namespace {
// What tells a ray set from the same set with t_min (with_t_min) in the
// caches below: a hash of its t_min values, 0 when all are 0.
uint64_t t_min_print(const std::vector<Ray>& rays) {
  uint64_t h = 0;
  for (const Ray& r : rays) h = (h ^ std::bit_cast<uint32_t>(r.tmin)) * 0x100000001b3ull;
  return h;
}
}  // namespace

std::vector<Ray> with_t_min(const std::vector<Ray>& rays, const std::vector<OracleHit>& closest) {
  std::vector<Ray> out(rays);
  for (size_t i = 0; i < out.size(); ++i) {
    Ray& r = out[i];
    if (closest[i].triangle == MC_NO_HIT) r.tmin = std::isfinite(r.tmax) ? r.tmax * 0.5f : 1.0f;
    else r.tmin = std::min(r.tmax, float(closest[i].t * (i % 3 == 0 ? 0.5 : i % 3 == 1 ? 1.25 : 2.0)));
  }
  return out;
}

const std::vector<OracleHit>& oracle_answers(const NamedMesh& m, RayKind kind, const std::vector<Ray>& rays,
                                             Cull cull) {
  static std::map<std::tuple<std::string, int, size_t, int, uint64_t>, std::vector<OracleHit>> cache;
  auto key = std::make_tuple(m.name, int(kind), rays.size(), int(cull), t_min_print(rays));
  if (!cache.count(key)) {
    std::vector<OracleHit> answers(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) answers[i] = oracle_tree(m).closest(rays[i], cull);
    cache[key] = std::move(answers);
  }
  return cache[key];
}

const std::vector<std::vector<OracleHit>>& oracle_all_answers(const NamedMesh& m, RayKind kind,
                                                              const std::vector<Ray>& rays, Cull cull) {
  static std::map<std::tuple<std::string, int, size_t, int, uint64_t>, std::vector<std::vector<OracleHit>>> cache;
  auto key = std::make_tuple(m.name, int(kind), rays.size(), int(cull), t_min_print(rays));
  if (!cache.count(key)) {
    std::vector<std::vector<OracleHit>> answers(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) answers[i] = oracle_tree(m).all(rays[i], cull);
    cache[key] = std::move(answers);
  }
  return cache[key];
}

Mesh stacked_planes(int planes) {
  Mesh m;
  for (int k = 0; k < planes; ++k) {
    const uint32_t base = uint32_t(m.vertices.size());
    const float z = float(k);
    for (Vec3 p : {Vec3{0, 0, z}, Vec3{1, 0, z}, Vec3{1, 1, z}, Vec3{0, 1, z}}) m.vertices.push_back(p);
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
  }
  return m;
}

std::vector<Ray> rays_down_through(int planes, size_t count) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  std::vector<Ray> rays;
  while (rays.size() < count) {
    const float x = u(rng), y = u(rng);
    if (std::fabs(x - y) < 0.05f) continue;  // clear of the diagonal: one triangle a plane
    rays.push_back({{x, y, float(planes) + 1}, {0, 0, -1}, INFINITY});
  }
  return rays;
}

void expect_nearest_rows(const Mesh& mesh, const std::vector<Ray>& rays, const HitLists& lists, const std::string& what) {
  const OracleTree tree(mesh);
  ASSERT_EQ(lists.found.size(), rays.size()) << what;
  for (size_t i = 0; i < rays.size(); ++i) {
    const std::vector<OracleHit> all = tree.all(rays[i]);
    ASSERT_EQ(lists.found[i], all.size()) << what << ", ray " << i;
    const std::span<const Hit> row = lists.row(i);
    ASSERT_EQ(row.size(), std::min<size_t>(all.size(), lists.max_hits)) << what << ", ray " << i;
    for (size_t k = 0; k < row.size(); ++k) {
      EXPECT_EQ(row[k].triangle, all[k].triangle) << what << ", ray " << i << ", record " << k;
      EXPECT_NEAR(row[k].t, all[k].t, 1e-5 * (1 + all[k].t)) << what << ", ray " << i << ", record " << k;
    }
  }
}

QueryAnswers check_queries(const QueryTracer& trace, const NamedMesh& reference, RayKind kind,
                           const std::vector<Ray>& rays, double tolerance, uint32_t max_hits, const std::string& what) {
  QueryAnswers out;
  const Cull cull = out.cull = kind == RayKind::Long ? Cull::Back : Cull::Front;
  const std::vector<OracleHit>& culled_oracle = oracle_answers(reference, kind, rays, cull);
  out.culled = trace.hits(rays, Query::Closest, cull);
  const Agreement a = compare(*reference.mesh, rays, out.culled, culled_oracle, tolerance);
  EXPECT_EQ(a.wrong + a.t_errors + a.t_rounding, 0u) << what << ", culled: " << a.first_problem;
  size_t culled_hits = 0;
  for (const Hit& h : out.culled) culled_hits += h.triangle != MC_NO_HIT;
  EXPECT_GT(culled_hits, rays.size() / 50) << what << ", culled: too few hits to show anything";
  out.any = trace.hits(rays, Query::Any, cull);
  const Agreement b = compare_any(*reference.mesh, rays, out.any, culled_oracle, tolerance, cull);
  EXPECT_EQ(b.wrong + b.t_errors + b.t_rounding, 0u) << what << ", Query::Any culled: " << b.first_problem;

  const Cull all_cull = out.all_cull = kind == RayKind::Long ? Cull::Front : Cull::None;
  out.all = trace.rows(rays, max_hits, all_cull);
  const Agreement c = compare_all(*reference.mesh, rays, out.all, oracle_all_answers(reference, kind, rays, all_cull),
                                  tolerance);
  EXPECT_EQ(c.wrong + c.t_errors + c.t_rounding, 0u) << what << ", Query::All: " << c.first_problem;
  EXPECT_GT(c.rays, rays.size() / 20) << what << ", Query::All: too few hits to show anything";
  return out;
}

TMinAnswers check_t_min_queries(const QueryTracer& trace, const NamedMesh& reference, RayKind kind,
                                const std::vector<Ray>& rays, double tolerance, uint32_t max_hits,
                                const std::string& what) {
  TMinAnswers out;
  const std::vector<OracleHit>& plain_oracle = oracle_answers(reference, kind, rays);
  out.rays = with_t_min(rays, plain_oracle);
  const std::vector<Ray>& offset_rays = out.rays;
  const std::vector<OracleHit>& offset_oracle = oracle_answers(reference, kind, offset_rays);
  out.closest = trace.hits(offset_rays, Query::Closest, Cull::None);
  const Agreement d = compare(*reference.mesh, offset_rays, out.closest, offset_oracle, tolerance);
  EXPECT_EQ(d.wrong + d.t_errors + d.t_rounding, 0u) << what << ", t_min: " << d.first_problem;
  // Where the first hits lie past the origin (not so for rays cast from a
  // plane they lie on), some must keep them and some skip them. Past it by
  // more than the tolerance: the oracle's t for a hit within rounding of
  // the origin carries little of its own value (its cancellations), and
  // half of it may lie past the exact t the walkers report.
  size_t kept_first = 0, skipped_first = 0, past_origin = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    const double len = std::sqrt(double(r.dir[0]) * r.dir[0] + double(r.dir[1]) * r.dir[1] + double(r.dir[2]) * r.dir[2]);
    if (plain_oracle[i].triangle == MC_NO_HIT || !(plain_oracle[i].t * len > tolerance)) continue;
    ++past_origin;
    if (offset_rays[i].tmin < plain_oracle[i].t) kept_first += out.closest[i].triangle == plain_oracle[i].triangle;
    else skipped_first += out.closest[i].triangle != plain_oracle[i].triangle;
  }
  // Judged on 20 such rays at least (a brute-force layout's tenth of its
  // rays may hold fewer: a handful can all fall one way).
  if (past_origin >= 20 && past_origin > rays.size() / 10) {
    EXPECT_GT(kept_first, past_origin / 10) << what << ", t_min: too few rays keep their first hit";
    EXPECT_GT(skipped_first, past_origin / 10) << what << ", t_min: too few rays skip their first hit";
  }
  const Agreement e = compare_any(*reference.mesh, offset_rays, trace.hits(offset_rays, Query::Any, Cull::None),
                                  offset_oracle, tolerance);
  EXPECT_EQ(e.wrong + e.t_errors + e.t_rounding, 0u) << what << ", Query::Any, t_min: " << e.first_problem;
  const Cull all_cull = kind == RayKind::Long ? Cull::Front : Cull::None;
  const Agreement f = compare_all(*reference.mesh, offset_rays, trace.rows(offset_rays, max_hits, all_cull),
                                  oracle_all_answers(reference, kind, offset_rays, all_cull), tolerance);
  EXPECT_EQ(f.wrong + f.t_errors + f.t_rounding, 0u) << what << ", Query::All, t_min: " << f.first_problem;
  return out;
}

Mesh unwelded(const Mesh& m) {
  Mesh soup;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const uint32_t base = uint32_t(soup.vertices.size());
    for (int c = 0; c < 3; ++c) soup.vertices.push_back(m.corner(t, c));
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  return soup;
}

std::vector<Hit> trace_all(const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, uint64_t* skipped,
                           uint32_t outputs, Query query, Cull cull) {
  BlobView view(blob, "test blob");
  std::vector<Hit> hits(rays.size());
  uint64_t s = view.trace(rays, hits, HitOutputs(outputs), query, cull);
  if (skipped) *skipped = s;
  return hits;
}

std::vector<Hit> trace_all(const BlobView& view, const std::vector<Ray>& rays, Query query, Cull cull) {
  std::vector<Hit> hits(rays.size());
  view.trace(rays, hits, HitOutputs::None, query, cull);
  return hits;
}

HitLists trace_lists(const BlobView& view, const std::vector<Ray>& rays, uint32_t max_hits, Cull cull) {
  HitLists lists;
  lists.max_hits = max_hits;
  view.trace_all_hits(rays, lists, HitOutputs::None, cull);
  return lists;
}

size_t expect_oracle(const Mesh& mesh, const std::vector<uint8_t>& blob, const std::vector<Ray>& rays,
                     const std::vector<Hit>& hits, const std::string& what) {
  // Slot-numbered hits (no remap) are judged on stored_mesh, numbered alike.
  const layout::BlobHeader& h = layout::header_of(blob.data());
  const Mesh stored = moves_vertices(h.triangle_format) || !layout::has_remap(h) ? stored_mesh(blob) : mesh;
  OracleTree tree(stored);
  std::vector<OracleHit> oracle(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) oracle[i] = tree.closest(rays[i]);
  Agreement a = compare(stored, rays, hits, oracle, 1e-5 * std::max(1e-30, mesh.bounds().diagonal()));
  EXPECT_EQ(a.wrong + a.t_errors + a.t_rounding, 0u) << what << ": " << a.first_problem;
  return size_t(std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.triangle != MC_NO_HIT; }));
}

std::vector<std::string> auto_settings() {
  return {"speed", "speed,trial=256", "memory", "memory,error=2e-6", "speed,bytes=20"};
}

}  // namespace meshcast::testing
