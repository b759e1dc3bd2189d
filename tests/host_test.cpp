// The host layer (host/): batches submitted now and collected later agree
// with the synchronous CPU walk on every layout the GPU reads, frames in
// flight never mix, a missing or lost device leaves the CPU answering, and
// several threads submitting at once get their own answers (this suite also
// runs under ThreadSanitizer in scripts/test.sh).
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <deque>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <cmath>
#include <cstdlib>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>

#include "meshcast/caster.h"
#if MESHCAST_VULKAN
#include "gpu/method.h"
#include "gpu/vulkan.h"
#include "layout/formats.h"
#endif
#include "check/generate.h"
#include "host/profile.h"
#include "tests/testing.h"

// Every allocation of this program counted, to show that a warm caster
// allocates nothing a frame (malloc and free behind new and delete, which
// GCC flags at inlined call sites: harmless here).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
static std::atomic<uint64_t> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace meshcast::testing {
namespace {

using host::Backend;
using host::Caster;
using host::CasterOptions;

// $MESHCAST_HOST_CPU_ONLY=1 keeps Vulkan out (for a ThreadSanitizer run
// on a driver whose own threads make it report what it cannot see), as does
// a build without the Vulkan backend (MESHCAST_VULKAN=OFF).
bool cpu_only() { return !MESHCAST_VULKAN || std::getenv("MESHCAST_HOST_CPU_ONLY") != nullptr; }

CasterOptions options(Backend b, uint32_t frames = 4) {
  CasterOptions o;
  o.backend = b, o.frames = frames, o.validation = true;
  return o;
}

// The Automatic backend passes over a software device (lavapipe, all a
// machine without a GPU has) unless one is named: its tests of the GPU side
// name the device $MESHCAST_VK_DEVICE names, else the first one, which it
// then takes whatever its type.
CasterOptions automatic_on_a_device() {
  CasterOptions o = options(Backend::Automatic);
  const char* env = std::getenv("MESHCAST_VK_DEVICE");
  o.device = env && *env ? env : "0";
  return o;
}

#if !MESHCAST_VULKAN
// Built without Vulkan: a caster asked for it says so and the CPU answers.
TEST(Host, WithoutTheVulkanBackendTheCpuAnswers) {
  const Mesh m = make_terrain(32, 32, 1);
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "terrain");
  for (Backend b : {Backend::Vulkan, Backend::Automatic}) {
    Caster caster(blob, "terrain", options(b));
    EXPECT_FALSE(caster.gpu_available());
    EXPECT_NE(caster.gpu_error().find("MESHCAST_VULKAN=OFF"), std::string::npos) << caster.gpu_error();
    const std::vector<Ray> rays = make_rays(m, RayKind::Long, 500, 1);
    std::vector<Hit> now(rays.size()), later(rays.size());
    caster.trace_now(rays, now);
    EXPECT_EQ(caster.wait(caster.submit(rays), later).ran_on, Backend::Cpu);
    for (size_t i = 0; i < rays.size(); ++i) EXPECT_EQ(later[i].triangle, now[i].triangle) << i;
  }
}
#endif

// Same triangle as the synchronous CPU walk, t within 1e-6 relative; a
// different triangle only at exactly the same t.
void expect_same(const std::vector<Hit>& got, const std::vector<Hit>& cpu, const std::string& what) {
  size_t differ = 0, hits = 0;
  for (size_t i = 0; i < cpu.size(); ++i) {
    hits += cpu[i].triangle != MC_NO_HIT;
    if (got[i].triangle != cpu[i].triangle && got[i].t == cpu[i].t) continue;
    bool t_ok = cpu[i].triangle == MC_NO_HIT || std::fabs(got[i].t - cpu[i].t) <= 1e-6 * std::fabs(cpu[i].t);
    if (got[i].triangle != cpu[i].triangle || !t_ok) ++differ;
  }
  EXPECT_EQ(differ, 0u) << what;
  EXPECT_GT(hits, cpu.size() / 20) << what << ": a ray set that never hits proves nothing";
}

std::vector<Hit> sync_cpu(const Caster& c, const std::vector<Ray>& rays) {
  std::vector<Hit> hits(rays.size());
  c.trace_now(rays, hits);
  return hits;
}

// Under ThreadSanitizer (scripts/test.sh) the test below walks the
// recommended layout alone: the caster's threads are the same for every
// layout, all of them took lavapipe two and a half minutes there, and the
// Release run walks them all.
#if defined(__SANITIZE_THREAD__)
#define MESHCAST_TEST_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define MESHCAST_TEST_TSAN 1
#endif
#endif
#ifdef MESHCAST_TEST_TSAN
const char* const kGpuLayouts[] = {"OctTreeCompressed/ClusterBitPackSOA8"};
#else
const char* const kGpuLayouts[] = {"BruteForce/Float3SOA128", "BruteForce/BitPackSOA128", "AABBList/Float3SOA128",
                                   "AABBList/BitPackSOA128", "AABBTree/Float3",
                                   "AABBTree/UncompressedStrip", "SKDTree/Float3", "StacklessLBVH/Float3",
                                   "QuadTreeHalfFloat/Indexed8BitPackSOA4", "OctTreeCompressed/ClusterBitPackSOA8",
                                   "OctTreeCompressed/ClusterFloat3SOA8"};
#endif

TEST(Host, SubmitWaitEqualsTheSynchronousCpuOnEveryGpuLayout) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  Mesh m = make_terrain(96, 64, 3);
  NamedMesh named{"terrain_12k", std::make_shared<const Mesh>(m)};
  for (const char* layout : kGpuLayouts) {
    // What this checks is the caster's frames, not the walk: the layouts
    // whose walk tests every triangle (or every batch) for every ray take a
    // tenth of the rays (2,000 a kind took lavapipe most of a minute).
    const std::string_view name(layout);
    const size_t count = name.starts_with("BruteForce/") || name.starts_with("AABBList/") ? 200 : 2000;
    std::vector<uint8_t> blob = build_blob(m, parse_layout(layout), "terrain");
    for (Backend b : {Backend::Cpu, Backend::Vulkan}) {
      Caster caster(blob, "terrain", options(b));
      ASSERT_TRUE(b == Backend::Cpu || caster.gpu_available()) << caster.gpu_error();
      std::vector<host::Ticket> tickets;
      std::vector<const std::vector<Ray>*> sets;
      for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial}) {
        sets.push_back(&test_rays(named, kind, count));
        tickets.push_back(caster.submit(*sets.back()));  // three frames in flight
      }
      for (size_t k = 0; k < tickets.size(); ++k) {
        std::vector<Hit> hits(sets[k]->size());
        host::BatchRecord r = caster.wait(tickets[k], hits);
        EXPECT_EQ(r.ran_on, b);
        EXPECT_EQ(r.rays, sets[k]->size());
        EXPECT_GT(r.latency_ms, 0.0);
        expect_same(hits, sync_cpu(caster, *sets[k]), std::string(layout) + " on " + host::backend_name(b));
      }
      // Again, now that the command buffers are recorded: resubmitted as they are.
      for (size_t k = 0; k < sets.size(); ++k) tickets[k] = caster.submit(*sets[k]);
      for (size_t k = 0; k < sets.size(); ++k) {
        std::vector<Hit> hits(sets[k]->size());
        caster.wait(tickets[k], hits);
        expect_same(hits, sync_cpu(caster, *sets[k]), std::string(layout) + " resubmitted");
      }
      EXPECT_EQ(caster.validation_messages(), 0u);
    }
  }
}

// CasterOptions::hit_outputs reach both backends: u, v and the point as the
// synchronous CPU walk gives them (which asks for the same), t and the
// triangle as without them.
TEST(Host, HitOutputsOnBothBackends) {
  Mesh m = make_terrain(48, 32, 4);
  NamedMesh named{"terrain_3k", std::make_shared<const Mesh>(m)};
  const std::vector<Ray>& rays = test_rays(named, RayKind::Long, 1000);
  std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "terrain");
  std::vector<Hit> plain(rays.size());
  BlobView(blob, "terrain").trace(rays, plain);
  for (Backend b : {Backend::Cpu, Backend::Vulkan}) {
    if (b == Backend::Vulkan && cpu_only()) continue;
    CasterOptions o = options(b);
    o.hit_outputs = HitOutputs::Uv | HitOutputs::Point;
    Caster caster(blob, "terrain", o);
    ASSERT_TRUE(b == Backend::Cpu || caster.gpu_available()) << caster.gpu_error();
    std::vector<Hit> hits(rays.size());
    EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, b);
    const std::vector<Hit> cpu = sync_cpu(caster, rays);
    expect_same(hits, plain, host::backend_name(b));
    size_t with_point = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      if (hits[i].triangle == MC_NO_HIT || hits[i].triangle != cpu[i].triangle) continue;
      EXPECT_NEAR(hits[i].u, cpu[i].u, 1e-5f) << i;
      EXPECT_NEAR(hits[i].v, cpu[i].v, 1e-5f) << i;
      for (int a = 0; a < 3; ++a) {
        const double p = double(rays[i].org[a]) + double(hits[i].t) * rays[i].dir[a];
        EXPECT_NEAR(hits[i].point[a], p, 1e-4) << i;
      }
      with_point += hits[i].point[0] != 0 || hits[i].point[1] != 0 || hits[i].point[2] != 0;
      EXPECT_EQ(plain[i].u, 0.0f) << "not asked for: " << i;
    }
    EXPECT_GT(with_point, rays.size() / 4) << host::backend_name(b);
    EXPECT_EQ(caster.validation_messages(), 0u);
  }
}

// The query is per batch: any hit, culled closest hits and
// every hit, in flight at once beside closest-hit batches, on both
// backends: each batch the BlobView's own answer to its query. Asking for
// the other kind of answer than the batch's is a UsageError.
TEST(Host, EveryQueryPerBatchOnBothBackends) {
  Mesh m = make_sphere(16, 32, 1.0f, {0, 0, 0});
  NamedMesh named{"sphere_host", std::make_shared<const Mesh>(m)};
  const std::vector<Ray>& rays = test_rays(named, RayKind::Long, 700);
  std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  const BlobView view(blob, "sphere");
  for (Backend b : {Backend::Cpu, Backend::Vulkan}) {
    if (b == Backend::Vulkan && cpu_only()) continue;
    Caster caster(blob, "sphere", options(b));
    ASSERT_TRUE(b == Backend::Cpu || caster.gpu_available()) << caster.gpu_error();
    const host::BatchQuery any{Query::Any}, culled{Query::Closest, Cull::Back}, all{Query::All, Cull::Front, 4};
    const host::Ticket t_closest = caster.submit(rays), t_any = caster.submit(rays, any);
    const host::Ticket t_culled = caster.submit(rays, culled), t_all = caster.submit(rays, all);
    std::vector<Hit> hits(rays.size()), expected(rays.size());
    HitLists lists;
    EXPECT_THROW(caster.wait(t_all, hits), UsageError);
    EXPECT_THROW(caster.wait(t_any, lists), UsageError);
    EXPECT_EQ(caster.wait(t_all, lists).ran_on, b);
    const HitLists expected_lists = trace_lists(view, rays, 4, Cull::Front);
    EXPECT_EQ(lists.max_hits, 4u);
    EXPECT_EQ(lists.found, expected_lists.found) << host::backend_name(b);
    for (size_t i = 0; i < rays.size(); ++i)
      for (size_t k = 0; k < lists.row(i).size(); ++k)
        EXPECT_EQ(lists.row(i)[k].triangle, expected_lists.row(i)[k].triangle) << host::backend_name(b) << " ray " << i;
    for (auto [ticket, query] : {std::pair{t_culled, culled}, std::pair{t_any, any}, std::pair{t_closest, host::BatchQuery{}}}) {
      EXPECT_EQ(caster.wait(ticket, hits).ran_on, b);
      view.trace(rays, expected, HitOutputs::None, query.query, query.cull);
      if (query.query == Query::Any) {  // any hit will do, but a hit for a hit
        for (size_t i = 0; i < rays.size(); ++i)
          EXPECT_EQ(hits[i].triangle == MC_NO_HIT, expected[i].triangle == MC_NO_HIT) << host::backend_name(b) << " ray " << i;
      } else {
        expect_same(hits, expected, std::string(host::backend_name(b)) + ", query " + std::to_string(int(query.cull)));
      }
    }
    HitLists now;
    now.max_hits = 4;
    caster.trace_now(rays, now, Cull::Front);
    EXPECT_EQ(now.found, expected_lists.found);
    EXPECT_THROW(caster.submit(rays, {Query::All, Cull::None, 0}), UsageError);
    EXPECT_EQ(caster.validation_messages(), 0u);
  }
}

