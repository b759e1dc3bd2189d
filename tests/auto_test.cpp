// The automatic layout: what it measures of a mesh, the rules it
// shortlists by, that its choice meets the caller's limits, and that every
// blob it chooses returns the double-precision oracle's answers on a
// surface within the error it states. (The stiff suite runs its choices
// too: robustness_test's Auto cases.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>

#include "check/generate.h"
#include "layout/blob_format.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

// Expected figures from the generators' own geometry (check/generate.h).
TEST(MeshStats, SphereGridAndSoup) {
  const int rings = 16, segments = 32;  // segments a multiple of 4: the box touches the sphere on every axis
  const Mesh sphere = make_sphere(rings, segments, 2.0f, {3.0f, 4.0f, 0.0f});
  const MeshStats s = measure_mesh(sphere);
  const double v = 2 + (rings - 1) * segments, t = 2 * (rings - 1) * segments;
  EXPECT_EQ(s.triangles, size_t(t));
  EXPECT_EQ(s.used_vertices, size_t(v));
  EXPECT_NEAR(s.corners_per_vertex, 3 * t / v, 1e-9);
  EXPECT_NEAR(s.diagonal, 4 * std::sqrt(3.0), 1e-5);
  EXPECT_NEAR(s.origin_distance, 5 / (4 * std::sqrt(3.0)), 1e-5);  // centre (3, 4, 0)
  EXPECT_NEAR(s.flatness, 1.0, 1e-6);
  EXPECT_GT(s.paired_ratio, 0.9) << "a closed welded mesh pairs almost whole";
  EXPECT_EQ(s.degenerate, 0u);

  const MeshStats soup = measure_mesh(unwelded(sphere));
  EXPECT_NEAR(soup.corners_per_vertex, 1.0, 1e-12);
  EXPECT_EQ(soup.paired_ratio, 0.0) << "pairing goes by shared vertex indices; a soup shares none";

  Mesh grid = make_grid_plane(8, 4);
  grid.triangles.push_back({0, 0, 1});  // one degenerate triangle
  const MeshStats g = measure_mesh(grid);
  EXPECT_EQ(g.flatness, 0.0);
  EXPECT_NEAR(g.size_spread, 1.0, 1e-6) << "every cell's two triangles have the same box";
  EXPECT_EQ(g.degenerate, 1u);
}

// Index width: past 65,536 vertices no 16-bit format is shortlisted; at or
// under it the indexed candidates are the 16-bit ones.
TEST(AutoLayout, IndexWidthFollowsTheVertexCount) {
  const Mesh wide = make_terrain(256, 256, 3);  // 257 x 257 = 66,049 vertices
  ASSERT_GT(wide.vertices.size(), 65536u);
  for (AutoGoal goal : {AutoGoal::Speed, AutoGoal::Memory}) {
    AutoLimits l;
    l.goal = goal;
    const AutoChoice c = choose_layout(wide, l, "terrain_66k");
    for (const AutoCandidate& k : c.candidates) EXPECT_EQ(k.label.find("Indexed16"), std::string::npos) << k.label;
    EXPECT_TRUE(c.choice().refused.empty());
  }
  AutoLimits memory;
  memory.goal = AutoGoal::Memory;
  const AutoChoice narrow = choose_layout(make_terrain(64, 64, 3), memory, "terrain_4k");
  bool any16 = false;
  for (const AutoCandidate& k : narrow.candidates) {
    EXPECT_EQ(k.label.find("Indexed32"), std::string::npos) << k.label;
    any16 = any16 || k.label.find("Indexed16") != std::string::npos;
  }
  EXPECT_TRUE(any16);
}

