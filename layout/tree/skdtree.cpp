// SKDTree's readings: validation and the leaf descent over the nodes of
// layout/tree/skdtree.h.
#include "layout/tree/tree_walks.h"

#include "layout/triangles/codecs.h"
#include "layout/tree/skdtree.h"

namespace meshcast::layout {

namespace {

void descend_skd(Descent& d, uint32_t at, const PathBox& region) {
  uint32_t p = load<uint32_t>(d.tree + at);
  if (skd_is_leaf(p)) return d.leaf(at + MC_SKD_LEAF_BYTES, skd_value(p), &region);
  PathBox l, r;
  skd_child_regions(d.tree + at, region.min, region.max, l.min, l.max, r.min, r.max);
  d.path.push_back(region);
  descend_skd(d, at + MC_SKD_INTERIOR_BYTES, l);
  descend_skd(d, skd_value(p), r);
  d.path.pop_back();
}

}  // namespace

// SKDTree: interior nodes and leaves of two sizes, each right child after
// its node.
std::string validate_tree(tree::SKDTree, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  const uint8_t* tree = blob + h.tree_offset;
  for (int a = 0; a < 3; ++a)
    if (!(h.bounds_min[a] <= h.bounds_max[a]) || !std::isfinite(h.bounds_min[a]) || !std::isfinite(h.bounds_max[a]))
      return "SKDTree: the root box in the header is empty or not finite";
  return walk_nodes(h, 0, "node at tree offset ", [&](uint32_t at, auto push) -> std::string {
    if (at % 4 != 0 || uint64_t(at) + MC_SKD_LEAF_BYTES > h.tree_size)
      return "node at tree offset " + num(at) + " is misaligned or past the tree section";
    uint32_t p = load<uint32_t>(tree + at);
    if (skd_is_leaf(p)) {
      *triangles += skd_value(p);
      return check_leaf(codec, blob, h, at + MC_SKD_LEAF_BYTES, skd_value(p));
    }
    uint32_t left = at + MC_SKD_INTERIOR_BYTES;
    if (uint64_t(left) > h.tree_size || skd_value(p) <= left)
      return "node at tree offset " + num(at) + " has its right child at " + num(skd_value(p)) + ", not after its left";
    if (!std::isfinite(skd_left_plane(tree + at)) || !std::isfinite(skd_right_plane(tree + at)))
      return "node at tree offset " + num(at) + " has a plane that is not finite";
    push(left), push(skd_value(p));
    return "";
  });
}

void from_root(Descent& d, tree::SKDTree) { descend_skd(d, 0, box_of(d.h.bounds_min, d.h.bounds_max)); }

}  // namespace meshcast::layout