// Rows of every hit at the limit against rows of 3 of the same rays: the
// same counts, each row of `every` holding its kept hits alone (the rows'
// memory follows the hits found, not rays x kMaxHitsLimit) and extending
// the row of 3 (the same triangles; t within 1e-6 relative, the GPU's
// own rounding).
bool same_hit(const Hit& a, const Hit& b) {
  return a.triangle == b.triangle && std::fabs(a.t - b.t) <= 1e-6f * std::fabs(b.t);
}
bool same_hit(const SceneHit& a, const SceneHit& b) {
  return a.instance == b.instance && a.triangle == b.triangle && a.t == b.t;
}
template <class Record>
void expect_rows_extend(const HitRows<Record>& every, const HitRows<Record>& few, const std::string& what) {
  ASSERT_EQ(every.max_hits, kMaxHitsLimit) << what;
  ASSERT_EQ(every.found, few.found) << what;
  size_t kept = 0;
  for (uint32_t found : every.found) kept += std::min(found, kMaxHitsLimit);
  ASSERT_GT(kept, every.found.size()) << what << ": too few hits to show anything";
  ASSERT_EQ(every.hits.size(), kept) << what << ": rows holding more than the hits found";
  for (size_t i = 0; i < every.found.size(); ++i) {
    ASSERT_EQ(every.row(i).size(), std::min(every.found[i], kMaxHitsLimit)) << what << ", ray " << i;
    for (size_t k = 0; k < few.row(i).size(); ++k)
      EXPECT_TRUE(same_hit(every.row(i)[k], few.row(i)[k])) << what << ", ray " << i << ", record " << k;
  }
}

// Every hit at the limit (kMaxHitsLimit a ray) on both backends and in a
// scene batch: 12 stacked planes, rays through all of them, cut short or
// aimed away. The caller's lists held longer rows before: they are
// replaced. A batch whose fixed device rows exceed the device's buffers is
// refused by the GPU method before it allocates, and the CPU answers it.
TEST(Host, EveryHitRowsAtTheLimitHoldTheHitsFoundAlone) {
  constexpr int kPlanes = 12;
  const Mesh planes = stacked_planes(kPlanes);
  std::vector<Ray> rays = rays_down_through(kPlanes, 3000);
  for (size_t i = 0; i < rays.size(); ++i) {
    if (i % 4 == 1) rays[i].tmax = float(i % kPlanes) + 0.5f;
    if (i % 4 == 2) rays[i].dir[2] = 1;
  }
  const std::vector<uint8_t> blob = build_blob(planes, parse_layout("AABBTree/Float3"), "planes");
  const BlobView view(blob, "planes");
  const HitLists few = trace_lists(view, rays, 3);
  const host::BatchQuery limit{Query::All, Cull::None, kMaxHitsLimit};
  for (Backend b : {Backend::Cpu, Backend::Vulkan}) {
    if (b == Backend::Vulkan && cpu_only()) continue;
    Caster caster(blob, "planes", options(b));
    ASSERT_TRUE(b == Backend::Cpu || caster.gpu_available()) << caster.gpu_error();
    HitLists lists = trace_lists(view, rays, 64);  // what the wait replaces
    EXPECT_EQ(caster.wait(caster.submit(rays, limit), lists).ran_on, b);
    expect_rows_extend(lists, few, host::backend_name(b));
    if (b == Backend::Vulkan) {
      // 140,000 rows of 4096 hits are 4.6 GB of device rows, beyond any
      // storage buffer (maxStorageBufferRange is a uint32).
      std::vector<Ray> many;
      while (many.size() < 140000) many.insert(many.end(), rays.begin(), rays.end());
      many.resize(140000);
      EXPECT_EQ(caster.wait(caster.submit(many, limit), lists).ran_on, Backend::Cpu);
      EXPECT_TRUE(caster.gpu_available()) << caster.gpu_error();
      ASSERT_EQ(lists.found.size(), many.size());
      for (size_t i = 0; i < many.size(); i += 997) EXPECT_EQ(lists.found[i], few.found[i % rays.size()]) << "ray " << i;
    }
    EXPECT_EQ(caster.validation_messages(), 0u);
  }
  // A scene batch: the planes placed twice, one above the other.
  Scene scene;
  const MeshId mesh = scene.add_mesh(blob, "planes");
  Transform above;
  above.translation[2] = 100;
  scene.add_instance(mesh, Transform{}), scene.add_instance(mesh, above);
  scene.commit();
  std::vector<RayD> world;
  for (const Ray& r : rays) world.push_back({{r.org[0], r.org[1], double(r.org[2]) + 100}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax + 100});
  SceneHitLists few_scene, got;
  few_scene.max_hits = 3;
  scene.trace_all_hits(world, few_scene);
  Caster scenes(options(Backend::Cpu));
  got.max_hits = 7;
  EXPECT_EQ(scenes.wait(scenes.submit(scene, world, {Query::All, Cull::None, 0xFF, kMaxHitsLimit}), got).ran_on, Backend::Cpu);
  expect_rows_extend(got, few_scene, "scene batch");
}

// Eight frames of different sizes and rays, collected in reverse order.
TEST(Host, FramesInFlightNeverMix) {
  Mesh m = make_sphere(24, 48, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "sphere");
  for (Backend b : {Backend::Cpu, Backend::Vulkan}) {
    if (b == Backend::Vulkan && cpu_only()) continue;
    Caster caster(blob, "sphere", options(b, 8));
    std::vector<std::vector<Ray>> frames;
    std::vector<host::Ticket> tickets;
    for (uint32_t f = 0; f < 8; ++f) {
      frames.push_back(make_rays(m, f % 2 ? RayKind::Radial : RayKind::Long, 100 + 300 * f, 40 + f));
      tickets.push_back(caster.submit(frames.back()));
    }
    EXPECT_THROW(caster.submit(frames[0]), UsageError);  // all eight frames are taken
    for (uint32_t f = 8; f-- > 0;) {
      std::vector<Hit> hits(frames[f].size());
      caster.wait(tickets[f], hits);
      expect_same(hits, sync_cpu(caster, frames[f]), "frame " + std::to_string(f));
      EXPECT_THROW(caster.wait(tickets[f], hits), UsageError);  // collected once
    }
    EXPECT_EQ(caster.validation_messages(), 0u);
  }
}

// A caller's mistakes get a UsageError naming what was wrong: a ticket of
// another caster or a made-up one, a hits span too short for the batch, on
// the caster and on a BlobView.
TEST(Host, MisuseIsAUsageError) {
  const Mesh m = make_sphere(8, 16, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  Caster caster(blob, "sphere", options(Backend::Cpu, 2));
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 50, 3);
  std::vector<Hit> hits(rays.size()), short_hits(rays.size() - 1);
  auto expect_usage = [](auto&& call, const std::string& words) { expect_throws<UsageError>(call, {words}); };
  expect_usage([&] { caster.poll(host::Ticket{12345, 7}); }, "not a ticket of this caster");
  expect_usage([&] { caster.wait(host::Ticket{12345, 7}, hits); }, "not a ticket of this caster");
  expect_usage([&] { caster.wait(host::Ticket{12345, 0}, hits); }, "issued by no caster");
  const host::Ticket t = caster.submit(rays);
  expect_usage([&] { caster.wait(host::Ticket{12345, 0, t.caster}, hits); }, "unknown or already collected");
  expect_usage([&] { caster.wait(t, short_hits); }, "needs room for 50 hits");
  caster.wait(t, hits);
  expect_usage([&] { caster.trace_now(rays, short_hits); }, "room for 49 hits");
  expect_usage([&] { BlobView(blob, "sphere").trace(rays, short_hits); }, "50 rays but room for 49 hits");
}

// Every caster numbers its batches from 1, so two casters issue tickets of
// the same id and slot: each refuses the other's tickets and open batches,
// and a destroyed caster's, even when a new caster takes its place, rather
// than answer its own batch for them.
TEST(Host, AnotherCastersTicketsAndOpenBatchesAreRefused) {
  const Mesh m = make_sphere(8, 16, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 50, 3);
  std::vector<Hit> hits(rays.size());
  auto expect_refused = [](auto&& call) { expect_throws<UsageError>(call, {"another caster", "not a ticket of this caster"}); };
  Caster a(blob, "sphere", options(Backend::Cpu, 2)), b(blob, "sphere", options(Backend::Cpu, 2));
  const host::Ticket ta = a.submit(rays), tb = b.submit(rays);
  ASSERT_TRUE(ta.id == tb.id && ta.slot == tb.slot);  // what the casters' own numbers cannot tell apart
  EXPECT_NE(ta.caster, tb.caster);
  expect_refused([&] { b.poll(ta); });
  expect_refused([&] { b.wait(ta, hits); });
  b.wait(tb, hits);  // b's own batch is still b's to collect
  a.wait(ta, hits);
  host::OpenBatch oa = a.open(10), ob = b.open(10);
  ASSERT_TRUE(oa.ticket.id == ob.ticket.id && oa.ticket.slot == ob.ticket.slot);
  std::copy(rays.begin(), rays.begin() + 10, oa.rays.begin());
  std::copy(rays.begin(), rays.begin() + 10, ob.rays.begin());
  expect_refused([&] { b.submit(oa); });
  std::vector<Hit> ten(10);
  b.wait(b.submit(ob), ten);  // still open, and b's own
  a.wait(a.submit(oa), ten);
  // A caster gone with its batch uncollected, and another made after it.
  host::Ticket gone;
  {
    Caster c(blob, "sphere", options(Backend::Cpu, 2));
    gone = c.submit(rays);
  }
  Caster d(blob, "sphere", options(Backend::Cpu, 2));
  const host::Ticket td = d.submit(rays);
  ASSERT_TRUE(gone.id == td.id && gone.slot == td.slot);
  expect_refused([&] { d.wait(gone, hits); });
  d.wait(td, hits);
}

