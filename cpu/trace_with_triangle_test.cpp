#include "cpu/trace_with_triangle_test.h"

#include <string>

#include "cpu/walk_table.h"
#include "layout/blob_format.h"
#include "layout/queries.h"

namespace meshcast {

uint64_t trace_with_triangle_test(const BlobView& view, TriangleTest test, std::span<const Ray> rays,
                                  std::span<Hit> hits) {
  if (test == TriangleTest::Watertight) return view.trace(rays, hits);
  if (hits.size() < rays.size())
    throw UsageError("trace_with_triangle_test: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(hits.size()) + " hits; the hits span must hold one hit a ray");
  const layout::BlobHeader& h = layout::header_of(view.bytes().data());
  // Every (tree, triangle format) pair the library walks has its plain-test
  // walker too (the same sources, compiled once more), so a view's layout
  // is always found.
  WalkFn walk = nullptr;
  for (const WalkEntry& e : walk_table_of<TriangleTest::MollerTrumbore>(walker_isa()))
    if (e.tree == h.tree_format && e.triangles == h.triangle_format) walk = e.walk;
  if (!walk)
    throw UsageError("trace_with_triangle_test: no Möller–Trumbore walker for tree format " +
                     std::to_string(h.tree_format) + ", triangle format " + std::to_string(h.triangle_format));
  const WalkRequest request{layout::query_bits(Query::Closest, Cull::None)};
  uint64_t skipped = 0;
  walk(view.bytes().data(), rays.data(), hits.data(), rays.size(), &skipped, request);
  return skipped;
}

}  // namespace meshcast
