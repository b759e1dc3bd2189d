// Embree's builder (rtcBuildBVH, Debian's Embree 3) as a source of the
// binary tree a blob is laid out over (builder/tree_source.h): the same
// triangle boxes meshcast's splitter sees, Embree's binned SAH over them,
// a node of at most meshcast's leaf size a leaf, as meshcast's splitter
// makes it; the blob's writer then collapses it to wide nodes as it does
// its own tree.
#include <embree3/rtcore.h>
#include <embree3/rtcore_builder.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "bench/peer.h"
#include "builder/build_topdown.h"

namespace meshcast::bench {

namespace {

// Embree's tree while it is built, in its allocator's memory: a binary
// node (children and their boxes) or a leaf (its triangles).
struct EmbreeNode {
  bool leaf = false;
  uint32_t count = 0;           // a leaf's triangles, in `ids`
  EmbreeNode* child[2] = {nullptr, nullptr};
  Box3 box[2];
  uint32_t ids[1];              // a leaf's first triangle; the rest follow it
};

// maxBranchingFactor 2: every node has two children.
void* create_node(RTCThreadLocalAllocator alloc, unsigned int, void*) {
  return new (rtcThreadLocalAlloc(alloc, sizeof(EmbreeNode), 16)) EmbreeNode{};
}

void set_children(void* node, void** children, unsigned int count, void*) {
  for (unsigned int i = 0; i < count; ++i) static_cast<EmbreeNode*>(node)->child[i] = static_cast<EmbreeNode*>(children[i]);
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
  for (unsigned int i = 0; i < count; ++i)
    static_cast<EmbreeNode*>(node)->box[i] = Box3{{bounds[i]->lower_x, bounds[i]->lower_y, bounds[i]->lower_z},
                                                  {bounds[i]->upper_x, bounds[i]->upper_y, bounds[i]->upper_z}};
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  const size_t bytes = sizeof(EmbreeNode) + sizeof(uint32_t) * (count > 0 ? count - 1 : 0);
  auto* leaf = new (rtcThreadLocalAlloc(alloc, bytes, 16)) EmbreeNode{};
  leaf->leaf = true;
  leaf->count = uint32_t(count);
  for (size_t i = 0; i < count; ++i) leaf->ids[i] = prims[i].primID;
  return leaf;
}

// Embree's tree as a BuildTree: nodes in depth-first order from the root,
// each leaf's triangles a range of `order`.
uint32_t copy_node(const EmbreeNode* n, const Box3& box, uint32_t depth, BuildTree& t) {
  const uint32_t at = uint32_t(t.nodes.size());
  t.nodes.emplace_back();
  t.nodes[at].box = box;
  t.depth = std::max(t.depth, depth);
  if (n->leaf) {
    t.nodes[at].first = uint32_t(t.order.size());
    t.nodes[at].count = n->count;
    t.order.insert(t.order.end(), n->ids, n->ids + n->count);
    return at;
  }
  const uint32_t left = copy_node(n->child[0], n->box[0], depth + 1, t);
  const uint32_t right = copy_node(n->child[1], n->box[1], depth + 1, t);
  t.nodes[at].left = left, t.nodes[at].right = right;
  return at;
}

}  // namespace

TreeSource embree_tree_source() {
  return [](const std::vector<Box3>& boxes, uint32_t leaf_size, uint32_t depth_limit, uint32_t leaf_capacity) {
    // One build thread: the same tree every run, as meshcast's build.
    std::unique_ptr<RTCDeviceTy, void (*)(RTCDevice)> device(rtcNewDevice("threads=1"), rtcReleaseDevice);
    std::unique_ptr<RTCBVHTy, void (*)(RTCBVH)> bvh(rtcNewBVH(device.get()), rtcReleaseBVH);
    std::vector<RTCBuildPrimitive> prims(boxes.size());
    Box3 root;
    for (size_t i = 0; i < boxes.size(); ++i) {
      const Box3& b = boxes[i];
      prims[i] = {b.min.x, b.min.y, b.min.z, 0u, b.max.x, b.max.y, b.max.z, uint32_t(i)};
      root.grow(b);
    }
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;  // its binned SAH; HIGH adds spatial splits (a triangle in two leaves)
    args.maxBranchingFactor = 2;
    args.maxDepth = std::min<uint32_t>(depth_limit, 1024);
    // Leaves as meshcast's splitter makes them: a node of at most leaf_size
    // triangles is a leaf (at unit costs Embree's SAH would split down to
    // one or two triangles a leaf, and the layout's clusters would be as
    // small: 40 bytes a triangle on ChineseDragon-10kv against 13.6).
    args.sahBlockSize = 1;
    args.minLeafSize = std::min(leaf_size, leaf_capacity);
    args.maxLeafSize = std::min(leaf_size, leaf_capacity);
    args.traversalCost = 1.0f;
    args.intersectionCost = 1.0f;
    args.bvh = bvh.get();
    args.primitives = prims.data();
    args.primitiveCount = prims.size();
    args.primitiveArrayCapacity = prims.size();
    args.createNode = create_node;
    args.setNodeChildren = set_children;
    args.setNodeBounds = set_bounds;
    args.createLeaf = create_leaf;
    const auto* top = static_cast<const EmbreeNode*>(rtcBuildBVH(&args));
    if (!top) throw std::runtime_error("Embree's builder failed (error " + std::to_string(int(rtcGetDeviceError(device.get()))) + ")");
    BuildTree t;
    t.order.reserve(boxes.size());
    copy_node(top, root, 0, t);
    t.sah_cost = sah_cost(t);
    return t;
  };
}

}  // namespace meshcast::bench