// An engine's job system: here every run goes to a thread of its own, and
// the calls are counted. While `fail` is set, run() throws EngineFault (a
// type of the engine's own, not a std::exception), as a full queue might;
// threads() says `thread_count`.
struct EngineFault {
  int code;
};
class CountingJobs : public host::JobSystem {
 public:
  void run(uint32_t count, const std::function<void(uint32_t)>& work) override {
    if (fail) throw EngineFault{7};
    runs += 1;
    threads_.emplace_back([count, &work] {
      for (uint32_t i = 0; i < count; ++i) work(i);
    });
  }
  uint32_t threads() const override { return thread_count; }
  ~CountingJobs() override {
    for (std::thread& t : threads_) t.join();
  }
  std::atomic<int> runs{0};
  std::atomic<bool> fail{false};
  std::atomic<uint32_t> thread_count{3};

 private:
  std::vector<std::thread> threads_;
};

// An option out of range is refused, naming the option and its range, by
// both constructors, never bent into range: no frames, more frames or
// threads than a caster takes, a backend or hit outputs outside their
// enums, an engine's job system of no threads. The limits themselves are
// taken.
TEST(Host, OptionsOutOfRangeAreRefused) {
  const Mesh m = make_sphere(8, 16, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  CountingJobs none;
  none.thread_count = 0;
  auto refused = [&](auto change, std::initializer_list<std::string> words) {
    CasterOptions o = options(Backend::Cpu);
    change(o);
    expect_throws<UsageError>([&] { Caster c(blob, "sphere", o); }, words);
    expect_throws<UsageError>([&] { Caster c(o); }, words);
  };
  refused([](CasterOptions& o) { o.frames = 0; }, {"CasterOptions::frames 0", "1..1024"});
  refused([](CasterOptions& o) { o.frames = ~0u; }, {"CasterOptions::frames 4294967295", "1..1024"});
  refused([](CasterOptions& o) { o.threads = 5000; }, {"CasterOptions::threads 5000", "0..1024"});
  refused([](CasterOptions& o) { o.backend = Backend(7); }, {"CasterOptions::backend 7"});
  refused([](CasterOptions& o) { o.hit_outputs = HitOutputs(0x100); }, {"CasterOptions::hit_outputs 256", "HitOutputs::Uv"});
  refused([&](CasterOptions& o) { o.jobs = &none; }, {"CasterOptions::jobs", "threads() is 0"});
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 100, 2);
  std::vector<Hit> hits(rays.size());
  Caster one(blob, "sphere", options(Backend::Cpu, 1));
  const host::Ticket t = one.submit(rays);
  EXPECT_THROW(one.submit(rays), UsageError);  // its one frame is taken
  one.wait(t, hits);
  Caster most(blob, "sphere", options(Backend::Cpu, host::kMaxCasterFrames));
  most.wait(most.submit(rays), hits);
}

TEST(Host, AMissingDeviceIsReportedAndTheCpuAnswers) {
  Mesh m = make_sphere(12, 24, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  CasterOptions o = options(Backend::Vulkan);
  o.device = "no such device";
  Caster caster(blob, "sphere", o);
  EXPECT_FALSE(caster.gpu_available());
  // Without the Vulkan backend the error says that instead.
  EXPECT_NE(caster.gpu_error().find(MESHCAST_VULKAN ? "no such device" : "MESHCAST_VULKAN=OFF"), std::string::npos)
      << caster.gpu_error();
  EXPECT_NE(caster.why(100).find("unavailable"), std::string::npos) << caster.why(100);
  std::vector<Ray> rays = make_rays(m, RayKind::Long, 500, 3);
  std::vector<Hit> hits(rays.size());
  EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Cpu);
  expect_same(hits, sync_cpu(caster, rays), "after a missing device");
}

// An environment variable set (value) or unset (null) for a scope, and put
// back as it was after it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* was = std::getenv(name)) was_ = was;
    if (value) ::setenv(name, value, 1);
    else ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (was_) ::setenv(name_, was_->c_str(), 1);
    else ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> was_;
};

// Mesa's lavapipe driver manifest in the loader's usual folders; "" for none.
std::string lavapipe_manifest() {
  for (const char* dir : {"/usr/share/vulkan/icd.d", "/usr/local/share/vulkan/icd.d", "/etc/vulkan/icd.d"}) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
      if (entry.path().filename().string().starts_with("lvp_icd")) return entry.path().string();
  }
  return "";
}

// A machine whose only Vulkan device is a software one (the loader shown
// lavapipe's driver alone): the Automatic backend makes an instance to
// look, destroys it at once, measures nothing, and leaves the CPU
// answering, saying why. Named, or on Backend::Vulkan, the device is taken.
TEST(Host, AutomaticPassesOverASoftwareDeviceAndSaysWhy) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  const std::string manifest = lavapipe_manifest();
  if (manifest.empty()) GTEST_SKIP() << "no lavapipe driver manifest (mesa-vulkan-drivers)";
  // VK_DRIVER_FILES for newer loaders, VK_ICD_FILENAMES for older ones.
  const ScopedEnv drivers("VK_DRIVER_FILES", manifest.c_str()), icds("VK_ICD_FILENAMES", manifest.c_str()),
      unnamed("MESHCAST_VK_DEVICE", nullptr);
  const Mesh m = make_sphere(12, 24, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "sphere");
  const host::VulkanInstances before = host::vulkan_instances();
  {
    Caster caster(blob, "sphere", options(Backend::Automatic));
    const host::VulkanInstances looked = host::vulkan_instances();
    EXPECT_EQ(looked.created, before.created + 1);  // made to see the devices
    EXPECT_EQ(looked.alive, before.alive);           // and gone at once
    EXPECT_FALSE(caster.gpu_available());
    EXPECT_TRUE(caster.crossover_known());  // nothing to measure
    EXPECT_EQ(caster.crossover(), ~0u);
    EXPECT_NE(caster.gpu_error().find("no device but CPU-type (software) ones (llvmpipe"), std::string::npos)
        << caster.gpu_error();
    const std::string why = caster.why(1u << 20);
    EXPECT_EQ(why.rfind("1048576 rays: CPU, the GPU is unavailable (", 0), 0u) << why;
    EXPECT_NE(why.find("the automatic choice passes over"), std::string::npos) << why;
    const std::vector<Ray> rays = make_rays(m, RayKind::Long, 500, 3);
    std::vector<Hit> hits(rays.size());
    EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Cpu);
    expect_same(hits, sync_cpu(caster, rays), "the Automatic backend beside a software device");
  }
  for (const CasterOptions& o : {options(Backend::Vulkan), automatic_on_a_device()}) {
    Caster caster(blob, "sphere", o);
    EXPECT_TRUE(caster.gpu_available()) << host::backend_name(o.backend) << ": " << caster.gpu_error();
    EXPECT_NE(caster.device_name().find("llvmpipe"), std::string::npos) << caster.device_name();
  }
}

// A caster that will never use the GPU makes no Vulkan instance at all:
// Backend::Cpu, for blob and scene batches, and a caster of scene batches
// alone on Automatic (which sends them to the CPU).
TEST(Host, CastersThatNeverUseTheGpuMakeNoVulkanInstance) {
  const Mesh m = make_sphere(12, 24, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "sphere");
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 300, 4);
  Scene scene;
  scene.add_instance(scene.add_mesh(blob, "sphere"), Transform{});
  scene.commit();
  std::vector<RayD> world;
  for (const Ray& r : rays) world.push_back({{r.org[0], r.org[1], r.org[2]}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax});
  const host::VulkanInstances before = host::vulkan_instances();
  {
    Caster cpu(blob, "sphere", options(Backend::Cpu));
    std::vector<Hit> hits(rays.size());
    EXPECT_EQ(cpu.wait(cpu.submit(rays), hits).ran_on, Backend::Cpu);
    std::vector<SceneHit> scene_hits(world.size());
    EXPECT_EQ(cpu.wait(cpu.submit(scene, world), scene_hits).ran_on, Backend::Cpu);
    EXPECT_FALSE(cpu.gpu_available());
    EXPECT_EQ(cpu.device_name(), "none");
  }
  {
    Caster scenes(options(Backend::Automatic));
    std::vector<SceneHit> scene_hits(world.size());
    EXPECT_EQ(scenes.wait(scenes.submit(scene, world), scene_hits).ran_on, Backend::Cpu);
    EXPECT_FALSE(scenes.gpu_available());
    EXPECT_EQ(scenes.gpu_error(), "");
  }
  const host::VulkanInstances after = host::vulkan_instances();
  EXPECT_EQ(after.created, before.created);
  EXPECT_EQ(after.alive, before.alive);
}

// A Vulkan caster on a small sphere whose GPU submissions go through
// `fault(n)` first (n counts from 1): the fault-injection tests' setup.
struct FaultySphere {
  explicit FaultySphere(std::function<void(int)> fault) {
    CasterOptions o = options(Backend::Vulkan);
    o.before_gpu_submit = [this, fault] { fault(++submissions); };
    caster = std::make_unique<Caster>(blob, "sphere", o);
  }
  Mesh mesh = make_sphere(12, 24, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(mesh, parse_layout("AABBTree/Float3"), "sphere");
  std::vector<Ray> rays = make_rays(mesh, RayKind::Radial, 500, 5);
  int submissions = 0;
  std::unique_ptr<Caster> caster;
};

// A refusal that is not a lost device (a batch beyond a buffer limit,
// memory) sends that one batch to the CPU and keeps the GPU.
TEST(Host, ARefusedBatchGoesToTheCpuAndTheGpuStays) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  FaultySphere f([](int submission) {
    if (submission == 2) throw GpuError("Vulkan: the ray buffer exceeds a limit (injected by the test)");
  });
  Caster& caster = *f.caster;
  const std::vector<Ray>& rays = f.rays;
  std::vector<Hit> hits(rays.size());
  EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Vulkan);
  EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Cpu);
  expect_same(hits, sync_cpu(caster, rays), "the refused batch");
  EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Vulkan);
  EXPECT_TRUE(caster.gpu_available());
}

TEST(Host, ALostDeviceMovesTheBatchesToTheCpu) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  FaultySphere f([](int submission) {
    if (submission > 1) throw GpuError("Vulkan: device lost (injected by the test)", true);
  });
  Caster& caster = *f.caster;
  const std::vector<Ray>& rays = f.rays;
  std::vector<Hit> hits(rays.size());
  EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Vulkan);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Cpu);
    expect_same(hits, sync_cpu(caster, rays), "after a lost device");
  }
  EXPECT_FALSE(caster.gpu_available());
  EXPECT_NE(caster.gpu_error().find("device lost"), std::string::npos) << caster.gpu_error();
}