// A triangle soup: no indexed or pair encodings are shortlisted.
TEST(AutoLayout, SoupGetsNoIndexedOrPairCandidates) {
  const Mesh soup = unwelded(make_sphere(12, 24, 1.0f, {}));
  for (AutoGoal goal : {AutoGoal::Speed, AutoGoal::Memory}) {
    AutoLimits l;
    l.goal = goal;
    for (const AutoCandidate& k : choose_layout(soup, l, "soup").candidates) {
      if (k.why.find("small") != std::string::npos) continue;  // the speed list's fallbacks under a byte limit
      EXPECT_EQ(k.label.find("Indexed"), std::string::npos) << k.label;
      EXPECT_EQ(k.label.find("Pair"), std::string::npos) << k.label;
    }
  }
}

// Limits nothing meets are refused naming the mesh; a GPU reader list
// keeps the choice to those layouts.
TEST(AutoLayout, ImpossibleLimitsAndReaders) {
  const Mesh sphere = make_sphere(12, 24, 1.0f, {});
  AutoLimits l;
  l.max_bytes_per_triangle = 1;
  try {
    choose_layout(sphere, l, "tiny-budget");
    ADD_FAILURE() << "one byte a triangle cannot be met";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tiny-budget"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no layout meets"), std::string::npos) << e.what();
  }
  // Readers that read no 128-lane layout: under a byte limit only
  // AABBTree/Float3 fits nothing, so no layout meets the limits, rather
  // than one no reader reads.
  AutoLimits narrow;
  narrow.readers = {parse_layout_name("AABBTree/Float3")};
  narrow.max_bytes_per_triangle = 30;
  EXPECT_THROW(choose_layout(sphere, narrow, "sphere"), InputError);
  AutoLimits gpu;
  gpu.readers = {parse_layout_name("AABBTree/Float3"), parse_layout_name("SKDTree/Float3")};
  for (AutoGoal goal : {AutoGoal::Speed, AutoGoal::Memory}) {
    gpu.goal = goal;
    const AutoChoice c = choose_layout(sphere, gpu, "sphere");
    const layout::BlobHeader& h = layout::header_of(c.blob.data());
    const std::string chosen = layout_name(h.tree_format, h.triangle_format);
    EXPECT_TRUE(chosen == "AABBTree/Float3" || chosen == "SKDTree/Float3") << chosen;
  }
}

