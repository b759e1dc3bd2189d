// AABBTreeCompressed's readings: validation and the leaf descent over the
// nodes of layout/tree/compressed.h.
#include "layout/tree/tree_walks.h"

#include "layout/triangles/codecs.h"
#include "layout/tree/compressed.h"

namespace meshcast::layout {

namespace {

void descend_compressed(Descent& d, uint32_t at, const CompressedBox& box) {
  CompressedNode n = load<CompressedNode>(d.tree + at);
  CompressedBox child[2];
  n.unpack(box, child[0], child[1]);
  const uint32_t offset[2] = {at + MC_COMPRESSED_NODE_BYTES, n.right}, count[2] = {n.left_count(), n.right_count()};
  d.path.push_back(box_of(box.min, box.max));
  for (int k = 0; k < 2; ++k) {
    PathBox b = box_of(child[k].min, child[k].max);
    if (count[k]) d.leaf(offset[k], count[k], &b);
    else descend_compressed(d, offset[k], child[k]);
  }
  d.path.pop_back();
}

}  // namespace

// AABBTreeCompressed: the section header, then nodes and blocks, each
// right child after its node, each left child right behind it.
std::string validate_tree(tree::AABBTreeCompressed, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  if (h.tree_size < MC_COMPRESSED_HEADER_BYTES) return "AABBTreeCompressed: the tree section is shorter than its header";
  const uint8_t* tree = blob + h.tree_offset;
  CompressedBox root = compressed_root_box(tree);
  for (int a = 0; a < 3; ++a)
    if (!(root.min[a] <= root.max[a]) || !std::isfinite(root.min[a]) || !std::isfinite(root.max[a]))
      return "AABBTreeCompressed: the root box is empty or not finite";
  if (uint32_t count = compressed_root_count(tree)) {
    std::string e = check_leaf(codec, blob, h, MC_COMPRESSED_HEADER_BYTES, count);
    *triangles += count;
    return e;
  }
  return walk_nodes(h, MC_COMPRESSED_HEADER_BYTES, "node at tree offset ", [&](uint32_t at, auto push) -> std::string {
    if (at % 4 != 0 || uint64_t(at) + MC_COMPRESSED_NODE_BYTES > h.tree_size)
      return "node at tree offset " + num(at) + " is misaligned or past the tree section";
    CompressedNode n = load<CompressedNode>(tree + at);
    uint32_t left = at + MC_COMPRESSED_NODE_BYTES;
    if (n.right <= left)
      return "node at tree offset " + num(at) + " has its right child at " + num(n.right) + ", not after its left";
    const uint32_t child[2] = {left, n.right}, count[2] = {n.left_count(), n.right_count()};
    for (int k = 0; k < 2; ++k) {
      if (count[k] == 0) {
        push(child[k]);
        continue;
      }
      if (std::string e = check_leaf(codec, blob, h, child[k], count[k]); !e.empty()) return e;
      *triangles += count[k];
    }
    return "";
  });
}

void from_root(Descent& d, tree::AABBTreeCompressed) {
  const CompressedBox root = compressed_root_box(d.tree);
  if (uint32_t count = compressed_root_count(d.tree)) {
    PathBox b = box_of(root.min, root.max);
    return d.leaf(MC_COMPRESSED_HEADER_BYTES, count, &b);
  }
  descend_compressed(d, MC_COMPRESSED_HEADER_BYTES, root);
}

}  // namespace meshcast::layout
