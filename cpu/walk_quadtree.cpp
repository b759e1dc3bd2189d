// QuadTree and QuadTreeHalfFloat walker (seed 000 §5.6-5.7): four child boxes
// tested at once, the children that are hit pushed farthest first so the
// nearest is walked next, and popped entries skipped once the closest hit is
// nearer than their entry distance. The two formats differ only in how a
// node's bounds are loaded (Bounds::load below).
#include "layout/triangles/codecs.h"
#include "cpu/walk.h"
#include "layout/tree/quadtree.h"

namespace meshcast {
MC_ISA_BEGIN

namespace {

// Near and far planes of the 4 children for each axis. The node stores
// MinX, MinY, MinZ, MaxX, MaxY, MaxZ rows of 4; the ray's direction signs
// pick the row per axis, so no per-lane blend is needed.
template <class Bounds>
struct NodeLoad;

template <>
struct NodeLoad<layout::QuadBoundsFloat> {
  static void load(const uint8_t* node, const layout::BlobHeader&, const RayPre& r, simd::F4 nearp[3],
                   simd::F4 farp[3]) {
    for (int a = 0; a < 3; ++a) {
      nearp[a] = simd::F4::load(node + (a + 3 * r.near_is_max[a]) * 16);
      farp[a] = simd::F4::load(node + (a + 3 * (1 - r.near_is_max[a])) * 16);
    }
  }
};

template <>
struct NodeLoad<layout::QuadBoundsHalf> {
  static void load(const uint8_t* node, const layout::BlobHeader& h, const RayPre& r, simd::F4 nearp[3],
                   simd::F4 farp[3]) {
    const simd::F4 scale = simd::F4::splat(h.node_scale);
    for (int a = 0; a < 3; ++a) {
      const simd::F4 origin = simd::F4::splat(h.node_origin[a]);
      nearp[a] = simd::fma(simd::from_half(node + (a + 3 * r.near_is_max[a]) * 8), scale, origin);
      farp[a] = simd::fma(simd::from_half(node + (a + 3 * (1 - r.near_is_max[a])) * 8), scale, origin);
    }
  }
};

// 3 entries a level at most stay behind on the stack (4 pushed, 1 popped).
constexpr int kStackSize = 3 * MC_MAX_DEPTH + 8;

}  // namespace

template <class Bounds, class Codec, TriangleTest kTest>
void walk_quadtree(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    uint32_t node_stack[kStackSize];
    float fraction_stack[kStackSize];
    node_stack[0] = h.root;
    fraction_stack[0] = 0.0f;
    int top = 0;
    do {
      uint32_t properties = node_stack[top];
      uint32_t count = layout::quad_count(properties), offset = layout::quad_offset(properties);
      if (count == 0) {
        const uint8_t* node = tree + offset;
        simd::F4 nearp[3], farp[3];
        NodeLoad<Bounds>::load(node, h, r, nearp, farp);
        simd::F4 fraction = box_test4(r, nearp, farp, c.t);
        simd::I4 props = simd::I4::load(node + Bounds::kPropertiesAt);
        int hit = simd::bits((fraction != simd::F4::splat(INFINITY)) & simd::nonzero(props));
        float f[4];
        uint32_t p[4];
        fraction.store(f);
        props.store(p);
        // Compact the children that were hit and sort them farthest first
        // (at most 4: an insertion sort is a sorting network here).
        float sf[4];
        uint32_t sp[4];
        int m = 0;
        for (int k = 0; k < 4; ++k) {
          if (!(hit >> k & 1)) continue;
          int j = m++;
          while (j > 0 && sf[j - 1] < f[k]) sf[j] = sf[j - 1], sp[j] = sp[j - 1], --j;
          sf[j] = f[k], sp[j] = p[k];
        }
        for (int k = 0; k < m; ++k) fraction_stack[top + k] = sf[k], node_stack[top + k] = sp[k];
        top += m;
      } else {
        test_leaf<Codec, kTest>(blob, r, h.tree_offset + offset, count, layout::slot_of(h, offset, 0), c);
      }
      do --top;
      while (top >= 0 && fraction_stack[top] > c.t * kFarScale);
    } while (top >= 0);
  });
}

template <class Codec, TriangleTest kTest>
void walk(layout::tree::QuadTree, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  walk_quadtree<layout::QuadBoundsFloat, Codec, kTest>(blob, rays, hits, n, skipped, request);
}

template <class Codec, TriangleTest kTest>
void walk(layout::tree::QuadTreeHalfFloat, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  walk_quadtree<layout::QuadBoundsHalf, Codec, kTest>(blob, rays, hits, n, skipped, request);
}

#define MC_INSTANTIATE(Codec, name)                                                                              \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::QuadTree, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);                                                 \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::QuadTreeHalfFloat, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

MC_ISA_END
}  // namespace meshcast
