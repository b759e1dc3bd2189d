// A scene's top level: the records one Scene::commit() makes and
// every trace of that frame reads: the instances that are walked (enabled at
// the commit) in the tree's order, and 8-wide nodes over their world boxes
// (scene/build_top_level.h builds them from boxes in double: worlds far from the
// origin keep their precision there too).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "layout/formats.h"

namespace meshcast::layout {

// An instance as the walk meets it (80 bytes: what the walk reads and no
// more; its world box lives with the scene's edits, builds and refits read
// it there).
struct PlacedInstance {
  uint32_t id;           // the caller's InstanceId's index
  uint32_t mesh;         // index into the snapshot's meshes
  uint32_t mask;         // 8 bits: a ray's mask must share one
  uint32_t flip_facing;  // 1 when the caller turned its faces (Scene::add_instance): its front is the mesh's back
  float to_local[9];     // the inverse of rotation_scale, row-major, rounded to float
  double translation[3];
};

// What a walk reads: 8-wide nodes, each slot a child's box in float,
// relative to the top level's anchor (double) and rounded outward, and what
// the slot holds: a node's index, kTopInstance | an index into `placed`, or
// kTopEmpty (its box empty: lo +inf, hi -inf, never entered). Float boxes
// near the anchor keep a level 10 km across to half a millimetre at 10^7
// from the origin: the anchor carries the distance. A node's children
// follow it in the array (refits go from the last node to the first).
constexpr uint32_t kTopInstance = 0x80000000u, kTopEmpty = 0xFFFFFFFFu;
constexpr int kTopWidth = 8;
struct TopWideNode {
  float lo[3][kTopWidth], hi[3][kTopWidth];  // [axis][slot]
  uint32_t slot[kTopWidth];                   // 8 words side by side: the walkers' order_hits reads them
};

// The top level: the placed instances in the tree's order, the 8-wide nodes
// (root first; none when nothing is placed), their anchor (the root box's
// centre, at every build and refit) and the root box, in double.
struct TopLevel {
  std::vector<PlacedInstance> placed;
  std::vector<TopWideNode> wide;
  double anchor[3] = {0, 0, 0};
  double min[3] = {0, 0, 0}, max[3] = {0, 0, 0};
};

// The records as layout/formats.h describes them to the shaders.
static_assert(sizeof(PlacedInstance) == MC_PLACED_BYTES && offsetof(PlacedInstance, mesh) == MC_PLACED_MESH_AT &&
              offsetof(PlacedInstance, mask) == MC_PLACED_MASK_AT && offsetof(PlacedInstance, flip_facing) == MC_PLACED_FLIP_FACING_AT &&
              offsetof(PlacedInstance, to_local) == MC_PLACED_TO_LOCAL_AT &&
              offsetof(PlacedInstance, translation) == MC_PLACED_TRANSLATION_AT);
static_assert(sizeof(TopWideNode) == MC_TOP_NODE_BYTES && offsetof(TopWideNode, hi) == MC_TOP_HI_AT &&
              offsetof(TopWideNode, slot) == MC_TOP_SLOT_AT && kTopWidth == int(MC_TOP_WIDTH) &&
              kTopInstance == MC_TOP_INSTANCE && kTopEmpty == MC_TOP_EMPTY);

}  // namespace meshcast::layout
