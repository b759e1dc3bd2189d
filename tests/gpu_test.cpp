// The Vulkan backend against the CPU walker on the same blob and against the
// double-precision oracle, on the device the machine has (lavapipe in CI),
// with the validation layers on.
#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string_view>

#include "gpu/method.h"
#include "layout/formats.h"
#include "layout/queries.h"
#include "gpu/vulkan.h"
#include "check/generate.h"
#include "tests/testing.h"

namespace meshcast::gpu {
// What a test's parameter prints as: "aabbtree reading AABBTree/Float3".
void PrintTo(const MethodLayout& m, std::ostream* os) { *os << m.method << " reading " << layout_name(m.layout); }
}  // namespace meshcast::gpu

namespace meshcast::testing {
namespace {

gpu::Context& context() {
  static gpu::Context ctx(gpu::DeviceChoice{"", true});
  return ctx;
}

// Same triangle as the CPU walker for every ray, t within 1e-6 relative; a
// different triangle only at exactly the same t (a tie the two may break
// apart, both right).
void expect_same_as_cpu(const std::vector<Hit>& gpu, const std::vector<Hit>& cpu, const std::string& what) {
  size_t differ = 0, hits = 0;
  std::string first;
  for (size_t i = 0; i < cpu.size(); ++i) {
    hits += cpu[i].triangle != MC_NO_HIT;
    bool same = gpu[i].triangle == cpu[i].triangle;
    bool t_ok = cpu[i].triangle == MC_NO_HIT ? gpu[i].triangle == MC_NO_HIT
                                             : std::fabs(gpu[i].t - cpu[i].t) <= 1e-6 * std::fabs(cpu[i].t);
    if (!same && gpu[i].t == cpu[i].t) continue;  // a tie
    if (!same || !t_ok) {
      if (differ++ == 0)
        first = "ray " + std::to_string(i) + ": gpu " + std::to_string(gpu[i].triangle) + " t " + std::to_string(gpu[i].t) +
                ", cpu " + std::to_string(cpu[i].triangle) + " t " + std::to_string(cpu[i].t);
    }
  }
  EXPECT_EQ(differ, 0u) << what << ": " << first;
  EXPECT_GT(hits, cpu.size() / 20) << what << ": a ray set that never hits proves nothing";
}

TEST(Gpu, DeviceIsNamedAndValidationIsOn) {
  EXPECT_FALSE(context().device_name().empty());
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

// The layers are really listening: an invalid call (a buffer of 0 bytes) is
// reported, so the zero counts of the other tests mean something.
TEST(Gpu, ValidationLayersReportAnInvalidCall) {
  gpu::Context ctx(gpu::DeviceChoice{"", true});
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = 0, info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  if (ctx.vk().CreateBuffer(ctx.device(), &info, nullptr, &buffer) == VK_SUCCESS && buffer) ctx.vk().DestroyBuffer(ctx.device(), buffer, nullptr);
  EXPECT_GT(ctx.validation_messages(), 0u);
}

TEST(Gpu, UnknownDeviceIsRefusedWithTheList) {
  try {
    gpu::Context ctx(gpu::DeviceChoice{"no such device", false});
    FAIL();
  } catch (const gpu::GpuError& e) {
    EXPECT_NE(std::string(e.what()).find("devices:"), std::string::npos) << e.what();
  }
}

// Contexts come and go beside one another: one without validation (so
// without the debug-utils extension) made and dropped, one refused, then
// the first context still traces and is destroyed cleanly at exit. On an
// H100 a shared function table (volk's) once held the dropped context's
// pointers and the process crashed at exit; now each context has its own.
TEST(Gpu, ContextsSideBySideKeepTheirOwnFunctions) {
  Mesh m = make_sphere(6, 12, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  std::unique_ptr<gpu::Method> first = gpu::make_method(context(), "aabbtree", blob, "sphere");
  {
    gpu::Context other(gpu::DeviceChoice{"", false});
    std::unique_ptr<gpu::Method> second = gpu::make_method(other, "aabbtree", blob, "sphere");
    EXPECT_THROW(gpu::Context(gpu::DeviceChoice{"no such device", false}), gpu::GpuError);
  }
  std::vector<Ray> rays = {Ray{{0.1f, 0.2f, -5}, {0, 0, 1}, 100}};
  std::vector<Hit> hits(1);
  first->trace(rays, hits);
  EXPECT_NE(hits[0].triangle, MC_NO_HIT);
  EXPECT_NEAR(hits[0].t, 4.0f, 0.2f);  // a faceted unit sphere
}

TEST(Gpu, MethodRefusesALayoutItDoesNotRead) {
  Mesh m = make_sphere(6, 12, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  EXPECT_THROW(gpu::make_method(context(), "bruteforce", blob, "sphere"), InputError);
  EXPECT_THROW(gpu::make_method(context(), "octree", blob, "sphere"), InputError);
}

// The methods that test every triangle (the brute force) or every batch of
// triangles (AABBList) for every ray: their time on lavapipe grows with rays
// times triangles, so they get fewer rays and smaller meshes below. Their
// shader code is the same for every ray and every triangle; the stiff suite
// probes their edges and vertices.
bool tests_every_triangle(const char* method) {
  return std::string_view(method) == "bruteforce" || std::string_view(method) == "aabblist";
}

// Every method on the layout it reads, every ray kind, against the CPU
// walker on the same blob and against the oracle, 10,000 rays of each kind
// on the sphere, bunny00 and the 64k terrain; the linear methods on the
// sphere and the smallest public mesh alone, the brute force on 300 rays
// (at 10,000 it took 4 minutes a codec on lavapipe, at 1,000 and with the
// terrain still 35-46 s, on bunny00 19-22 s, the longest tests in CI),
// AABBList on 3,000.
class GpuMethods : public ::testing::TestWithParam<gpu::MethodLayout> {};

TEST_P(GpuMethods, MatchTheCpuAndTheOracle) {
  const gpu::MethodLayout mc = GetParam();
  const bool linear = tests_every_triangle(mc.method);
  for (const NamedMesh& m : test_meshes(false)) {
    const bool public_mesh = linear ? is_smallest_public_mesh(m.name) : m.name == "bunny00";
    if (m.name != "sphere" && !public_mesh && (linear || m.name != "terrain_64k")) continue;
    std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(layout_name(mc.layout)), m.name);
    std::unique_ptr<gpu::Method> method = gpu::make_method(context(), mc.method, blob, m.name);
    // A quantized layout is judged on the mesh it stores, as on the CPU (kept
    // alive across the kinds: the oracle cache refers to it by name).
    NamedMesh reference = m;
    if (moves_vertices(uint32_t(parse_layout(layout_name(mc.layout)).layout.triangles)))
      reference = {m.name + "#" + layout_name(mc.layout), std::make_shared<const Mesh>(stored_mesh(blob))};
    for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial}) {
      const size_t count = !linear ? 10000 : std::string_view(mc.method) == "bruteforce" ? 300 : 3000;
      const std::vector<Ray>& rays = test_rays(m, kind, count);
      std::vector<Hit> gpu(rays.size()), cpu = trace_all(blob, rays);
      method->trace(rays, gpu);
      std::string what = std::string(mc.method) + " on " + m.name + " kind " + std::to_string(int(kind));
      expect_same_as_cpu(gpu, cpu, what);
      Agreement a = compare(*reference.mesh, rays, gpu, oracle_answers(reference, kind, rays), 1e-5 * m.mesh->bounds().diagonal());
      EXPECT_EQ(a.wrong + a.t_errors + a.t_rounding, 0u) << what << ": " << a.first_problem;
    }
  }
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

// The queries besides the closest hit, each a method made for
// it (specialization constants): closest and any hit with a face culled,
// and every hit (culled on long rays), on every method against the oracle
// with the same culling, and every hit's rows equal to the CPU's; the
// three again with a t_min (check_t_min_queries), the closest hits the CPU's. 500
// rays of each kind on bunny00, the brute force and AABBList 100 on the
// smallest public mesh (on bunny00 they took 35-39 s a codec, the longest
// Vulkan tests in CI); the stiff suite probes the sphere and the grid.
TEST_P(GpuMethods, QueriesMatchTheOracle) {
  const gpu::MethodLayout mc = GetParam();
  for (const NamedMesh& m : test_meshes(false)) {
    if (!(tests_every_triangle(mc.method) ? is_smallest_public_mesh(m.name) : is_chosen_public_mesh(m.name))) continue;
    std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(layout_name(mc.layout)), m.name);
    const BlobView view(blob, m.name);
    NamedMesh reference = m;
    if (moves_vertices(uint32_t(parse_layout(layout_name(mc.layout)).layout.triangles)))
      reference = {m.name + "#" + layout_name(mc.layout), std::make_shared<const Mesh>(stored_mesh(blob))};
    const double tolerance = 1e-5 * m.mesh->bounds().diagonal();
    for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial}) {
      const size_t count = tests_every_triangle(mc.method) ? 100 : 500;
      const std::vector<Ray>& rays = test_rays(m, kind, count);
      const std::string what = std::string(mc.method) + " on " + m.name + " kind " + std::to_string(int(kind));
      // The query and culling are the method's specialization constants.
      const QueryTracer vulkan{
          [&](const std::vector<Ray>& r, Query q, Cull c) {
            std::vector<Hit> hits(r.size());
            gpu::make_method(context(), mc.method, blob, m.name, 1, layout::query_bits(q, c))->trace(r, hits);
            return hits;
          },
          [&](const std::vector<Ray>& r, uint32_t max_hits, Cull c) {
            HitLists rows;
            gpu::make_method(context(), mc.method, blob, m.name, 1, layout::query_bits(Query::All, c), max_hits)
                ->trace_all_hits(r, rows);
            return rows;
          }};
      const QueryAnswers answers = check_queries(vulkan, reference, kind, rays, tolerance, 64, what);
      expect_same_as_cpu(answers.culled, trace_all(view, rays, Query::Closest, answers.cull), what + ", culled");
      const TMinAnswers offset = check_t_min_queries(vulkan, reference, kind, rays, tolerance, 64, what);
      expect_same_as_cpu(offset.closest, trace_all(view, offset.rays), what + ", t_min");
      const HitLists& lists = answers.all;
      const HitLists cpu = trace_lists(view, rays, 64, answers.all_cull);
      for (size_t i = 0; i < rays.size(); ++i) {
        ASSERT_EQ(lists.found[i], cpu.found[i]) << what << ", Query::All, ray " << i;
        for (size_t k = 0; k < lists.row(i).size(); ++k)
          EXPECT_EQ(lists.row(i)[k].triangle, cpu.row(i)[k].triangle) << what << ", Query::All, ray " << i;
      }
    }
  }
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

// Rows shorter than the hits: 12 stacked planes, rows of 1, 3 and 12 on
// every method (the brute force and AABBList keep them by a chain of
// atomic minimums, shaders/keys.glsl): each row the nearest of the
// oracle's set, the count all of them; the points filled on the host.
TEST_P(GpuMethods, RowsKeepTheNearestAndCountAll) {
  const gpu::MethodLayout mc = GetParam();
  const Mesh planes = stacked_planes(12);
  const std::vector<Ray> rays = rays_down_through(12, 300);
  const std::vector<uint8_t> blob = build_blob(planes, parse_layout(layout_name(mc.layout)), "planes");
  const Mesh stored = moves_vertices(uint32_t(parse_layout(layout_name(mc.layout)).layout.triangles)) ? stored_mesh(blob) : planes;
  for (uint32_t max_hits : {1u, 3u, 12u, kMaxHitsLimit}) {
    HitLists lists;
    gpu::make_method(context(), mc.method, blob, "planes", 1, MC_QUERY_ALL | MC_HIT_POINT, max_hits)->trace_all_hits(rays, lists);
    const std::string what = std::string(mc.method) + ", rows of " + std::to_string(max_hits);
    expect_nearest_rows(stored, rays, lists, what);
    // Read back compact: the kept hits alone, whatever the device's rows.
    EXPECT_EQ(lists.hits.size(), rays.size() * std::min(12u, max_hits)) << what;
    for (size_t i = 0; i < rays.size(); ++i)
      for (const Hit& h : lists.row(i)) EXPECT_NEAR(h.point[2], rays[i].org[2] - h.t, 1e-4) << what << ", ray " << i;
  }
  EXPECT_THROW(gpu::make_method(context(), mc.method, blob, "planes", 1, MC_QUERY_ALL | MC_HIT_UV, 4), UsageError);
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

// Batches as a game runs them: three frames in flight on one method, each
// batch cut into pieces of 256 rays (limit_piece: more pieces than the
// device's limits would make on these few rays), the rays written straight
// into the slots' mapped buffers, collected out of order, then the ring
// run again with the sizes swapped round (a slot grows, the others keep
// their buffers); every query and culling. Unwalkable rays among them are
// misses and counted, as on the CPU. On the test meshes' sphere; for the
// linear methods a sphere of a sixteenth of its triangles (what is tested
// here is the ring of slots, not the triangle test).
TEST_P(GpuMethods, PiecesAndFramesInFlightMatchTheCpu) {
  const gpu::MethodLayout mc = GetParam();
  std::vector<NamedMesh> meshes;
  for (const NamedMesh& m : test_meshes(false))
    if (m.name == "sphere") meshes.push_back(m);
  if (tests_every_triangle(mc.method))
    meshes = {{"coarse_sphere", std::make_shared<const Mesh>(make_sphere(12, 24, 2.0f, {0.5f, -0.25f, 1.0f}))}};
  for (const NamedMesh& m : meshes) {
    std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(layout_name(mc.layout)), m.name);
    const BlobView view(blob, m.name);
    std::vector<Ray> rays = test_rays(m, RayKind::Long, 1800);
    rays[5].org[0] = NAN, rays[300].dir[0] = rays[300].dir[1] = rays[300].dir[2] = 0, rays[1001].tmin = 2 * rays[1001].tmax;
    const std::vector<uint32_t> sizes = {700, 333, 767};
    for (Query query : {Query::Closest, Query::Any, Query::All})
      for (Cull cull : {Cull::None, Cull::Back, Cull::Front}) {
        const std::string what = std::string(mc.method) + " query " + std::to_string(int(query)) + " cull " +
                                 std::to_string(int(cull));
        const std::unique_ptr<gpu::Method> method =
            gpu::make_method(context(), mc.method, blob, m.name, 3, layout::query_bits(query, cull), 8);
        method->limit_piece(256);
        for (int round = 0; round < 2; ++round) {
          std::vector<std::vector<Ray>> batches;
          for (uint32_t slot = 0, first = 0; slot < 3; ++slot) {
            const uint32_t n = sizes[(slot + round) % 3];
            batches.emplace_back(rays.begin() + first, rays.begin() + first + n);
            first += n;
            std::span<Ray> to = method->rays(slot, n);
            ASSERT_EQ(to.size(), n);
            std::copy(batches.back().begin(), batches.back().end(), to.begin());
            method->submit(slot);
          }
          for (uint32_t slot : {2u, 0u, 1u}) {
            const std::vector<Ray>& batch = batches[slot];
            uint64_t cpu_skipped = 0;
            for (const Ray& r : batch) cpu_skipped += !ray_is_walkable(r);
            const std::string at = what + ", round " + std::to_string(round) + ", slot " + std::to_string(slot);
            if (query == Query::All) {
              HitLists lists;
              EXPECT_EQ(method->finish_lists(slot, lists), cpu_skipped) << at;
              const HitLists cpu = trace_lists(view, batch, 8, cull);
              ASSERT_EQ(lists.rays(), batch.size()) << at;
              for (size_t i = 0; i < batch.size(); ++i) {
                ASSERT_EQ(lists.found[i], cpu.found[i]) << at << ", ray " << i;
                for (size_t k = 0; k < lists.row(i).size(); ++k)
                  EXPECT_EQ(lists.row(i)[k].triangle, cpu.row(i)[k].triangle) << at << ", ray " << i;
              }
              continue;
            }
            uint64_t skipped = 0;
            const std::span<const Hit> hits = method->hits(slot, nullptr, &skipped);
            EXPECT_EQ(skipped, cpu_skipped) << at;
            const std::vector<Hit> gpu(hits.begin(), hits.end()), cpu = trace_all(view, batch, query, cull);
            ASSERT_EQ(gpu.size(), batch.size()) << at;
            if (query == Query::Closest) {
              expect_same_as_cpu(gpu, cpu, at);
              continue;
            }
            for (size_t i = 0; i < batch.size(); ++i)  // any hit: hit or miss as the CPU, the triangle its own
              EXPECT_EQ(gpu[i].triangle == MC_NO_HIT, cpu[i].triangle == MC_NO_HIT) << at << ", ray " << i;
          }
        }
      }
  }
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

// A batch of 262,144 rays (a quarter of a million: past what the suites
// above run, where a fault that strikes one ray in a few thousand shows)
// answers ray for ray as the CPU walker, on every tree walker (the brute
// force and AABBList test every ray against every batch: too slow here).
TEST_P(GpuMethods, ALargeBatchMatchesTheCpuRayForRay) {
  const gpu::MethodLayout mc = GetParam();
  if (tests_every_triangle(mc.method)) GTEST_SKIP();
  for (const NamedMesh& m : test_meshes(false)) {
    if (m.name != "bunny00") continue;
    std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(layout_name(mc.layout)), m.name);
    const std::vector<Ray> rays = make_rays(*m.mesh, RayKind::Long, 262144, 11);
    std::vector<Hit> gpu(rays.size()), cpu = trace_all(blob, rays);
    EXPECT_EQ(gpu::make_method(context(), mc.method, blob, m.name)->trace(rays, gpu), 0u);
    expect_same_as_cpu(gpu, cpu, std::string(mc.method) + " on 262,144 rays of " + m.name);
  }
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

INSTANTIATE_TEST_SUITE_P(Methods, GpuMethods, ::testing::ValuesIn(gpu::method_layouts().begin(), gpu::method_layouts().end()),
                         [](const auto& info) {
                           std::string n = layout_name(info.param.layout);
                           for (char& ch : n)
                             if (ch == '/') ch = '_';
                           return std::string(info.param.method) + "_" + n;
                         });

// A batch whose buffers exceed the device's host-visible memory is refused
// before anything is allocated, the refusal naming the bytes and the
// limit: rows of 4096 hits take 32,832 bytes a ray (the 32-byte ray, the
// 28-byte hit, the row's count and 4096 (t, triangle) pairs), and a batch
// past 2^32 - 1 rays is refused as such. The method goes on with the
// batches that fit.
TEST(Gpu, ABatchBeyondTheDeviceMemoryIsRefusedUpFront) {
  const Mesh planes = stacked_planes(12);
  const std::vector<Ray> rays = rays_down_through(12, 300);
  const std::vector<uint8_t> blob = build_blob(planes, parse_layout("AABBTree/Float3"), "planes");
  const std::unique_ptr<gpu::Method> method =
      gpu::make_method(context(), "aabbtree", blob, "planes", 1, MC_QUERY_ALL, kMaxHitsLimit);
  EXPECT_EQ(method->refusal(uint32_t(rays.size())), "");
  const uint64_t too_many = context().mapped_heap_bytes() / (32 + 28 + 4 * (1 + 2 * 4096)) + 4096;
  const std::string why = method->refusal(too_many);
  for (const std::string& word : {std::string("aabbtree"), std::to_string(too_many) + " rays",
                                 std::string("rows of 4096 hits a ray")})
    EXPECT_NE(why.find(word), std::string::npos) << "'" << word << "' not in: " << why;
  // The heap where it is under 4 GiB (lavapipe's 2 GiB), else the 32-bit
  // offsets that reach 4 GiB of a buffer.
  const bool heap = why.find("bytes of host-visible memory") != std::string::npos &&
                    why.find(std::to_string(context().mapped_heap_bytes()) + " bytes") != std::string::npos;
  EXPECT_TRUE(heap || why.find("past the 4 GiB a buffer's 32-bit offsets reach") != std::string::npos) << why;
  EXPECT_NE(method->refusal(uint64_t(1) << 32).find("2^32 - 1 rays"), std::string::npos);
  try {
    method->rays(0, too_many);
    ADD_FAILURE() << "a batch of " << too_many << " rows of 4096 was given room";
  } catch (const GpuError& e) {
    EXPECT_EQ(std::string(e.what()), why);
    EXPECT_FALSE(e.lost);
  }
  HitLists lists;
  method->trace_all_hits(rays, lists);
  EXPECT_EQ(lists.hits.size(), rays.size() * 12);
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

// AABBList with a pair buffer of 50,000 pairs: 10,000 rays on the 64k
// terrain (256 batches) go in chunks of 195 rays, so the counter reset and the dispatch
// arguments between chunks are exercised, not just one chunk.
TEST(Gpu, AABBListInManyChunksMatchesTheCpu) {
  for (const NamedMesh& m : test_meshes(false)) {
    if (m.name != "terrain_64k") continue;
    std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout("AABBList/Float3SOA128"), m.name);
    ASSERT_GT(layout::header_of(blob.data()).node_count * 10000ull, 50000ull * 20);
    std::unique_ptr<gpu::Method> method = gpu::make_aabblist(context(), blob, m.name, 50000);
    const std::vector<Ray>& rays = test_rays(m, RayKind::Radial, 10000);
    std::vector<Hit> gpu(rays.size()), cpu = trace_all(blob, rays);
    method->trace(rays, gpu);
    expect_same_as_cpu(gpu, cpu, "aabblist in chunks on " + m.name);
  }
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

TEST(Gpu, UnwalkableRaysAreMissesAndCounted) {
  Mesh m = make_sphere(6, 12, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("BruteForce/Float3SOA128"), "sphere");
  std::unique_ptr<gpu::Method> method = gpu::make_method(context(), "bruteforce", blob, "sphere");
  std::vector<Ray> rays = {{{0, 0, -5}, {0, 0, 1}, INFINITY}, {{0, 0, -5}, {0, 0, 0}, INFINITY},
                           {{NAN, 0, -5}, {0, 0, 1}, INFINITY}, {{0, 0, -5}, {0, 0, 1}, NAN}};
  std::vector<Hit> hits(rays.size());
  EXPECT_EQ(method->trace(rays, hits), 3u);
  EXPECT_NE(hits[0].triangle, MC_NO_HIT);
  for (size_t i = 1; i < rays.size(); ++i) EXPECT_EQ(hits[i].triangle, MC_NO_HIT) << i;
  EXPECT_EQ(context().validation_messages(), 0u) << context().last_validation_message();
}

}  // namespace
}  // namespace meshcast::testing
