// SKDTree walker (seed 000 §5.5): the ray's [near, far] interval inside the
// root box is cut by each node's planes: a child is entered when its cut
// interval is not empty, the nearer first, the other pushed with its
// interval. Plane distances are single roundings of (plane - origin) * 1/d
// and are compared with the far end widened by kFarScale, as in the
// conservative box test (Ize 2013), so no region the ray touches is culled;
// a direction component of 0 gives an infinite distance (or NaN on the
// plane), which max_keep/min_keep ignore, as box_test does.
#include "layout/triangles/codecs.h"
#include "cpu/walk.h"
#include "layout/tree/skdtree.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Codec, TriangleTest kTest>
void walk(layout::tree::SKDTree, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    struct Entry { uint32_t at; float tnear, tfar; };
    Entry stack[MC_MAX_DEPTH + 2];
    int top = -1;
    float tn, tf;
    box_interval(r, h.bounds_min, h.bounds_max, &tn, &tf);
    uint32_t at = 0;
    auto open = [&](float lo, float hi) { return interval_open(lo, hi, c.t); };
    if (!open(tn, tf)) return;
    for (;;) {
      const uint32_t properties = layout::load<uint32_t>(tree + at);
      if (!layout::skd_is_leaf(properties)) {
        const uint32_t a = layout::skd_axis(properties);
        const float tl = (layout::skd_left_plane(tree + at) - r.org[a]) * r.inv[a];
        const float tr = (layout::skd_right_plane(tree + at) - r.org[a]) * r.inv[a];
        // Going up the axis the ray leaves the left region at tl and enters
        // the right one at tr; going down, it enters the left and leaves the right.
        Entry left{at + MC_SKD_INTERIOR_BYTES, tn, tf}, right{layout::skd_value(properties), tn, tf};
        if (r.near_is_max[a]) left.tnear = max_keep(tl, tn), right.tfar = min_keep(tr, tf);
        else left.tfar = min_keep(tl, tf), right.tnear = max_keep(tr, tn);
        bool lhit = open(left.tnear, left.tfar), rhit = open(right.tnear, right.tfar);
        if (lhit || rhit) {
          bool left_first = lhit && (!rhit || left.tnear < right.tnear);
          const Entry& next = left_first ? left : right;
          if (lhit && rhit) stack[++top] = left_first ? right : left;
          at = next.at, tn = next.tnear, tf = next.tfar;
          continue;
        }
      } else {
        uint32_t block = at + MC_SKD_LEAF_BYTES;
        test_leaf<Codec, kTest>(blob, r, h.tree_offset + block, layout::skd_value(properties), layout::slot_of(h, block, 0), c);
      }
      while (top >= 0 && !open(stack[top].tnear, stack[top].tfar)) --top;
      if (top < 0) break;
      const Entry& e = stack[top--];
      at = e.at, tn = e.tnear, tf = e.tfar;
    }
  });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::SKDTree, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

MC_ISA_END
}  // namespace meshcast
