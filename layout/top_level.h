// A scene's top level (issue 21): the records one Scene::commit() makes and
// every trace of that frame reads. The instances that are walked (enabled at
// the commit) in the tree's order, and a binary tree over their world boxes
// in double (worlds far from the origin keep their precision there too).
#pragma once
#include <cstdint>
#include <vector>

namespace meshcast::layout {

// An instance as the walk meets it.
struct PlacedInstance {
  uint32_t id;        // the caller's InstanceId
  uint32_t mesh;      // index into the snapshot's meshes
  uint32_t mask;      // 8 bits: a ray's mask must share one
  uint32_t mirrored;  // 1 when rotation_scale's determinant is negative: the world sees its faces turned
  float to_local[9];  // the inverse of rotation_scale, row-major, rounded to float
  double translation[3];
  double box_min[3], box_max[3];  // what the instance's triangles cover in the world, padded outward
};

// `count` > 0: a leaf over placed[first, first + count); 0: an inner node,
// its children this node + 1 and `right`.
struct TopNode {
  double min[3], max[3];
  uint32_t first, count, right, pad = 0;
};

// The top level: placed instances reordered into tree order, the nodes
// (root first; empty when no instance is placed). Leaves hold at most
// kTopLeafSize instances.
constexpr uint32_t kTopLeafSize = 1;
struct TopLevel {
  std::vector<PlacedInstance> placed;
  std::vector<TopNode> nodes;
};

}  // namespace meshcast::layout