// The refusal names each limit as it was given (0.001, not "0.00"; 1.25e-30,
// not "1.2e-30"), ends in whole words on what the nearest
// came to (the smallest's bytes, the most exact's error), and never shows a
// figure at or under the limit it is over.
TEST(AutoLayout, RefusalNamesTheLimitsAsGiven) {
  const Mesh sphere = make_sphere(12, 24, 1.0f, {});
  auto refusal = [&](const AutoLimits& l) -> std::string {
    try {
      choose_layout(sphere, l, "sphere");
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "the limits were met";
    return "";
  };
  AutoLimits bytes;
  bytes.max_bytes_per_triangle = 0.001;
  const std::string b = refusal(bytes);
  EXPECT_NE(b.find("(at most 0.001 bytes a triangle)"), std::string::npos) << b;
  // The exact layouts (Float3) are among those built: the most exact is exact.
  EXPECT_TRUE(b.ends_with(" bytes a triangle and the most exact is exact (an error of 0)")) << b;

  // Only a quantized layout: the most exact states an error above 0.
  AutoLimits error;
  error.readers = {parse_layout_name("QuadTreeHalfFloat/Indexed8BitPackSOA4")};
  error.max_error = 1.25e-30;
  const std::string e = refusal(error);
  EXPECT_NE(e.find("(error at most 1.25e-30 of the diagonal, read by the GPU too)"), std::string::npos) << e;
  const size_t states = e.find("the most exact states an error of ");
  ASSERT_NE(states, std::string::npos) << e;
  EXPECT_TRUE(e.ends_with(" of the diagonal")) << e;
  // Its grid's half step alone is over the limit: not built, the floor named.
  const char* least = "the most exact states an error of at least ";
  ASSERT_TRUE(e.compare(states, std::strlen(least), least) == 0) << e;
  EXPECT_GT(std::strtod(e.c_str() + states + std::strlen(least), nullptr), 1.25e-30) << e;

  // A limit a hair under the smallest blob: the figure shown is over it.
  AutoLimits memory;
  memory.goal = AutoGoal::Memory;
  const double smallest = choose_layout(sphere, memory, "sphere").choice().bytes_per_triangle;
  AutoLimits hair;
  hair.max_bytes_per_triangle = smallest * (1 - 1e-6);
  const std::string h = refusal(hair);
  const size_t takes = h.find("the smallest built takes ");
  ASSERT_NE(takes, std::string::npos) << h;
  EXPECT_GT(std::strtod(h.c_str() + takes + std::strlen("the smallest built takes "), nullptr), hair.max_bytes_per_triangle) << h;
}

// Without the remap (BuildOptions::triangle_ids false) every layout walks
// the same hits, naming triangles by slot: the same t, the same stored
// corners, the oracle's answers over stored_mesh (numbered by slot too), and
// the blob is smaller by the remap section. When the build kept the input
// order the remap keeps only its bitmap and ranks.
TEST(NoRemap, EveryLayoutAnswersBySlot) {
  const Mesh mesh = make_sphere(24, 48, 1.0f, {0.1f, 0.2f, -0.3f});
  const std::vector<Ray> rays = make_rays(mesh, RayKind::Long, 1500, 11);
  for (const std::string& layout : covering_layouts(layout_names())) {
    BuildOptions with = parse_layout(layout), without = with;
    without.triangle_ids = false;
    const std::vector<uint8_t> a = build_blob(mesh, with, "sphere"), b = build_blob(mesh, without, "sphere");
    const layout::BlobHeader &ha = layout::header_of(a.data()), &hb = layout::header_of(b.data());
    ASSERT_EQ(layout::validate(b), "") << layout;
    EXPECT_FALSE(layout::has_remap(hb)) << layout;
    EXPECT_EQ(b.size() + ha.remap_size + (ha.remap_offset - hb.remap_offset), a.size()) << layout;
    const std::vector<Hit> ha_hits = trace_all(a, rays), hb_hits = trace_all(b, rays);
    const Mesh sa = stored_mesh(a), sb = stored_mesh(b);
    std::vector<OracleHit> oracle(rays.size());
    OracleTree tree(sb);
    for (size_t i = 0; i < rays.size(); ++i) oracle[i] = tree.closest(rays[i]);
    Agreement agree = compare(sb, rays, hb_hits, oracle, 1e-5 * mesh.bounds().diagonal());
    EXPECT_EQ(agree.wrong + agree.t_errors + agree.t_rounding, 0u) << layout << ": " << agree.first_problem;
    for (size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(ha_hits[i].t, hb_hits[i].t) << layout << " ray " << i;
      if (ha_hits[i].triangle == MC_NO_HIT) continue;
      ASSERT_LT(hb_hits[i].triangle, hb.remap_slots) << layout;
      for (int k = 0; k < 3; ++k)
        for (int x = 0; x < 3; ++x)
          ASSERT_EQ(sa.corner(ha_hits[i].triangle, k)[x], sb.corner(hb_hits[i].triangle, k)[x]) << layout << " ray " << i;
    }
    // Kept input order (brute force, but for the pair encoding, which puts
    // each pair side by side): the remap is the used-slot bitmap and ranks
    // alone, and the hits still name the input's triangles.
    if (uint32_t(with.layout.tree) == MC_TREE_BRUTEFORCE && uint32_t(with.layout.triangles) != MC_TRI_FLOAT3PAIRSOA4) {
      EXPECT_EQ(ha.remap_bits, 0u) << layout;
      // 12 bytes a 64 slot numbers (a word of bits, a rank), however many
      // slot numbers the codec's blocks spread its triangles over.
      EXPECT_LE(ha.remap_size, 12 * ((uint64_t(ha.remap_slots) + 63) / 64) + 8) << layout << ": 12 bytes a 64 slots";
      expect_oracle(mesh, a, rays, ha_hits, layout + " (input order kept)");
    }
  }
}

class AutoChoices : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

// The choice meets its limits and is what its goal says among the
// candidates built; the blob validates, returns the oracle's answers over
// the mesh it stores, and that mesh lies within the stated bound of the
// input: each stored corner within displacement_bound of an input corner of
// the same triangle.
TEST_P(AutoChoices, MeetLimitsAndAnswerWithinTheirBound) {
  const auto& [mesh_name, setting] = GetParam();
  NamedMesh m;
  for (const NamedMesh& t : test_meshes(false))
    if (t.name == mesh_name) m = t;
  if (!m.mesh) GTEST_SKIP() << mesh_name << " not here (quick run, or no data/)";
  const AutoLimits limits = parse_auto_setting(setting);
  const AutoChoice c = choose_layout(*m.mesh, limits, mesh_name);
  const AutoCandidate& chosen = c.choice();
  ASSERT_TRUE(chosen.refused.empty()) << chosen.refused;
  ASSERT_EQ(layout::validate(c.blob), "");
  const double n = double(m.mesh->triangles.size());
  if (limits.max_bytes_per_triangle > 0) { EXPECT_LE(double(c.blob.size()) / n, limits.max_bytes_per_triangle); }
  const double diagonal = m.mesh->bounds().diagonal();
  if (limits.max_error > 0) { EXPECT_LE(relative_error_bound(c.blob, diagonal), limits.max_error); }
  for (size_t i = 0; i < c.candidates.size(); ++i) {
    const AutoCandidate& k = c.candidates[i];
    if (!k.built || !k.refused.empty() || i == c.chosen) continue;
    if (limits.goal == AutoGoal::Memory) { EXPECT_GE(k.bytes_per_triangle, chosen.bytes_per_triangle) << k.label; }
    if (limits.trial_rays > 0) { EXPECT_GE(k.trial_ns, chosen.trial_ns) << k.label; }
    if (limits.goal == AutoGoal::Speed && limits.trial_rays == 0) { EXPECT_GT(i, c.chosen) << "rule order: " << k.label; }
  }

  const size_t count = quick() ? 500 : 4000;
  const std::vector<Ray>& rays = test_rays(m, RayKind::Long, count);
  expect_oracle(*m.mesh, c.blob, rays, trace_all(c.blob, rays), mesh_name + " auto " + setting + ": " + chosen.label);

  float bound[3];
  displacement_bound(c.blob, bound);
  const Mesh stored = stored_mesh(c.blob);
  size_t beyond = 0;
  for (size_t t = 0; t < m.mesh->triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3 s = stored.corner(t, k);
      bool near = false;  // strips store a rotation of the corners
      for (int j = 0; j < 3 && !near; ++j) {
        const Vec3 in = m.mesh->corner(t, j);
        near = std::fabs(s.x - in.x) <= bound[0] && std::fabs(s.y - in.y) <= bound[1] && std::fabs(s.z - in.z) <= bound[2];
      }
      beyond += !near;
    }
  EXPECT_EQ(beyond, 0u) << "stored corners beyond the stated bound (" << bound[0] << ", " << bound[1] << ", "
                        << bound[2] << ") in " << chosen.label;
}

std::vector<std::string> mesh_names() {
  return {"sphere", "grid_plane", "terrain_64k", "bunny00", "armadillo", "refined_elephant", "ChineseDragon-10kv"};
}

INSTANTIATE_TEST_SUITE_P(Meshes, AutoChoices,
                         ::testing::Combine(::testing::ValuesIn(mesh_names()), ::testing::ValuesIn(auto_settings())),
                         [](const ::testing::TestParamInfo<AutoChoices::ParamType>& info) {
                           std::string n = std::get<0>(info.param) + "_" + std::get<1>(info.param);
                           for (char& ch : n)
                             if (ch == ',' || ch == '-' || ch == '=' || ch == '.') ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace meshcast::testing
