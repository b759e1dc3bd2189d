#include "meshcast/blob.h"

#include <algorithm>
#include <cfloat>
#include <vector>

#include "cpu/pairs.h"
#include "cpu/walk.h"
#include "layout/blob_format.h"
#include "layout/quadtree.h"

namespace meshcast {

namespace {

struct Entry {
  uint32_t tree, triangles;
  WalkFn walk;
};

template <class Codec>
constexpr WalkFn walker_for(uint32_t tree) {
  switch (tree) {
    case MC_TREE_AABBTREE: return &walk_aabbtree<Codec>;
    case MC_TREE_QUADTREE: return &walk_quadtree<layout::QuadBoundsFloat, Codec>;
    case MC_TREE_QUADTREEHALFFLOAT: return &walk_quadtree<layout::QuadBoundsHalf, Codec>;
    case MC_TREE_BRUTEFORCE: return &walk_bruteforce<Codec>;
    case MC_TREE_AABBTREESPLITAXIS: return &walk_aabbtree_splitaxis<Codec>;
    case MC_TREE_AABBTREEPNS: return &walk_aabbtree_pns<Codec>;
    case MC_TREE_AABBTREECOMPRESSED: return &walk_aabbtree_compressed<Codec>;
    case MC_TREE_SKDTREE: return &walk_skdtree<Codec>;
    case MC_TREE_STACKLESSLBVH: return &walk_lbvh<Codec>;
    case MC_TREE_AABBLIST: return &walk_aabblist<Codec>;
  }
  return nullptr;
}

// Every (tree, triangle format) pair of the two lists.
std::vector<Entry> make_walkers() {
  std::vector<Entry> entries;
#define MC_TREE_ENTRY(Tree, tree_id) trees.push_back(tree_id);
#define MC_CODEC_ENTRIES(Codec, name) \
  for (uint32_t t : trees) entries.push_back({t, layout::Codec::kFormat, walker_for<layout::Codec>(t)});
  std::vector<uint32_t> trees;
  MC_FOR_EACH_TREE(MC_TREE_ENTRY)
  MC_FOR_EACH_TRIANGLE_CODEC(MC_CODEC_ENTRIES)
#undef MC_TREE_ENTRY
#undef MC_CODEC_ENTRIES
  entries.push_back({MC_TREE_ZEROBYTE, MC_TRI_INDEXED24, &walk_zerobyte});
  entries.push_back({MC_TREE_ZEROBYTEHYBRID, MC_TRI_INDEXED24, &walk_zerobyte});
  return entries;
}

// Made on first use, not at static initialisation: a BlobView made by
// another translation unit's static initialiser finds it ready.
const std::vector<Entry>& walkers() {
  static const std::vector<Entry> table = make_walkers();
  return table;
}

}  // namespace

bool watertight_lane_double(const float ax, const float ay, const float bx, const float by, const float cx,
                            const float cy, const float az, const float bz, const float cz, const float sz,
                            float closest, LaneHit* out) {
  double U = double(cx) * by - double(cy) * bx;
  double V = double(ax) * cy - double(ay) * cx;
  double W = double(bx) * ay - double(by) * ax;
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return false;
  double det = U + V + W;
  if (det == 0) return false;
  double T = (U * az + V * bz + W * cz) * double(sz);
  if (det < 0) T = -T, U = -U, V = -V, W = -W, det = -det;
  if (T < 0) return false;
  // Compared in double: a t past the largest float is no hit.
  const double t = T / det;
  if (!(t <= double(std::min(closest, FLT_MAX)))) return false;
  out->t = float(t), out->u = float(V / det), out->v = float(W / det);
  return true;
}

BlobView::BlobView(std::span<const uint8_t> bytes, const std::string& name) : bytes_(bytes) {
  std::string why = layout::validate(bytes);
  if (!why.empty()) throw InputError(name + ": " + why);
  const layout::BlobHeader& h = layout::header_of(bytes.data());
  for (const Entry& e : walkers())
    if (e.tree == h.tree_format && e.triangles == h.triangle_format) walk_ = e.walk;
  if (!walk_) throw InputError(name + ": no walker for this layout");
}

uint64_t BlobView::trace(std::span<const Ray> rays, std::span<Hit> hits, HitOutputs outputs) const {
  if (hits.size() < rays.size())
    throw UsageError("BlobView::trace: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(hits.size()) + " hits; the hits span must hold one hit a ray");
  uint64_t skipped = 0;
  walk_(bytes_.data(), rays.data(), hits.data(), rays.size(), &skipped, uint32_t(outputs));
  return skipped;
}

Layout BlobView::layout() const {
  const layout::BlobHeader& h = layout::header_of(bytes_.data());
  return {TreeFormat(h.tree_format), TriangleFormat(h.triangle_format)};
}

uint32_t BlobView::triangle_count() const { return layout::header_of(bytes_.data()).triangle_count; }

}  // namespace meshcast
