#include "meshcast/blob.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <span>
#include <vector>

#if defined(__x86_64__)
#include <cpuid.h>
#endif

#include "cpu/scratch.h"
#include "cpu/walk.h"
#include "cpu/walk_top.h"
#include "layout/queries.h"
#include "cpu/walk_table.h"
#include "layout/blob_format.h"
#include "layout/codecs.h"
#include "layout/zerobyte.h"

namespace meshcast {

namespace {


struct IsaChoice {
  WalkerIsa isa;
  std::span<const WalkEntry> table;
};

// Whether this build has the set and the processor runs it.
bool cpu_has(WalkerIsa isa) {
#if defined(__x86_64__)
  __builtin_cpu_init();
  // F16C from CPUID (leaf 1, ECX): clang's __builtin_cpu_supports does not
  // know the name.
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  const bool f16c = __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & bit_F16C) != 0;
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && f16c;
  const bool avx512 = avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
#if MESHCAST_HAS_ISA_AVX2
  if (isa == WalkerIsa::Avx2) return avx2;
#endif
#if MESHCAST_HAS_ISA_AVX512
  if (isa == WalkerIsa::Avx512) return avx512;
#endif
  (void)avx2, (void)avx512;
#endif
#if MESHCAST_HAS_ISA_SCALAR
  return isa == WalkerIsa::Scalar;
#else
  return false;
#endif
}

std::span<const WalkEntry> table_of(WalkerIsa isa) {
#if MESHCAST_HAS_ISA_AVX512
  if (isa == WalkerIsa::Avx512) return isa_avx512::walk_table();
#endif
#if MESHCAST_HAS_ISA_AVX2
  if (isa == WalkerIsa::Avx2) return isa_avx2::walk_table();
#endif
  (void)isa;
#if MESHCAST_HAS_ISA_SCALAR
  return isa_scalar::walk_table();
#else
  return {};  // not reached: choose_isa picks a set this build has
#endif
}

// Chosen once, on first use: the widest set the processor has, or the one
// MESHCAST_ISA names (scalar, avx2, avx512) when the processor has it. A
// build without the scalar set (MESHCAST_ISAS, the test scripts' sanitizer
// builds) refuses a processor that runs none of its sets.
IsaChoice choose_isa() {
  std::optional<WalkerIsa> widest;
  for (WalkerIsa candidate : {WalkerIsa::Avx512, WalkerIsa::Avx2, WalkerIsa::Scalar})
    if (cpu_has(candidate)) {
      widest = candidate;
      break;
    }
  if (!widest) throw UsageError("meshcast was built without the scalar walkers, and this processor runs none of its sets");
  WalkerIsa isa = *widest;
  if (const char* asked = std::getenv("MESHCAST_ISA")) {
    for (WalkerIsa named : {WalkerIsa::Scalar, WalkerIsa::Avx2, WalkerIsa::Avx512})
      if (walker_isa_name(named) == asked) {
        if (!cpu_has(named))
          throw UsageError(std::string("MESHCAST_ISA=") + asked + ": this processor or build lacks it (it has " +
                           std::string(walker_isa_name(isa)) + ")");
        isa = named;
      }
    if (std::string(asked) != walker_isa_name(isa))
      throw UsageError(std::string("MESHCAST_ISA=") + asked + ": not one of scalar, avx2, avx512");
  }
  return {isa, table_of(isa)};
}

const IsaChoice& chosen() {
  static const IsaChoice choice = choose_isa();
  return choice;
}

}  // namespace

WalkTopFn walk_top_fn() {
  const WalkerIsa isa = chosen().isa;
#if MESHCAST_HAS_ISA_AVX512
  if (isa == WalkerIsa::Avx512) return &isa_avx512::walk_top;
#endif
#if MESHCAST_HAS_ISA_AVX2
  if (isa == WalkerIsa::Avx2) return &isa_avx2::walk_top;
#endif
  (void)isa;
#if MESHCAST_HAS_ISA_SCALAR
  return &isa_scalar::walk_top;
#else
  return nullptr;  // not reached: choose_isa picks a set this build has
#endif
}

std::string_view walker_isa_name(WalkerIsa isa) {
  switch (isa) {
    case WalkerIsa::Scalar: return "scalar";
    case WalkerIsa::Avx2: return "avx2";
    case WalkerIsa::Avx512: return "avx512";
  }
  return "";
}

WalkerIsa walker_isa() { return chosen().isa; }

bool ray_is_walkable(const Ray& r) {
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(r.org[a]) <= kMaxCoordinate) || !(std::fabs(r.dir[a]) <= kMaxDirection)) return false;
  const float m = std::max({std::fabs(r.dir[0]), std::fabs(r.dir[1]), std::fabs(r.dir[2])});
  if (!(m >= 0x1p-126f)) return false;
  // Comparisons false on NaN: a NaN tmax or tmin is refused with them.
  return r.tmax >= 0 && r.tmin >= 0 && r.tmin <= r.tmax;
}

