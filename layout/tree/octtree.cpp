// OctTreeCompressed's frame coding, validation and leaf descent over the
// nodes of layout/tree/octtree.h.
#include "layout/tree/octtree.h"

#include <algorithm>
#include <cfloat>

#include "layout/triangles/codecs.h"
#include "layout/tree/tree_walks.h"
#include "meshcast/errors.h"

namespace meshcast::layout {

namespace {

// Every multiple of 2^e of magnitude up to |x| is a float when the float
// spacing at |x| is no coarser than 2^e (and |x| is finite).
bool on_float_grid(double x, int e) {
  x = std::fabs(x);
  if (x == 0) return true;
  if (!(x <= FLT_MAX)) return false;
  return std::max(std::ilogb(x) - 23, -149) <= e;
}

}  // namespace

OctFrame oct_frame(float lo, float hi) {
  const double extent = double(hi) - double(lo);
  int e = extent > 0 ? std::ilogb(extent / 255.0) : -126;
  e = std::max(e, -126);  // a normal scale: its exponent byte is 1 or more
  for (;; ++e) {
    if (e > 127)
      throw InputError("an OctTreeCompressed node spans " + std::to_string(lo) + ".." + std::to_string(hi) +
                       ", beyond 255 steps of 2^127");
    const double step = std::ldexp(1.0, e);
    const double origin = std::floor(double(lo) / step) * step, top = origin + 255.0 * step;
    if (top >= double(hi) && on_float_grid(origin, e) && on_float_grid(top, e))
      return {float(origin), uint8_t(e + 127)};
  }
}

uint8_t oct_code(float v, const OctFrame& f, bool up) {
  const double q = (double(v) - double(f.origin)) / double(oct_scale(f.exponent));
  uint32_t c = uint32_t(std::clamp(up ? std::ceil(q) : std::floor(q), 0.0, 255.0));
  // v - origin may round in double when v is far smaller than the step
  // (a tiny v beside a distant origin): the decode, exact, has the last word.
  const float scale = oct_scale(f.exponent);
  if (up)
    while (c < 255 && oct_decode(c, f.origin, scale) < v) ++c;
  else
    while (c > 0 && oct_decode(c, f.origin, scale) > v) --c;
  return uint8_t(c);
}

namespace {

void descend_octtree(Descent& d, uint32_t properties) {
  const uint8_t* node = d.tree + oct_offset(properties);
  for (int k = 0; k < int(MC_OCT_WIDTH); ++k) {
    const uint32_t c = oct_child_properties(node, k);
    if (!c) continue;
    PathBox b;
    oct_child_box(node, k, b.min, b.max);
    if (oct_count(c)) {
      d.leaf(oct_offset(c), oct_count(c), &b);
      continue;
    }
    d.path.push_back(b);
    descend_octtree(d, c);
    d.path.pop_back();
  }
}

}  // namespace

// Nodes lie in the node area, each after its parent (so no walk loops), with
// finite origins and normal scales within the header's reach; every leaf
// passes check_leaf.
std::string validate_tree(tree::OctTreeCompressed, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  // The header's node reach (what the walker pads its planes by): finite
  // and not negative, and below each node checks against it.
  for (int a = 0; a < 3; ++a)
    if (!(h.node_origin[a] >= 0 && h.node_origin[a] <= FLT_MAX))
      return "OctTreeCompressed node reach node_origin[" + num(uint32_t(a)) + "] must be finite and not negative";
  if (!(h.node_scale >= 0 && h.node_scale <= FLT_MAX))
    return "OctTreeCompressed node reach node_scale must be finite and not negative";
  struct Item { uint32_t properties, parent, depth; };
  std::vector<Item> stack{{h.root, 0, 0}};
  uint64_t visited = 0;
  bool root = true;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const uint32_t count = oct_count(it.properties), offset = oct_offset(it.properties);
    if (count != 0) {
      std::string e = check_leaf(codec, blob, h, offset, count, MC_OCT_MAX_COUNT);
      if (!e.empty()) return e;
      *triangles += count;
      continue;
    }
    const std::string name = "node at tree offset " + num(offset);
    if (!root && offset <= it.parent) return name + " does not lie after its parent at " + num(it.parent);
    root = false;
    if (std::string e = reach(&visited, it.depth, h, name); !e.empty()) return e;
    const uint64_t node_area = h.triangle_base > 0 ? h.triangle_base : h.tree_size;
    if (uint64_t(offset) + MC_OCT_NODE_BYTES > node_area)
      return name + " lies outside the node area (" + num(node_area) + " bytes)";
    const uint8_t* node = blob + h.tree_offset + offset;
    for (int a = 0; a < 3; ++a) {
      const uint8_t e = node[MC_OCT_EXPONENTS_AT + a];
      const float origin = load<float>(node + MC_OCT_ORIGIN_AT + 4 * a);
      if (e == 0 || e == 255 || !std::isfinite(origin))
        return name + " has a frame that is not a finite origin and a normal power of two (axis " + num(uint32_t(a)) + ")";
      if (!(std::fabs(origin) <= h.node_origin[a]) || !(oct_scale(e) <= h.node_scale))
        return name + "'s frame (axis " + num(uint32_t(a)) + ") lies beyond the header's node reach (node_origin, node_scale)";
    }
    for (int k = 0; k < int(MC_OCT_WIDTH); ++k)
      if (const uint32_t p = oct_child_properties(node, k)) stack.push_back({p, offset, it.depth + 1});
  }
  return "";
}

void from_root(Descent& d, tree::OctTreeCompressed) {
  if (oct_count(d.h.root)) return d.leaf(oct_offset(d.h.root), oct_count(d.h.root), nullptr);
  descend_octtree(d, d.h.root);
}

}  // namespace meshcast::layout