// Four threads, each with rays of its own, submitting and collecting at once.
TEST(Host, ThreadsSubmittingAtOnceGetTheirOwnAnswers) {
  Mesh m = make_terrain(64, 64, 9);
  std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "terrain");
  for (Backend b : {Backend::Cpu, Backend::Vulkan}) {
    if (b == Backend::Vulkan && cpu_only()) continue;
    Caster caster(blob, "terrain", options(b, 8));
    std::vector<std::vector<Ray>> rays;
    std::vector<std::vector<Hit>> expected;
    for (uint32_t t = 0; t < 4; ++t) {
      rays.push_back(make_rays(m, RayKind::Radial, 300 + 100 * t, 100 + t));
      expected.push_back(sync_cpu(caster, rays.back()));
    }
    std::vector<size_t> wrong(4, 0);
    std::vector<std::thread> threads;
    for (uint32_t t = 0; t < 4; ++t)
      threads.emplace_back([&, t] {
        std::vector<Hit> hits(rays[t].size());
        for (int k = 0; k < 20; ++k) {
          host::Ticket ticket = caster.submit(rays[t]);
          caster.wait(ticket, hits);
          for (size_t i = 0; i < hits.size(); ++i) wrong[t] += hits[i].triangle != expected[t][i].triangle && hits[i].t != expected[t][i].t;
        }
      });
    for (std::thread& th : threads) th.join();
    for (uint32_t t = 0; t < 4; ++t) EXPECT_EQ(wrong[t], 0u) << host::backend_name(b) << " thread " << t;
    EXPECT_EQ(caster.percentiles(b).batches, 80u);
  }
}

// After the first batches of a size, submit and wait allocate nothing (the
// CPU backend: the GPU's driver is not ours to count).
TEST(Host, AWarmCasterAllocatesNothingAFrame) {
  Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "sphere");
  Caster caster(blob, "sphere", options(Backend::Cpu, 2));
  std::vector<Ray> a = make_rays(m, RayKind::Long, 2000, 1), b = make_rays(m, RayKind::Radial, 1500, 2);
  std::vector<Hit> hits(2000);
  auto frame = [&] {
    host::Ticket ta = caster.submit(a), tb = caster.submit(b);  // two frames in flight
    caster.wait(ta, hits);
    caster.wait(tb, hits);
  };
  for (int k = 0; k < 3; ++k) frame();  // warm-up: each slot grows its buffers once
  const uint64_t before = g_allocations.load();
  for (int k = 0; k < 20; ++k) frame();
  EXPECT_EQ(g_allocations.load() - before, 0u);
  // Every hit at the limit, blob and scene batches, on a caster of one
  // worker (a worker makes its scratch rows on its first every-hit job):
  // the jobs' rows, the worker's scratch and the caller's lists are kept.
  CasterOptions one = options(Backend::Cpu, 2);
  one.threads = 1;
  Caster every(blob, "sphere", one);
  Scene scene;
  scene.add_instance(scene.add_mesh(blob, "sphere"), Transform{});
  scene.commit();
  std::vector<RayD> world;
  for (const Ray& r : a) world.push_back(widened(r));
  HitLists lists;
  SceneHitLists scene_lists;
  auto every_frame = [&] {
    const host::Ticket ta = every.submit(a, {Query::All, Cull::None, kMaxHitsLimit});
    const host::Ticket tb = every.submit(scene, world, {Query::All, Cull::None, 0xFF, kMaxHitsLimit});
    every.wait(ta, lists);
    every.wait(tb, scene_lists);
  };
  for (int k = 0; k < 3; ++k) every_frame();
  const uint64_t before_every = g_allocations.load();
  for (int k = 0; k < 20; ++k) every_frame();
  EXPECT_EQ(g_allocations.load() - before_every, 0u);
  EXPECT_GT(lists.hits.size(), a.size() / 2);
  EXPECT_EQ(scene_lists.hits.size(), lists.hits.size());
}

#if MESHCAST_VULKAN
// The GPU's side of the same (no validation layer: it allocates on every
// call it checks). A method's batches through rays(), submit() and hits()
// in two frame slots, sizes alternating, closest and every hit: after the
// first batch of each slot nothing is allocated, and each slot's mapped
// ray and hit memory stays where it was (no buffer made again). Then a
// caster on the Vulkan backend, frames in flight: nothing either.
TEST(Host, AWarmGpuBatchAllocatesNothing) {
  if (cpu_only()) GTEST_SKIP() << "the Vulkan backend is kept out";
  // $MESHCAST_VK_VALIDATION=1 (the test command's) would turn the layer on
  // for this test's instances too: left out while they are made.
  struct WithoutValidationEnv {
    std::string was;
    bool set = false;
    WithoutValidationEnv() {
      if (const char* v = std::getenv("MESHCAST_VK_VALIDATION")) was = v, set = true;
      unsetenv("MESHCAST_VK_VALIDATION");
    }
    ~WithoutValidationEnv() {
      if (set) setenv("MESHCAST_VK_VALIDATION", was.c_str(), 1);
    }
  } without_validation;
  Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "sphere");
  std::vector<Ray> a = make_rays(m, RayKind::Long, 2000, 1), b = make_rays(m, RayKind::Radial, 1500, 2);
  gpu::Context ctx(gpu::DeviceChoice{"", false});
  const std::unique_ptr<gpu::Method> closest = gpu::make_method(ctx, "octtree", blob, "sphere", 2);
  const std::unique_ptr<gpu::Method> every = gpu::make_method(ctx, "octtree", blob, "sphere", 2, MC_QUERY_ALL, 8);
  HitLists lists;
  std::vector<const void*> where;
  where.reserve(4 * 21);  // the frames' records, kept out of the count
  uint64_t hit_sum = 0;
  auto frame = [&](bool record) {
    for (uint32_t slot = 0; slot < 2; ++slot) {
      const std::vector<Ray>& rays = slot ? b : a;
      const std::span<Ray> to = closest->rays(slot, rays.size());
      std::copy(rays.begin(), rays.end(), to.begin());
      closest->submit(slot);
      every->begin(slot, rays);
      if (record) where.push_back(to.data());
    }
    for (uint32_t slot = 0; slot < 2; ++slot) {
      const std::span<const Hit> hits = closest->hits(slot);
      hit_sum += hits[0].triangle != MC_NO_HIT;
      if (record) where.push_back(hits.data());
      every->finish_lists(slot, lists);
    }
  };
  for (int k = 0; k < 2; ++k) frame(false);  // warm-up: each slot grows its buffers once
  frame(true);
  const std::vector<const void*> first = where;
  const uint64_t before = g_allocations.load();
  for (int k = 0; k < 20; ++k) frame(true);
  EXPECT_EQ(g_allocations.load() - before, 0u);
  for (size_t i = first.size(); i < where.size(); ++i) EXPECT_EQ(where[i], first[i % first.size()]) << i;
  EXPECT_GT(lists.hits.size(), b.size() / 2);

  CasterOptions o = options(Backend::Vulkan, 2);
  o.validation = false;
  Caster caster(blob, "sphere", o);
  ASSERT_EQ(caster.gpu_error(), "");
  std::vector<Hit> hits(2000);
  auto caster_frame = [&] {
    host::Ticket ta = caster.submit(a), tb = caster.submit(b);  // two frames in flight
    caster.wait(ta, hits);
    caster.wait(tb, hits);
    host::OpenBatch in_place = caster.open(uint32_t(a.size()));  // written where the device reads it
    std::copy(a.begin(), a.end(), in_place.rays.begin());
    caster.wait(caster.submit(in_place), hits);
  };
  for (int k = 0; k < 3; ++k) caster_frame();
  const uint64_t before_caster = g_allocations.load();
  for (int k = 0; k < 20; ++k) caster_frame();
  EXPECT_EQ(g_allocations.load() - before_caster, 0u);
  EXPECT_EQ(caster.percentiles(Backend::Vulkan).batches, 69u);
}
#endif

// Batches written in place: open() gives room for the rays (on the GPU,
// its mapped memory), the caller writes them there and submits; the
// answers are the CPU walker's, on either backend, for one hit and every
// hit. An open batch holds its slot and cannot be polled or collected
// until submitted; submitted once.
TEST(Host, OpenBatchesAreWrittenInPlace) {
  Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "sphere");
  const BlobView view(blob, "sphere");
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 3000, 5);
  const std::vector<Hit> expected = trace_all(view, rays);
  const HitLists expected_rows = trace_lists(view, rays, 4, Cull::Back);
  std::vector<Backend> backends = {Backend::Cpu};
  if (!cpu_only()) backends.push_back(Backend::Vulkan);
  for (Backend b : backends) {
    Caster caster(blob, "sphere", options(b, 2));
    const std::string on = host::backend_name(b);
    for (int round = 0; round < 3; ++round) {
      host::OpenBatch open = caster.open(uint32_t(rays.size()));
      ASSERT_EQ(open.rays.size(), rays.size()) << on;
      EXPECT_THROW(caster.poll(open.ticket), UsageError) << on;
      std::vector<Hit> hits(rays.size());
      EXPECT_THROW(caster.wait(open.ticket, hits), UsageError) << on;
      std::copy(rays.begin(), rays.end(), open.rays.begin());
      const host::Ticket t = caster.submit(open);
      EXPECT_THROW(caster.submit(open), UsageError) << on << ": submitted twice";
      const host::BatchRecord r = caster.wait(t, hits);
      EXPECT_EQ(r.ran_on, b) << on;
      for (size_t i = 0; i < rays.size(); ++i)
        ASSERT_TRUE(hits[i].triangle == expected[i].triangle || hits[i].t == expected[i].t) << on << ", ray " << i;
      host::OpenBatch every = caster.open(uint32_t(rays.size()), {Query::All, Cull::Back, 4});
      std::copy(rays.begin(), rays.end(), every.rays.begin());
      HitLists lists;
      caster.wait(caster.submit(every), lists);
      ASSERT_EQ(lists.rays(), rays.size()) << on;
      for (size_t i = 0; i < rays.size(); ++i) {
        ASSERT_EQ(lists.found[i], expected_rows.found[i]) << on << ", ray " << i;
        for (size_t k = 0; k < lists.row(i).size(); ++k)
          EXPECT_EQ(lists.row(i)[k].triangle, expected_rows.row(i)[k].triangle) << on << ", ray " << i;
      }
    }
    // An open batch holds its slot: two open, a third refused.
    host::OpenBatch a = caster.open(10), c = caster.open(10);
    EXPECT_THROW(caster.open(10), UsageError) << on;
    for (host::OpenBatch* o : {&a, &c}) {
      std::copy(rays.begin(), rays.begin() + 10, o->rays.begin());
      std::vector<Hit> hits(10);
      caster.wait(caster.submit(*o), hits);
    }
    EXPECT_EQ(caster.validation_messages(), 0u) << on;
  }
}

