// The quad trees' readings (QuadTree, QuadTreeHalfFloat): validation and
// the leaf descent over the nodes of layout/tree/quadtree.h.
#include "layout/tree/tree_walks.h"

#include "layout/triangles/codecs.h"
#include "layout/tree/quadtree.h"

namespace meshcast::layout {

namespace {

// QuadTree and QuadTreeHalfFloat: the same walk over their own child bounds.
template <class Bounds>
std::string validate_quad_nodes(const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  struct Item { uint32_t properties, parent, depth; };
  std::vector<Item> stack{{h.root, 0, 0}};
  uint64_t visited = 0;
  bool root = true;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    uint32_t count = quad_count(it.properties), offset = quad_offset(it.properties);
    if (count != 0) {
      std::string e = check_leaf(codec, blob, h, offset, count);
      if (!e.empty()) return e;
      *triangles += count;
      continue;
    }
    if (!root && offset <= it.parent)
      return "node at tree offset " + num(offset) + " does not lie after its parent at " + num(it.parent);
    root = false;
    if (std::string e = reach(&visited, it.depth, h, "node at tree offset " + num(offset)); !e.empty()) return e;
    // Nodes lie before the triangle area, or anywhere in the section when
    // blocks sit among them (the §4.3 orders without "triangles last").
    const uint64_t node_area = h.triangle_base > 0 ? h.triangle_base : h.tree_size;
    if (offset % 4 != 0 || uint64_t(offset) + Bounds::kNodeBytes > node_area)
      return "node at tree offset " + num(offset) + " is misaligned or outside the node area (" + num(node_area) +
             " bytes)";
    const uint8_t* node = blob + h.tree_offset + offset;
    for (int k = 0; k < 4; ++k) {
      uint32_t p = quad_child_properties(node, Bounds::kPropertiesAt, k);
      if (p == 0) continue;  // unused child: the walker never follows it
      stack.push_back({p, offset, it.depth + 1});
    }
  }
  return "";
}

template <class Bounds>
void descend_quadtree(Descent& d, uint32_t properties) {
  const uint8_t* node = d.tree + quad_offset(properties);
  for (int k = 0; k < 4; ++k) {
    uint32_t c = quad_child_properties(node, Bounds::kPropertiesAt, k);
    if (!c) continue;
    PathBox b;
    Bounds::decode(node, d.h, k, b.min, b.max);
    if (quad_count(c)) {
      d.leaf(quad_offset(c), quad_count(c), &b);
      continue;
    }
    d.path.push_back(b);
    descend_quadtree<Bounds>(d, c);
    d.path.pop_back();
  }
}

template <class Bounds>
void descend_quad_root(Descent& d) {
  if (quad_count(d.h.root)) return d.leaf(quad_offset(d.h.root), quad_count(d.h.root), nullptr);
  descend_quadtree<Bounds>(d, d.h.root);
}

}  // namespace

std::string validate_tree(tree::QuadTree, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  return validate_quad_nodes<QuadBoundsFloat>(codec, blob, h, triangles);
}

std::string validate_tree(tree::QuadTreeHalfFloat, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  return validate_quad_nodes<QuadBoundsHalf>(codec, blob, h, triangles);
}

void from_root(Descent& d, tree::QuadTree) { descend_quad_root<QuadBoundsFloat>(d); }
void from_root(Descent& d, tree::QuadTreeHalfFloat) { descend_quad_root<QuadBoundsHalf>(d); }

}  // namespace meshcast::layout
