// The instruction set the walkers run on, chosen once a process (cpu/isa.h),
// and its walkers: the dispatch table walker_for reads and the scene's
// top-level walk.
#include <cstdlib>
#include <optional>
#include <span>
#include <string>

#if defined(__x86_64__)
#include <cpuid.h>
#endif

#include "cpu/walk_table.h"
#include "cpu/walk_points.h"
#include "cpu/walk_top.h"
#include "meshcast/blob.h"

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
  return {isa, walk_table_of<TriangleTest::Watertight>(isa)};
}

const IsaChoice& chosen() {
  static const IsaChoice choice = choose_isa();
  return choice;
}

}  // namespace

// The chosen set's function `name`, of a set this build has.
#if MESHCAST_HAS_ISA_AVX512
#define MC_PICK_AVX512(name) if (isa == WalkerIsa::Avx512) return &isa_avx512::name;
#else
#define MC_PICK_AVX512(name)
#endif
#if MESHCAST_HAS_ISA_AVX2
#define MC_PICK_AVX2(name) if (isa == WalkerIsa::Avx2) return &isa_avx2::name;
#else
#define MC_PICK_AVX2(name)
#endif
#if MESHCAST_HAS_ISA_SCALAR
#define MC_PICK_SCALAR(name) return &isa_scalar::name;
#else
#define MC_PICK_SCALAR(name) return nullptr;  // not reached: choose_isa picks a set this build has
#endif
#define MC_PICK(name) \
  MC_PICK_AVX512(name) \
  MC_PICK_AVX2(name)   \
  (void)isa;           \
  MC_PICK_SCALAR(name)

WalkTopFn walk_top_fn() {
  const WalkerIsa isa = chosen().isa;
  MC_PICK(walk_top)
}
WalkPointsFn walk_points_fn() {
  const WalkerIsa isa = chosen().isa;
  MC_PICK(walk_points)
}
NearestOnTrianglesFn nearest_on_triangles_fn() { return nearest_on_triangles_of(chosen().isa); }
NearestOnTrianglesFn nearest_on_triangles_of(WalkerIsa isa) {
  if (!cpu_has(isa)) return nullptr;
  MC_PICK(nearest_on_triangles)
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

WalkFn walker_for(uint32_t tree_format, uint32_t triangle_format) {
  for (const WalkEntry& e : chosen().table)
    if (e.tree == tree_format && e.triangles == triangle_format) return e.walk;
  return nullptr;
}

}  // namespace meshcast