void set_triangle_test(TriangleTest t) { triangle_test_choice.store(t, std::memory_order_relaxed); }

bool watertight_lane_double(const float ax, const float ay, const float bx, const float by, const float cx,
                            const float cy, const float az, const float bz, const float cz, const float sz,
                            float cull, float tmin, float closest, LaneHit* out) {
  double U = double(cx) * by - double(cy) * bx;
  double V = double(ax) * cy - double(ay) * cx;
  double W = double(bx) * ay - double(by) * ax;
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return false;
  double det = U + V + W;
  if (det == 0 || det * cull < 0) return false;  // cull: the face the query drops
  double T = (U * az + V * bz + W * cz) * double(sz);
  if (det < 0) T = -T, U = -U, V = -V, W = -W, det = -det;
  if (T < 0) return false;
  // Compared in double: a t past the largest float is no hit. Both ends
  // are floats, so the float t reported lies between them too.
  const double t = T / det;
  if (!(t >= double(tmin) && t <= double(std::min(closest, FLT_MAX)))) return false;
  out->t = float(t), out->u = float(V / det), out->v = float(W / det);
  return true;
}

WalkFn walker_for(uint32_t tree_format, uint32_t triangle_format) {
  for (const WalkEntry& e : chosen().table)
    if (e.tree == tree_format && e.triangles == triangle_format) return e.walk;
  return nullptr;
}

BlobView::BlobView(std::span<const uint8_t> bytes, const std::string& name) : bytes_(bytes) {
  std::string why = layout::validate(bytes);
  if (!why.empty()) throw InputError(name + ": " + why);
  const layout::BlobHeader& h = layout::header_of(bytes.data());
  walk_ = walker_for(h.tree_format, h.triangle_format);
  if (!walk_) throw InputError(name + ": no walker for this layout");
}

namespace {

// The walkers' flags word: only the outputs' own bits (the query's and the
// culling's share the word), checked names for the rest.
uint32_t flags_of(const char* who, HitOutputs outputs, Query query, Cull cull) {
  layout::check_query(who, query, cull);
  return (uint32_t(outputs) & (MC_HIT_UV | MC_HIT_POINT)) | layout::query_bits(query, cull);
}

}  // namespace

uint64_t BlobView::trace(std::span<const Ray> rays, std::span<Hit> hits, HitOutputs outputs, Query query,
                         Cull cull) const {
  if (hits.size() < rays.size())
    throw UsageError("BlobView::trace: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(hits.size()) + " hits; the hits span must hold one hit a ray");
  if (query == Query::All)
    throw UsageError("BlobView::trace: Query::All has a list of hits a ray: BlobView::trace_all_hits answers it");
  WalkRequest request{flags_of("BlobView::trace", outputs, query, cull)};
  uint64_t skipped = 0;
  walk_(bytes_.data(), rays.data(), hits.data(), rays.size(), &skipped, request);
  return skipped;
}

namespace {

// Query::All walks a few rays at a time into a thread's scratch rows
// (cpu/scratch.h), at most kScratchRecords records (448 KiB) whatever
// max_hits, and copies each ray's kept hits out: the answers' memory and
// time follow the hits found, not rays x max_hits.
constexpr size_t kScratchRecords = 16384;
constexpr size_t kMostRaysAWalk = 64;

}  // namespace

uint64_t BlobView::trace_all_hits(std::span<const Ray> rays, HitLists& lists, HitOutputs outputs, Cull cull) const {
  const uint32_t max_hits = lists.max_hits;
  if (max_hits < 1 || max_hits > kMaxHitsLimit)
    throw UsageError("BlobView::trace_all_hits: max_hits " + std::to_string(max_hits) + " is not in 1.." +
                     std::to_string(kMaxHitsLimit));
  const uint32_t flags = flags_of("BlobView::trace_all_hits", outputs, Query::All, cull);
  lists.clear();
  lists.found.reserve(rays.size());
  lists.offsets.reserve(rays.size() + 1);
  const size_t per_walk = std::clamp<size_t>(kScratchRecords / max_hits, 1, kMostRaysAWalk);
  const std::span<Hit> rows = thread_scratch<Hit>(per_walk * max_hits);
  uint32_t found[kMostRaysAWalk];
  const WalkRequest request{flags, max_hits, found, rows.data()};
  uint64_t skipped = 0;
  for (size_t begin = 0; begin < rays.size(); begin += per_walk) {
    const size_t n = std::min(per_walk, rays.size() - begin);
    walk_(bytes_.data(), rays.data() + begin, nullptr, n, &skipped, request);
    for (size_t i = 0; i < n; ++i)
      lists.add_row(found[i], rows.subspan(i * max_hits, std::min(found[i], max_hits)));
  }
  return skipped;
}

Layout BlobView::layout() const {
  const layout::BlobHeader& h = layout::header_of(bytes_.data());
  return {TreeFormat(h.tree_format), TriangleFormat(h.triangle_format)};
}

uint32_t BlobView::triangle_count() const { return layout::header_of(bytes_.data()).triangle_count; }

}  // namespace meshcast
