// The leaf descent's entry: the catalog's switch to each family's from_root
// (in its layout/tree/<family>.cpp).
#include "layout/tree/leaves.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "layout/triangles/codecs.h"
#include "layout/tree/tree_walks.h"
#include "layout/tree/zerobyte.h"

namespace meshcast::layout {

void for_each_leaf_path(const uint8_t* blob, const LeafPathVisitor& visit) {
  const BlobHeader& h = header_of(blob);
  Descent d{blob, h, blob + h.tree_offset, visit, {}};
  with_tree_format(h.tree_format, 0, [&](auto tag) {
    from_root(d, tag);
    return 0;
  });
}

void for_each_leaf(const uint8_t* blob, const std::function<void(uint32_t, uint32_t)>& visit) {
  for_each_leaf_path(blob, [&](uint32_t block, uint32_t count, const std::vector<PathBox>&) { visit(block, count); });
}

void decode_triangle(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
  const BlobHeader& h = header_of(blob);
  if (h.triangle_format == MC_TRI_INDEXED24) return Indexed24::decode(blob, block, i, out);
#define MC_DECODE(Codec, name) \
  if (h.triangle_format == Codec::kFormat) return Codec::decode(blob, block, i, out);
  MC_FOR_EACH_TRIANGLE_CODEC(MC_DECODE)
#undef MC_DECODE
}

namespace {
// The leaf by Codec's own decode_leaf, where it has one and is the blob's.
template <class Codec>
bool decode_whole_leaf(const uint8_t* blob, uint32_t block, uint32_t count, float (*out)[3][3]) {
  if constexpr (requires { Codec::decode_leaf(blob, block, count, out); }) {
    if (header_of(blob).triangle_format != Codec::kFormat) return false;
    Codec::decode_leaf(blob, block, count, out);
    return true;
  }
  return false;
}
}  // namespace

void decode_leaf(const uint8_t* blob, uint32_t block, uint32_t count, float (*out)[3][3]) {
  // A codec with a decode of its own for the whole leaf (the clusters')
  // takes it; the rest triangle by triangle.
#define MC_DECODE_LEAF(Codec, name) \
  if (decode_whole_leaf<Codec>(blob, block, count, out)) return;
  MC_FOR_EACH_TRIANGLE_CODEC(MC_DECODE_LEAF)
#undef MC_DECODE_LEAF
  for (uint32_t i = 0; i < count; ++i) decode_triangle(blob, block, i, out[i]);
}

std::string check_tree_bounds(const uint8_t* blob) {
  const BlobHeader& h = header_of(blob);
  std::string problem;
  std::vector<float> floats;  // a leaf's corners, 9 floats a triangle
  for_each_leaf_path(blob, [&](uint32_t block, uint32_t count, const std::vector<PathBox>& path) {
    if (!problem.empty() || path.empty()) return;
    floats.resize(9 * size_t(count));
    float (*corners)[3][3] = reinterpret_cast<float (*)[3][3]>(floats.data());
    decode_leaf(blob, h.tree_offset + block, count, corners);
    // The leaf's corners' box against each box above it (comparisons that
    // fail on NaN too).
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c)
        for (int a = 0; a < 3; ++a) {
          const float v = corners[i][c][a];
          if (!(std::fabs(v) <= FLT_MAX)) {
            problem = "triangle block at tree offset " + std::to_string(block) + " decodes a corner that is not finite";
            return;
          }
          lo[a] = std::min(lo[a], v), hi[a] = std::max(hi[a], v);
        }
    for (size_t depth = 0; depth < path.size(); ++depth)
      for (int a = 0; a < 3; ++a)
        if (!(path[depth].min[a] <= lo[a] && hi[a] <= path[depth].max[a])) {
          problem = "triangle block at tree offset " + std::to_string(block) + " holds corners from " +
                    std::to_string(lo[a]) + " to " + std::to_string(hi[a]) + " on axis " + std::to_string(a) +
                    ", outside the box [" + std::to_string(path[depth].min[a]) + ", " +
                    std::to_string(path[depth].max[a]) + "] of the node above it at depth " + std::to_string(depth) +
                    ": the tree does not bound its triangles";
          return;
        }
  });
  return problem;
}

}  // namespace meshcast::layout
