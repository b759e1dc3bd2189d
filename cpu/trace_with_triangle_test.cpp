#include "cpu/trace_with_triangle_test.h"

#include <string>

#include "cpu/walk_table.h"
#include "layout/blob_format.h"
#include "layout/names.h"
#include "layout/queries.h"

namespace meshcast {

uint64_t trace_with_triangle_test(const BlobView& view, TriangleTest test, std::span<const Ray> rays,
                                  std::span<Hit> hits) {
  if (test == TriangleTest::Watertight) return view.trace(rays, hits);
  if (hits.size() < rays.size())
    throw UsageError("trace_with_triangle_test: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(hits.size()) + " hits; the hits span must hold one hit a ray");
  const layout::BlobHeader& h = layout::header_of(view.bytes().data());
  // The plain-test walkers exist for the AABBTree and QuadTree families
  // alone (cpu/walk_table.cpp), the trees the benchmark compares.
  // On the instruction set the watertight walkers run, so the two tests
  // are compared like for like; a build may have them for fewer sets
  // (MESHCAST_TRIANGLE_TEST_ISAS).
  const WalkerIsa isa = walker_isa();
  bool built = false;
#if MESHCAST_HAS_ISA_SCALAR
  built |= isa == WalkerIsa::Scalar;
#endif
#if MESHCAST_HAS_ISA_AVX2
  built |= isa == WalkerIsa::Avx2;
#endif
#if MESHCAST_HAS_ISA_AVX512
  built |= isa == WalkerIsa::Avx512;
#endif
  if (!built)
    throw UsageError("trace_with_triangle_test: this build has the Möller–Trumbore walkers for other instruction "
                     "sets (MESHCAST_TRIANGLE_TEST_ISAS) than the one the walkers run here, " +
                     std::string(walker_isa_name(isa)));
  WalkFn walk = nullptr;
  for (const WalkEntry& e : walk_table_of<TriangleTest::MollerTrumbore>(isa))
    if (e.tree == h.tree_format && e.triangles == h.triangle_format) walk = e.walk;
  if (!walk)
    throw UsageError("trace_with_triangle_test: the Möller–Trumbore walkers are built for the AABBTree and "
                     "QuadTree trees alone, not for " + layout_name(h.tree_format, h.triangle_format));
  const WalkRequest request{layout::query_bits(Query::Closest, Cull::None)};
  uint64_t skipped = 0;
  walk(view.bytes().data(), rays.data(), hits.data(), rays.size(), &skipped, request);
  return skipped;
}

}  // namespace meshcast