// An open batch's room holds the slot's earlier rays until written: a
// caller that wrote k of them narrows the span to those (rays.first(k)),
// and the batch is those k rays, on either backend, one hit a ray or every
// hit; the rays the caller did not write are not answered. A span that
// starts elsewhere or grew is refused, and the batch stays open.
TEST(Host, AnOpenBatchSubmitsTheRaysWritten) {
  Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "sphere");
  const BlobView view(blob, "sphere");
  const uint32_t n = 3000, k = 700;
  const std::vector<Ray> earlier = make_rays(m, RayKind::Long, n, 5);
  const std::vector<Ray> written = make_rays(m, RayKind::Radial, k, 6);
  const std::vector<Hit> expected = trace_all(view, written);
  const HitLists expected_rows = trace_lists(view, written, 4, Cull::None);
  std::vector<Backend> backends = {Backend::Cpu};
  if (!cpu_only()) backends.push_back(Backend::Vulkan);
  for (Backend b : backends) {
    Caster caster(blob, "sphere", options(b, 1));  // one slot: every batch in the same room
    ASSERT_TRUE(b == Backend::Cpu || caster.gpu_available()) << caster.gpu_error();
    const std::string on = host::backend_name(b);
    for (const Query query : {Query::Closest, Query::All}) {
      const host::BatchQuery q{query, Cull::None, 4};
      host::OpenBatch first = caster.open(n, q);
      std::copy(earlier.begin(), earlier.end(), first.rays.begin());
      std::vector<Hit> hits(n);
      HitLists lists;
      if (query == Query::All) caster.wait(caster.submit(first), lists);
      else caster.wait(caster.submit(first), hits);

      host::OpenBatch next = caster.open(n, q);
      std::copy(written.begin(), written.end(), next.rays.begin());
      host::OpenBatch moved = next, grown = next;
      moved.rays = next.rays.subspan(1, k);
      grown.rays = std::span<Ray>(next.rays.data(), n + 1);  // never read: refused on its size
      expect_throws<UsageError>([&] { caster.submit(moved); }, {"do not start where open() put them", "rays.first(k)"});
      expect_throws<UsageError>([&] { caster.submit(grown); }, {"3001 rays, more than the 3000 opened"});
      next.rays = next.rays.first(k);
      const Hit untouched{-1.0f, 12345u};
      std::fill(hits.begin(), hits.end(), untouched);
      const host::Ticket t = caster.submit(next);
      const host::BatchRecord r = query == Query::All ? caster.wait(t, lists) : caster.wait(t, hits);
      EXPECT_EQ(r.rays, k) << on;
      EXPECT_EQ(r.ran_on, b) << on;
      if (query == Query::All) {
        ASSERT_EQ(lists.rays(), k) << on;
        for (size_t i = 0; i < k; ++i) ASSERT_EQ(lists.found[i], expected_rows.found[i]) << on << ", ray " << i;
      } else {
        for (size_t i = 0; i < k; ++i)
          ASSERT_TRUE(hits[i].triangle == expected[i].triangle || hits[i].t == expected[i].t) << on << ", ray " << i;
        for (size_t i = k; i < n; ++i) ASSERT_EQ(hits[i].triangle, 12345u) << on << ": ray " << i << " was not written";
      }
    }
    // None written: a batch of no rays, answered at once.
    host::OpenBatch none = caster.open(n);
    none.rays = none.rays.first(0);
    std::vector<Hit> no_hits;
    EXPECT_EQ(caster.wait(caster.submit(none), no_hits).rays, 0u) << on;
    EXPECT_EQ(caster.validation_messages(), 0u) << on;
  }
}

// A batch the machine's memory cannot hold is refused as a UsageError
// naming the rays and the bytes (not std::bad_alloc, which names nothing),
// before anything is allocated or read: open() of 2^32 - 1 rays, and
// submit() of spans that long (address space reserved, never readable: the
// caster must refuse them on their size alone). The slots stay free.
TEST(Host, ABatchBeyondMemoryIsAUsageError) {
  const Mesh m = make_sphere(8, 16, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  const uint64_t memory = uint64_t(::sysconf(_SC_PHYS_PAGES)) * uint64_t(::sysconf(_SC_PAGESIZE));
  const uint64_t most = UINT32_MAX;
  if (memory >= most * sizeof(Ray)) GTEST_SKIP() << "this machine holds 2^32 - 1 rays";
  Caster caster(blob, "sphere", options(Backend::Cpu, 1));
  expect_throws<UsageError>([&] { caster.open(UINT32_MAX); },
                            {"Caster::open: a batch of 4294967295 rays needs " + std::to_string(most * (sizeof(Ray) + sizeof(Hit))) + " bytes",
                             "more than this machine's memory"});
  expect_throws<UsageError>([&] { caster.open(UINT32_MAX, {Query::All, Cull::None, 4}); },
                            {"4294967295 rays needs " + std::to_string(most * sizeof(Ray)) + " bytes"});
  const size_t reserved = most * sizeof(RayD);
  void* space = ::mmap(nullptr, reserved, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (space != MAP_FAILED) {
    expect_throws<UsageError>([&] { caster.submit(std::span<const Ray>(static_cast<const Ray*>(space), most)); },
                              {"Caster::submit: a batch of 4294967295 rays", "bytes"});
    Scene scene;
    scene.add_instance(scene.add_mesh(blob, "sphere"), Transform{});
    scene.commit();
    Caster scenes(options(Backend::Cpu, 1));
    expect_throws<UsageError>(
        [&] { scenes.submit(scene, std::span<const RayD>(static_cast<const RayD*>(space), most)); },
        {"Caster::submit: a batch of 4294967295 rays needs " + std::to_string(most * (sizeof(RayD) + sizeof(SceneHit))) +
         " bytes"});
    ::munmap(space, reserved);
    std::vector<RayD> world(10);
    for (RayD& r : world) r = {{0, 0, 5}, {0, 0, -1}, INFINITY};
    std::vector<SceneHit> scene_hits(world.size());
    scenes.wait(scenes.submit(scene, world), scene_hits);
    EXPECT_EQ(scene_hits[0].instance, 0u);
  }
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 50, 3);
  std::vector<Hit> hits(rays.size());
  EXPECT_EQ(caster.wait(caster.submit(rays), hits).rays, 50u);
}

TEST(Host, AnEnginesJobSystemRunsTheCpuWork) {
  Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3SOA4"), "sphere");
  CountingJobs jobs;
  CasterOptions o = options(Backend::Cpu);
  o.jobs = &jobs;
  {
    Caster caster(blob, "sphere", o);
    EXPECT_EQ(caster.cpu_threads(), 3u);
    std::vector<Ray> rays = make_rays(m, RayKind::Long, 3000, 8);
    std::vector<Hit> hits(rays.size());
    caster.wait(caster.submit(rays), hits);
    expect_same(hits, sync_cpu(caster, rays), "on the engine's jobs");
  }
  EXPECT_EQ(jobs.runs.load(), 1);
}

// An engine's job system whose run() throws (its queue full, say):
// submit() throws what it threw, as it threw it, and the frame stays free
// (more failed submissions than frames, then every frame taken).
TEST(Host, AnEnginesJobSystemThatThrowsFailsTheSubmission) {
  const Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3SOA4"), "sphere");
  CountingJobs jobs;
  CasterOptions o = options(Backend::Cpu, 2);
  o.jobs = &jobs;
  Caster caster(blob, "sphere", o);
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 1000, 8);
  jobs.fail = true;
  for (int k = 0; k < 3; ++k) EXPECT_THROW(caster.submit(rays), EngineFault);
  jobs.fail = false;
  const host::Ticket a = caster.submit(rays), b = caster.submit(rays);
  for (const host::Ticket& t : {a, b}) {
    std::vector<Hit> hits(rays.size());
    caster.wait(t, hits);
    expect_same(hits, sync_cpu(caster, rays), "after the job system threw");
  }
}

// The automatic backend measures the crossover once, writes it to the
// profile, and the next caster on the same device and blob reads it back.
TEST(Host, AutomaticChoiceMeasuresSavesAndLoadsTheCrossover) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  Mesh m = make_sphere(24, 48, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "sphere");
  const std::string profile = (std::filesystem::temp_directory_path() / "meshcast_host_test.profile").string();
  std::filesystem::remove(profile);
  CasterOptions o = automatic_on_a_device();
  o.profile = profile;
  uint32_t crossover;
  {
    Caster caster(blob, "sphere", o);
    ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
    // Construction did not wait for the measurement: until it is known,
    // every batch goes to the CPU and why() says so.
    const std::vector<Ray> rays = make_rays(m, RayKind::Long, 3000, 5);
    std::vector<Hit> hits(rays.size());
    for (int k = 0; k < 3 && !caster.crossover_known(); ++k) {
      const std::string why = caster.why(1u << 20);
      const host::BatchRecord r = caster.wait(caster.submit(rays), hits);
      if (why.find("measured in the background") != std::string::npos) {
        EXPECT_EQ(r.ran_on, Backend::Cpu) << why;
      }
    }
    caster.clear_records();
    caster.wait_for_crossover();
    EXPECT_TRUE(caster.crossover_known());
    crossover = caster.crossover();
    EXPECT_NE(caster.why(1).find("measured at start-up"), std::string::npos) << caster.why(1);
    for (uint32_t n : {1u, 64u, 4096u, 1u << 20})
      EXPECT_EQ(caster.choose(n), n >= crossover ? Backend::Vulkan : Backend::Cpu) << n;
    EXPECT_TRUE(caster.records().empty());  // the measurement's batches are not the game's
  }
  ASSERT_TRUE(std::filesystem::exists(profile));
  {
    Caster again(blob, "sphere", o);
    EXPECT_TRUE(again.crossover_known());  // loaded in the constructor
    EXPECT_EQ(again.crossover(), crossover);
    EXPECT_NE(again.why(1).find("loaded from"), std::string::npos) << again.why(1);
  }
  // The same profile with a crossover of -1 (which an unsigned read takes
  // for 4294967295, "never"): not used, and why() says so at once.
  std::ifstream in(profile);
  std::string magic, key;
  std::getline(in, magic), std::getline(in, key);
  in.close();
  std::ofstream(profile) << magic << "\n" << key << "\n-1\nedited by hand\n";
  Caster edited(blob, "sphere", o);  // destroyed at once: its measurement stops after one batch
  EXPECT_NE(edited.why(1).find("line 3 '-1' is not a batch size"), std::string::npos) << edited.why(1);
  std::filesystem::remove(profile);
}

