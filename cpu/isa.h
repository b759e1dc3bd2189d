// The instruction set a translation unit's walkers are compiled for, read
// from the compiler's own target macros, and the namespace that keeps each
// set's code apart. The walkers (cpu/walk_*.cpp, cpu/walk_table.cpp) are
// compiled once a set (CMakeLists.txt: scalar, AVX2, AVX-512) into one
// library (and once more, for the benchmark alone, with the plain triangle
// test: cpu/which_triangle_test.h); everything of cpu/ that a set compiles
// differently lives in `meshcast::isa_<set>` (an inline namespace: the code
// names it as plain meshcast), so no two sets share a symbol and the linker
// never hands one set's instructions to another. cpu/isa_choice.cpp picks a
// set at run time.
#pragma once

#if defined(MESHCAST_ISA_SCALAR) || defined(MESHCAST_SCALAR) || !defined(__AVX2__) || !defined(__FMA__) || \
    !defined(__F16C__)
#define MC_ISA_SIMD 0
#define MC_ISA_NS isa_scalar
#define MC_ISA_ID 0
#elif defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512BW__) && defined(__AVX512DQ__)
#define MC_ISA_SIMD 1
#define MC_ISA_NS isa_avx512
#define MC_ISA_ID 2
#else
#define MC_ISA_SIMD 1
#define MC_ISA_NS isa_avx2
#define MC_ISA_ID 1
#endif

#define MC_ISA_BEGIN inline namespace MC_ISA_NS {
#define MC_ISA_END }