// A profile file's hostile contents, as the Automatic backend reads them
// (host/profile.h): none is used, each says why naming the path, and each
// is written over only when it is a meshcast profile (damaged, of another
// version, device or blob), never when it is something else (notes, a
// binary, a folder); a pipe is refused before it is opened (its open
// would wait for a writer). A good one is read, "never" included.
TEST(Host, HostileProfilesAreNotUsedAndSayWhy) {
  const std::string key = "lavapipe | OctTreeCompressed/ClusterBitPackSOA8 | 96 triangles | 12345";
  const std::string head = "meshcast-profile 1\n" + key + "\n";
  auto read = [&](const std::string& name, const std::string& bytes) {
    return host::read_profile(make_file(name, bytes), key);
  };
  const host::SavedProfile good = read("good", head + "4096\nmeasured\n");
  ASSERT_TRUE(good.crossover.has_value()) << good.note;
  EXPECT_EQ(*good.crossover, 4096u);
  EXPECT_EQ(good.note, "measured");
  EXPECT_EQ(read("never", head + "4294967295\nmeasured\n").crossover, std::optional<uint32_t>(~0u));
  struct Case {
    std::string name, bytes, words;
    bool replaceable;
  };
  const Case cases[] = {
      {"negative", head + "-1\nnote\n", "line 3 '-1' is not a batch size (0 to 4294967295)", true},
      {"nan", head + "nan\nnote\n", "line 3 'nan' is not a batch size", true},
      {"huge", head + "99999999999999999999\nnote\n", "line 3 '99999999999999999999' is not", true},
      {"exponent", head + "1e9\nnote\n", "line 3 '1e9' is not", true},
      {"suffixed", head + "12abc\nnote\n", "line 3 '12abc' is not", true},
      {"blank", head + "\nnote\n", "line 3 '' is not", true},
      {"binary", head + std::string("\x01\xff\0", 3) + "\nnote\n", "line 3 '\\x01\\xFF\\x00' is not", true},
      {"truncated", head, "truncated or damaged (2 lines where a profile has 4)", true},
      {"cut", head + "4096\nmeas", "truncated (its last line has no end)", true},
      {"extra", head + "4096\nnote\nmore\n", "truncated or damaged (5 lines", true},
      {"another_device", "meshcast-profile 1\nanother GPU | x\n64\nnote\n", "another device or blob ('another GPU | x')", true},
      {"another_version", "meshcast-profile 2\n" + key + "\n64\nnote\n", "another version ('meshcast-profile 2')", true},
      {"long", head + "4096\n" + std::string(5000, 'x') + "\n", "longer than a profile (over 4096 bytes)", true},
      {"empty", "", "not a meshcast profile", false},
      {"notes", "my own notes\n4096\n", "not a meshcast profile", false},
      {"elf", std::string("\x7f" "ELF\x02\x01\x01\0\0\0", 10) + std::string(100000, '\0'), "not a meshcast profile", false},
  };
  for (const Case& c : cases) {
    const host::SavedProfile p = read(c.name, c.bytes);
    EXPECT_FALSE(p.crossover.has_value()) << c.name;
    EXPECT_NE(p.note.find((scratch_dir() / c.name).string() + ": "), std::string::npos) << c.name << ": " << p.note;
    EXPECT_NE(p.note.find(c.words), std::string::npos) << c.name << ": " << p.note;
    EXPECT_EQ(p.replaceable, c.replaceable) << c.name;
  }
  const std::string folder = (scratch_dir() / "profile_folder").string(), pipe = (scratch_dir() / "profile_pipe").string();
  std::filesystem::create_directory(folder);
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  for (auto [path, words] : {std::pair{folder, "is a directory"}, std::pair{pipe, "not a regular file"}}) {
    const host::SavedProfile p = host::read_profile(path, key);
    EXPECT_FALSE(p.crossover.has_value()) << path;
    EXPECT_NE(p.note.find(path + ": " + words), std::string::npos) << p.note;
    EXPECT_FALSE(p.replaceable) << path;
  }
  const host::SavedProfile absent = host::read_profile((scratch_dir() / "no_profile").string(), key);
  EXPECT_FALSE(absent.crossover.has_value());
  EXPECT_EQ(absent.note, "");
  EXPECT_TRUE(absent.replaceable);
  // What write_profile writes reads back; a folder that is not there is an OutputError naming the path.
  const std::string written = (scratch_dir() / "written").string();
  host::write_profile(written, key, 256, "at 256 rays");
  EXPECT_EQ(host::read_profile(written, key).crossover, std::optional<uint32_t>(256));
  const std::string nowhere = (scratch_dir() / "no folder" / "profile").string();
  expect_throws<OutputError>([&] { host::write_profile(nowhere, key, 256, "at 256 rays"); }, {nowhere});
}

// The Automatic backend on profiles it cannot use: a file of notes is
// measured over and left as it is, a profile in a folder that is not there
// is measured and not saved, a folder in the profile's place is not used;
// why() says each, from the start.
TEST(Host, AutomaticChoiceOnProfilesItCannotUse) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  const Mesh m = make_sphere(12, 24, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "sphere");
  CasterOptions o = automatic_on_a_device();
  o.profile = make_file("notes.txt", "my own notes\n");
  {
    Caster caster(blob, "sphere", o);
    ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
    EXPECT_NE(caster.why(1).find(o.profile + ": not a meshcast profile"), std::string::npos) << caster.why(1);
    caster.wait_for_crossover();
    EXPECT_NE(caster.why(1).find("measured at start-up"), std::string::npos) << caster.why(1);
    EXPECT_NE(caster.why(1).find("not saved: " + o.profile + " is left as it is"), std::string::npos) << caster.why(1);
  }
  std::ifstream notes(o.profile);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(notes), {}), "my own notes\n");
  o.profile = (scratch_dir() / "no folder" / "profile").string();
  {
    Caster caster(blob, "sphere", o);
    caster.wait_for_crossover();
    EXPECT_NE(caster.why(1).find("measured at start-up"), std::string::npos) << caster.why(1);
    EXPECT_NE(caster.why(1).find("not saved: " + o.profile + ": cannot write"), std::string::npos) << caster.why(1);
  }
  o.profile = scratch_dir().string();
  Caster folder(blob, "sphere", o);
  EXPECT_NE(folder.why(1).find(o.profile + ": is a directory"), std::string::npos) << folder.why(1);
}

}  // namespace
}  // namespace meshcast::testing

// Scene batches: the game moves, hides, shows, adds and removes
// instances and commits a frame while up to three batches are in flight;
// every batch, collected frames later, is the scene as it was when it was
// submitted (the same answers as walking that frame's snapshot), and the
// world did change under them. The job system here starts each batch's
// work only a while after it was handed over, so the batches really walk
// while later frames are committed (and their snapshots' arrays would be
// reused under them, were a held snapshot ever taken for a new frame).
namespace meshcast::testing {
namespace {
// `delay`: how long after run() its work starts, unless open() was called.
class LateJobs : public host::JobSystem {
 public:
  explicit LateJobs(std::chrono::milliseconds delay = std::chrono::milliseconds(3))
      : delay_(delay), thread_([this] { loop(); }) {}
  ~LateJobs() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  void run(uint32_t count, const std::function<void(uint32_t)>& work) override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back({count, &work, std::chrono::steady_clock::now() + delay_});
    }
    wake_.notify_all();
  }
  uint32_t threads() const override { return 1; }
  // Every run from now on starts at once.
  void open() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      open_ = true;
    }
    wake_.notify_all();
  }

 private:
  struct Run {
    uint32_t count;
    const std::function<void(uint32_t)>* work;
    std::chrono::steady_clock::time_point at;
  };
  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;
      const Run r = queue_.front();
      queue_.pop_front();
      wake_.wait_until(lock, r.at, [this] { return open_; });
      lock.unlock();
      for (uint32_t i = 0; i < r.count; ++i) (*r.work)(i);
      lock.lock();
    }
  }
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Run> queue_;
  bool stop_ = false, open_ = false;
  const std::chrono::milliseconds delay_;
  std::thread thread_;
};

// The frames of SceneBatchesSeeTheFrameTheySubmittedIn on `backend`, the
// sphere in `sphere_layout` (the terrain is in the recommended layout).
// Returns the batches each backend answered.
std::map<Backend, int> scene_frames(Backend backend, const char* sphere_layout) {
  std::map<Backend, int> answered;
  Scene scene;
  const MeshId sphere = scene.add_mesh(build_blob(make_sphere(8, 12, 1, {0, 0, 0}), parse_layout(sphere_layout), "sphere"), "sphere");
  const MeshId ground = scene.add_mesh(build_blob(make_terrain(6, 6, 3), parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "terrain"), "terrain");
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-30, 30);
  auto somewhere = [&] {
    Transform t;
    for (double& x : t.translation) x = 1e6 + std::round(u(rng));
    if (rng() % 3 == 0) t.rotation_scale[0] = -1;  // mirrored
    return t;
  };
  std::vector<InstanceId> live;
  for (int i = 0; i < 40; ++i) live.push_back(scene.add_instance(i % 2 ? sphere : ground, somewhere(), uint8_t(1u << (i % 3))));
  scene.commit();
  std::vector<RayD> rays(500);
  for (RayD& r : rays) {
    for (int a = 0; a < 3; ++a) r.org[a] = 1e6 + u(rng), r.dir[a] = float(1e6 + u(rng) - r.org[a]);
    r.tmax = INFINITY;
  }
  LateJobs late;
  CasterOptions o = options(backend, 3);
  o.jobs = &late;
  Caster caster(o);
  EXPECT_EQ(caster.gpu_error(), "");
  EXPECT_THROW(caster.submit(std::vector<Ray>(1)), UsageError);  // no blob
  // What each batch must answer, walked from its frame's snapshot when it
  // was submitted (the snapshot is not kept: only the caster holds it).
  struct InFlight {
    host::Ticket ticket;
    host::SceneBatchQuery query;
    std::vector<SceneHit> want;
    SceneHitLists want_rows;
  };
  std::deque<InFlight> flight;
  size_t changed = 0, gpu_rays = 0, ties = 0;
  auto collect = [&] {
    const InFlight f = std::move(flight.front());
    flight.pop_front();
    if (f.query.query == Query::All) {
      SceneHitLists got;
      const SceneHitLists& want = f.want_rows;
      ++answered[caster.wait(f.ticket, got).ran_on];
      ASSERT_EQ(got.found, want.found);
      for (size_t i = 0; i < want.hits.size(); ++i) {
        EXPECT_EQ(got.hits[i].instance, want.hits[i].instance) << "record " << i;
        EXPECT_EQ(got.hits[i].triangle, want.hits[i].triangle) << "record " << i;
      }
      return;
    }
    std::vector<SceneHit> got(rays.size()), now(rays.size());
    const std::vector<SceneHit>& want = f.want;
    const Backend ran_on = caster.wait(f.ticket, got).ran_on;
    ++answered[ran_on];
    scene.trace(rays, now, HitOutputs::None, f.query.query, f.query.cull, f.query.mask);
    for (size_t i = 0; i < rays.size(); ++i) {
      EXPECT_EQ(got[i].instance, want[i].instance) << "ray " << i;
      // The GPU may name the other of two triangles met at the same t
      // (gpu_scene_test): counted, and few; the CPU names the oracle's.
      if (ran_on == Backend::Cpu) {
        EXPECT_EQ(got[i].triangle, want[i].triangle) << "ray " << i;
      } else {
        ++gpu_rays;
        ties += got[i].triangle != want[i].triangle;
      }
      EXPECT_EQ(got[i].t, want[i].t) << "ray " << i;
      changed += got[i].instance != now[i].instance || got[i].t != now[i].t;
    }
  };
  for (int frame = 0; frame < 24; ++frame) {
    const host::SceneBatchQuery q = frame % 3 == 0   ? host::SceneBatchQuery{Query::All, Cull::None, 0xFF, 32}
                                    : frame % 3 == 1 ? host::SceneBatchQuery{Query::Closest, Cull::None, 0xFF}
                                                     : host::SceneBatchQuery{Query::Any, Cull::Back, 0x03};
    InFlight f{caster.submit(scene, rays, q), q, std::vector<SceneHit>(rays.size()), {}};
    if (q.query == Query::All) {
      f.want_rows.max_hits = q.max_hits;
      scene.trace_all_hits(rays, f.want_rows, HitOutputs::None, q.cull, q.mask);
    } else {
      scene.trace(rays, f.want, HitOutputs::None, q.query, q.cull, q.mask);
    }
    flight.push_back(std::move(f));
    if (flight.size() == 3) collect();
    // The next frame: moves, a hidden and a shown instance, one added, one
    // removed every 4th frame.
    for (int k = 0; k < 6; ++k) scene.set_transform(live[rng() % live.size()], somewhere());
    scene.set_enabled(live[rng() % live.size()], false);
    scene.set_enabled(live[rng() % live.size()], true);
    live.push_back(scene.add_instance(frame % 2 ? sphere : ground, somewhere()));
    if (frame % 4 == 3) {
      const size_t gone = rng() % live.size();
      scene.remove_instance(live[gone]);
      live.erase(live.begin() + std::ptrdiff_t(gone));
    }
    scene.commit();
  }
  while (!flight.empty()) collect();
  EXPECT_GT(changed, rays.size() / 10) << "the world hardly changed under the batches";
  EXPECT_LE(ties, gpu_rays / 100) << "GPU hits naming another triangle at the CPU's t";
  // A scene batch is collected as scene hits, and a wrong kind is refused.
  const host::Ticket t = caster.submit(scene, rays);
  std::vector<Hit> plain(rays.size());
  EXPECT_THROW(caster.wait(t, plain), UsageError);
  std::vector<SceneHit> hits(rays.size());
  caster.wait(t, hits);
  EXPECT_EQ(caster.validation_messages(), 0u);
  return answered;
}

TEST(Host, SceneBatchesSeeTheFrameTheySubmittedIn) {
  const std::map<Backend, int> answered = scene_frames(Backend::Cpu, "AABBTree/Float3");
  EXPECT_EQ(answered.at(Backend::Cpu), 24);
  EXPECT_EQ(answered.count(Backend::Vulkan), 0u);
}

// The same frames with Backend::Vulkan: the closest- and any-hit batches
// are the GPU's (16 of 24), Query::All's the CPU's; with a mesh in a layout
// the GPU scene method does not read, every batch is the CPU's, answered
// the same.
TEST(Host, SceneBatchesOnTheGpuSeeTheFrameTheySubmittedIn) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  const std::map<Backend, int> gpu = scene_frames(Backend::Vulkan, "OctTreeCompressed/ClusterBitPackSOA8");
  EXPECT_EQ(gpu.at(Backend::Vulkan), 16);
  EXPECT_EQ(gpu.at(Backend::Cpu), 8);
  const std::map<Backend, int> refused = scene_frames(Backend::Vulkan, "AABBTree/Float3");
  EXPECT_EQ(refused.at(Backend::Cpu), 24);
  EXPECT_EQ(refused.count(Backend::Vulkan), 0u);
}

// Scene::commit() writes the next frame into the older snapshot once
// nothing holds it, while other threads trace the scene (each trace holds
// the snapshot it walks until it returns) and a caster's batches hold
// theirs until collected. Every trace sees one committed frame whole, and
// under ThreadSanitizer (scripts/test.sh) the reuse is seen to come after
// the last reads of whoever let the snapshot go.
TEST(Host, CommitsWhileOtherThreadsTrace) {
  Scene scene;
  const MeshId ball = scene.add_mesh(
      build_blob(make_sphere(8, 12, 1, {0, 0, 0}), parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "ball"), "ball");
  // A row of balls, raised together by a unit each frame.
  constexpr int kBalls = 8, kFrames = 150, kRaysABall = 4;
  auto at = [](int i, int frame) {
    Transform t;
    t.translation[0] = 4.0 * i, t.translation[2] = frame;
    return t;
  };
  std::vector<InstanceId> balls;
  for (int i = 0; i < kBalls; ++i) balls.push_back(scene.add_instance(ball, at(i, 0)));
  scene.commit();
  // Rays straight down onto each ball's top, a few to a ball: a frame's
  // traces all meet their ball at the same height. Short traces, so that
  // many begin on one frame and end before the commit after next.
  std::vector<RayD> rays;
  for (int i = 0; i < kBalls; ++i)
    for (int k = 0; k < kRaysABall; ++k) rays.push_back({{4.0 * i, 0, 1000}, {0, 0, -1}, INFINITY});
  std::vector<SceneHit> first(rays.size());
  scene.trace(rays, first);
  ASSERT_EQ(first[0].instance, 0u);
  const float top = 1000 - first[0].t;  // the ball's top above its centre
  std::atomic<bool> done{false};
  std::atomic<int> traces{0}, torn{0};
  auto tracer = [&] {
    std::vector<SceneHit> hits(rays.size());
    while (!done.load()) {
      scene.trace(rays, hits);
      const float frame = 1000 - hits[0].t - top;
      bool whole = std::fabs(frame - std::round(frame)) < 1e-3f && frame > -0.5f && frame < kFrames + 0.5f;
      for (size_t r = 0; r < rays.size(); ++r)
        whole = whole && hits[r].instance == r / kRaysABall && hits[r].t == hits[0].t;
      torn += !whole;
      ++traces;
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < 3; ++k) threads.emplace_back(tracer);
  CasterOptions o = options(Backend::Cpu, 2);
  o.threads = 1;
  Caster caster(o);
  std::deque<std::pair<host::Ticket, int>> batches;  // and the frame each was submitted in
  std::vector<SceneHit> batch_hits(rays.size());
  int wrong_batches = 0;
  for (int frame = 1; frame <= kFrames; ++frame) {
    for (int i = 0; i < kBalls; ++i) scene.set_transform(balls[i], at(i, frame));
    scene.commit();
    // A pause for the traces of the frames before to end: the older
    // snapshot is then free, and the next commit writes into it.
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (frame % 3 == 0) {  // a batch held over the next frames' commits
      if (batches.size() == 2) {
        caster.wait(batches.front().first, batch_hits);
        wrong_batches += std::fabs(1000 - batch_hits[0].t - top - float(batches.front().second)) > 1e-3f;
        batches.pop_front();
      }
      batches.emplace_back(caster.submit(scene, rays), frame);
    }
  }
  done = true;
  for (std::thread& t : threads) t.join();
  for (const auto& [ticket, frame] : batches) {
    caster.wait(ticket, batch_hits);
    wrong_batches += std::fabs(1000 - batch_hits[0].t - top - float(frame)) > 1e-3f;
  }
  EXPECT_GT(traces.load(), 0);
  EXPECT_EQ(torn.load(), 0) << "of " << traces.load() << " traces";
  EXPECT_EQ(wrong_batches, 0);
}

// Scene batches over blobs the scene does not own: a mapped blob file
// shared with the scene, and the same file referenced through a BlobView.
// Each batch answers as the scene over a copy, on the CPU and on the GPU
// (uploaded from the mapping); the shared scene is dropped, and the
// caller's mapping with it, while its batch is in flight: the batch's
// snapshot keeps the mapping until it is collected.
TEST(Host, SceneBatchesReadMappedBlobs) {
  const std::vector<uint8_t> blob =
      build_blob(make_sphere(12, 16, 1, {0, 0, 0}), parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "ball");
  const std::string path = (scratch_dir() / "host_scene_ball.mcb").string();
  save_blob(path, blob);
  const MappedBlob referenced(path);
  auto place = [](Scene& scene, MeshId ball) {
    for (int i = 0; i < 8; ++i) {
      Transform t;
      t.translation[0] = 1e6 + 4.0 * i;
      if (i % 3 == 0) t.rotation_scale[4] = -1;  // mirrored
      scene.add_instance(ball, t, 0xFF, i % 4 == 1);
    }
    scene.commit();
  };
  Scene copied, viewed;
  place(copied, copied.add_mesh(blob, "ball"));
  place(viewed, viewed.add_mesh(BlobView(referenced.bytes(), path), path));
  std::vector<RayD> world(600);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> along(-2, 30), across(-1.2, 1.2);
  for (RayD& r : world) r = {{1e6 + along(rng), across(rng), 5}, {0, float(across(rng) * 0.1), -1}, INFINITY};
  for (const Backend b : {Backend::Cpu, Backend::Vulkan}) {
    if (b == Backend::Vulkan && cpu_only()) continue;
    for (const Cull cull : {Cull::None, Cull::Back}) {
      std::vector<SceneHit> want(world.size());
      copied.trace(world, want, HitOutputs::None, Query::Closest, cull);
      size_t hits = 0;
      for (const SceneHit& h : want) hits += h.instance != kNoHit;
      EXPECT_GT(hits, world.size() / 4);
      Caster caster(options(b));
      auto shared = std::make_unique<Scene>();
      {
        auto file = std::make_shared<const MappedBlob>(path);
        const MeshId mesh = shared->add_mesh(file, path);
        place(*shared, mesh);
        EXPECT_EQ(shared->mesh_blob(mesh).data(), file->bytes().data());
      }  // the caller lets go of its mapping: the scene holds it
      const host::Ticket from_shared = caster.submit(*shared, world, {Query::Closest, cull, 0xFF});
      shared.reset();  // the scene goes too: the batch's snapshot holds the mapping
      const host::Ticket from_view = caster.submit(viewed, world, {Query::Closest, cull, 0xFF});
      for (const host::Ticket& t : {from_shared, from_view}) {
        std::vector<SceneHit> got(world.size());
        EXPECT_EQ(caster.wait(t, got).ran_on, b);
        size_t differ = 0;
        for (size_t i = 0; i < world.size(); ++i) differ += std::memcmp(&got[i], &want[i], sizeof(SceneHit)) != 0;
        EXPECT_EQ(differ, 0u) << host::backend_name(b) << ", cull " << int(cull) << (t.id == from_shared.id ? ", shared" : ", viewed");
      }
      EXPECT_EQ(caster.validation_messages(), 0u);
    }
  }
}

// A blob's caster on the GPU takes scene batches beside its blob batches,
// frames of both kinds in flight at once (the blob's begun on this thread,
// the scenes' on the caster's GPU thread, one queue and command pool),
// with u and v; each answers as its own CPU walk. On Automatic, scene
// batches are the CPU's.
TEST(Host, BlobAndSceneBatchesShareTheGpu) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  const Mesh m = make_terrain(48, 32, 5);
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "terrain");
  Scene scene;
  const MeshId ground = scene.add_mesh(blob, "terrain");
  for (int i = 0; i < 6; ++i) {
    Transform t;
    t.translation[0] = 1e6 + 40.0 * i, t.translation[2] = -1e6;
    if (i % 2) t.rotation_scale[8] = -1;  // mirrored
    scene.add_instance(ground, t);
  }
  scene.commit();
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 1500, 3);
  std::vector<RayD> world(1500);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-20, 240), v(-20, 20);
  for (RayD& r : world) r = {{1e6 + u(rng), 30 + v(rng), -1e6 + v(rng)}, {float(v(rng) * 0.01), -1, float(v(rng) * 0.01)}, INFINITY};
  std::vector<SceneHit> want(world.size());
  scene.trace(world, want, HitOutputs::Uv);
  for (Backend b : {Backend::Vulkan, Backend::Automatic}) {
    CasterOptions o = b == Backend::Automatic ? automatic_on_a_device() : options(b);
    o.hit_outputs = HitOutputs::Uv;
    Caster caster(blob, "terrain", o);
    ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
    const Backend scene_on = b == Backend::Vulkan ? Backend::Vulkan : Backend::Cpu;
    for (int round = 0; round < 2; ++round) {
      const host::Ticket t0 = caster.submit(rays), s0 = caster.submit(scene, world), t1 = caster.submit(rays),
                         s1 = caster.submit(scene, world, {Query::Any, Cull::None, 0xFF});
      for (const host::Ticket& t : {t0, t1}) {
        std::vector<Hit> hits(rays.size());
        caster.wait(t, hits);
        expect_same(hits, sync_cpu(caster, rays), "blob batch beside scene batches");
      }
      std::vector<SceneHit> got(world.size()), any(world.size());
      EXPECT_EQ(caster.wait(s0, got).ran_on, scene_on);
      EXPECT_EQ(caster.wait(s1, any).ran_on, scene_on);
      size_t hit = 0, ties = 0;
      for (size_t i = 0; i < world.size(); ++i) {
        EXPECT_EQ(got[i].instance, want[i].instance) << "ray " << i;
        EXPECT_EQ(got[i].t, want[i].t) << "ray " << i;
        EXPECT_EQ(any[i].instance == kNoHit, want[i].instance == kNoHit) << "ray " << i;
        hit += want[i].instance != kNoHit;
        if (got[i].triangle != want[i].triangle) {
          ++ties;
          continue;
        }
        EXPECT_NEAR(got[i].u, want[i].u, 1e-5) << "ray " << i;
        EXPECT_NEAR(got[i].v, want[i].v, 1e-5) << "ray " << i;
      }
      EXPECT_GT(hit, world.size() / 5) << "rays that miss the scene prove little";
      EXPECT_LE(ties, world.size() / 100);
    }
    EXPECT_EQ(caster.validation_messages(), 0u);
  }
}

// Eight balls in a row, in the layout the GPU scene method reads, and 64
// rays across them with the scene's own answers; and the ball's blob, for
// blob batches beside the scene's.
struct BallRow {
  BallRow() {
    const MeshId id = scene.add_mesh(blob, "ball");
    for (int i = 0; i < 8; ++i) {
      Transform t;
      t.translation[0] = 3.0 * i;
      scene.add_instance(id, t);
    }
    scene.commit();
    for (size_t i = 0; i < rays.size(); ++i) rays[i] = {{0.37 * double(i), 0.2, -10}, {0, 0, 1}, INFINITY};
    scene.trace(rays, want);
  }
  // A batch's hits are the scene's own (the instance and t: the GPU may
  // name the other of two triangles met at one t).
  void expect_answered(const std::vector<SceneHit>& got, const std::string& what) const {
    for (size_t i = 0; i < rays.size(); ++i) {
      EXPECT_EQ(got[i].instance, want[i].instance) << what << ", ray " << i;
      EXPECT_EQ(got[i].t, want[i].t) << what << ", ray " << i;
    }
  }
  Mesh ball = make_sphere(8, 12, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(ball, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "ball");
  Scene scene;
  std::vector<RayD> rays = std::vector<RayD>(64);
  std::vector<SceneHit> want = std::vector<SceneHit>(64);
};

// A scene batch the GPU refuses (an injected limit) is the CPU's and the
// GPU stays; after a lost device every scene batch is the CPU's. Each
// answers as the scene's own walk.
TEST(Host, SceneBatchesLeaveARefusingOrLostGpuForTheCpu) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  const BallRow row;
  std::vector<SceneHit> got(row.rays.size());
  int submission = 0;
  CasterOptions o = options(Backend::Vulkan);
  o.before_gpu_submit = [&submission] {
    ++submission;
    if (submission == 2) throw GpuError("Vulkan: the scene's buffers exceed a limit (injected by the test)");
    if (submission > 3) throw GpuError("Vulkan: device lost (injected by the test)", true);
  };
  Caster caster(o);
  const Backend expected[] = {Backend::Vulkan, Backend::Cpu, Backend::Vulkan, Backend::Cpu, Backend::Cpu};
  ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
  for (Backend b : expected) {
    EXPECT_EQ(caster.wait(caster.submit(row.scene, row.rays), got).ran_on, b);
    row.expect_answered(got, host::backend_name(b));
  }
  EXPECT_FALSE(caster.gpu_available());
  EXPECT_NE(caster.gpu_error().find("device lost"), std::string::npos) << caster.gpu_error();
}

// The device lost at the second scene batch's submission, with blob and
// scene batches in flight behind it: the batches before it stay the GPU's;
// that one and every later one, scene or blob, are the CPU's, answered as
// the CPU answers them; gpu_available() turns false and gpu_error() says
// why. A caster of scene batches alone says its GPU is available (and its
// error empty) until then, as a blob's does.
TEST(Host, ADeviceLostAmidSceneBatchesLeavesTheRestToTheCpu) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  const BallRow row;
  const std::vector<Ray> rays = make_rays(row.ball, RayKind::Long, 300, 6);
  const std::thread::id game = std::this_thread::get_id();
  for (bool with_blob : {false, true}) {
    int scene_submissions = 0;  // the GPU thread's, which submits the scene batches
    CasterOptions o = options(Backend::Vulkan, 8);
    o.before_gpu_submit = [&] {
      if (std::this_thread::get_id() != game && ++scene_submissions == 2)
        throw GpuError("Vulkan: vkQueueSubmit failed (VK_ERROR_DEVICE_LOST, injected by the test)", true);
    };
    const std::unique_ptr<Caster> made = with_blob ? std::make_unique<Caster>(row.blob, "ball", o) : std::make_unique<Caster>(o);
    Caster& caster = *made;
    ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
    EXPECT_EQ(caster.gpu_error(), "");
    // In flight at once: blob batch 0, scene batch 0, blob 1, scene 1 (its
    // submission loses the device), blob 2, scene 2. Blob batch 1 was
    // begun before scene batch 1 was submitted; blob 2 may have been too,
    // and is answered after the loss.
    struct Batch {
      host::Ticket ticket;
      bool scene;
      Backend expected;
    };
    std::vector<Batch> batches;
    for (int k = 0; k < 3; ++k) {
      if (with_blob) batches.push_back({caster.submit(rays), false, k < 2 ? Backend::Vulkan : Backend::Cpu});
      batches.push_back({caster.submit(row.scene, row.rays), true, k < 1 ? Backend::Vulkan : Backend::Cpu});
    }
    for (const Batch& b : batches) {
      const std::string what = std::string(b.scene ? "scene" : "blob") + " batch " + std::to_string(b.ticket.id);
      if (b.scene) {
        std::vector<SceneHit> got(row.rays.size());
        EXPECT_EQ(caster.wait(b.ticket, got).ran_on, b.expected) << what;
        row.expect_answered(got, what);
      } else {
        std::vector<Hit> got(rays.size());
        EXPECT_EQ(caster.wait(b.ticket, got).ran_on, b.expected) << what;
        expect_same(got, sync_cpu(caster, rays), what);
      }
    }
    EXPECT_FALSE(caster.gpu_available());
    EXPECT_NE(caster.gpu_error().find("VK_ERROR_DEVICE_LOST"), std::string::npos) << caster.gpu_error();
    // Then one of each, the CPU's from their submission.
    std::vector<SceneHit> got(row.rays.size());
    EXPECT_EQ(caster.wait(caster.submit(row.scene, row.rays), got).ran_on, Backend::Cpu);
    row.expect_answered(got, "a scene batch after the loss");
    if (with_blob) {
      std::vector<Hit> hits(rays.size());
      EXPECT_EQ(caster.wait(caster.submit(rays), hits).ran_on, Backend::Cpu);
      expect_same(hits, sync_cpu(caster, rays), "a blob batch after the loss");
    }
    EXPECT_EQ(scene_submissions, 2);  // none after the loss
    EXPECT_EQ(caster.validation_messages(), 0u);
  }
}

// An engine's job system that throws on the caster's own threads, where
// no caller is there to take the exception: a scene batch the GPU refuses
// (an injected limit), moved to the CPU while run() throws, is collected by
// rethrowing what it threw, and the caster goes on; the Automatic
// backend's measurement stops and why() says so. Nothing terminates.
TEST(Host, AnEnginesJobSystemThatThrowsOnTheCastersThreads) {
  if (cpu_only()) GTEST_SKIP() << "Vulkan kept out of this run";
  const BallRow row;
  std::vector<SceneHit> got(row.rays.size());
  CountingJobs jobs;
  int submission = 0;
  CasterOptions o = options(Backend::Vulkan);
  o.jobs = &jobs;
  o.before_gpu_submit = [&submission] {
    if (++submission == 2) throw GpuError("Vulkan: the scene's buffers exceed a limit (injected by the test)");
  };
  {
    Caster caster(o);
    EXPECT_EQ(caster.wait(caster.submit(row.scene, row.rays), got).ran_on, Backend::Vulkan);
    jobs.fail = true;
    const host::Ticket refused = caster.submit(row.scene, row.rays);
    EXPECT_THROW(caster.wait(refused, got), EngineFault);
    EXPECT_THROW(caster.wait(refused, got), UsageError);  // collected
    jobs.fail = false;
    EXPECT_EQ(caster.wait(caster.submit(row.scene, row.rays), got).ran_on, Backend::Vulkan);
    row.expect_answered(got, "after the job system threw");
    EXPECT_TRUE(caster.gpu_available());
  }
  CasterOptions a = automatic_on_a_device();
  a.jobs = &jobs;
  jobs.fail = true;
  Caster automatic(row.blob, "ball", a);
  automatic.wait_for_crossover();
  EXPECT_EQ(automatic.choose(1u << 20), Backend::Cpu);
  EXPECT_NE(automatic.why(1u << 20).find("not measured: the job system threw"), std::string::npos) << automatic.why(1u << 20);
  jobs.fail = false;
}

// Whether thread `tid` of this process is asleep (blocked on a lock or a
// condition variable), as /proc/self/task says: how a test knows that
// another thread is inside a blocking call.
bool asleep(pid_t tid) {
  std::ifstream stat("/proc/self/task/" + std::to_string(tid) + "/stat");
  const std::string line((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const size_t name_end = line.rfind(')');  // "tid (name) state ...": the name may hold anything
  return name_end != std::string::npos && name_end + 2 < line.size() && line[name_end + 2] == 'S';
}

// A caster destroyed while another thread is blocked in wait(): that
// thread gets UsageError naming its ticket, and the destructor waits for
// the batch still running and for that thread to leave (nothing freed
// under it: this suite runs under ThreadSanitizer, and the CPU host layer
// under AddressSanitizer). The batch runs only once the waiter has thrown.
TEST(Host, DestroyingACasterWhileAThreadWaitsThrowsThere) {
  const Mesh m = make_sphere(8, 16, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 200, 4);
  LateJobs late(std::chrono::seconds(10));  // a bound, should the waiter never throw
  CasterOptions o = options(Backend::Cpu);
  o.jobs = &late;
  auto caster = std::make_unique<Caster>(blob, "sphere", o);
  Caster* const shared = caster.get();
  const host::Ticket t = caster->submit(rays);
  std::atomic<pid_t> tid{0};
  std::string error;
  bool returned = false;
  std::thread waiter([&, shared] {
    tid = pid_t(::syscall(SYS_gettid));
    std::vector<Hit> hits(rays.size());
    try {
      shared->wait(t, hits);
      returned = true;
    } catch (const UsageError& e) {
      error = e.what();
    }
    late.open();
  });
  // Blocked in wait(): asleep 50 ms on end (its batch cannot be ready yet).
  int asleep_for = 0;
  for (int k = 0; k < 2000 && asleep_for < 10; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    asleep_for = tid != 0 && asleep(tid) ? asleep_for + 1 : 0;
  }
  if (asleep_for < 10) {
    late.open();
    waiter.join();
    FAIL() << "the waiting thread never blocked";
  }
  caster.reset();
  waiter.join();
  EXPECT_FALSE(returned);
  EXPECT_NE(error.find("ticket " + std::to_string(t.id) + " was not collected: the caster was destroyed while waiting"),
            std::string::npos)
      << error;
}
}  // namespace
}  // namespace meshcast::testing
