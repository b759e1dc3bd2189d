// SKDTree (seed 000 §5.5): per node a split axis and two planes, LeftPlane
// (the left child's max along the axis) and RightPlane (the right child's
// min); formats.h gives the bits. A node bounds the region of its parent
// cut by its plane, starting from the blob header's box, so the planes are
// the children's exact float bounds and nothing is rounded.
#pragma once
#include <algorithm>
#include <cstdint>

#include "layout/blob_format.h"

namespace meshcast::layout {

inline uint32_t skd_axis(uint32_t properties) { return properties >> MC_SKD_AXIS_SHIFT; }
inline uint32_t skd_value(uint32_t properties) { return properties & MC_SKD_VALUE_MASK; }
inline bool skd_is_leaf(uint32_t properties) { return skd_axis(properties) == MC_SKD_LEAF_AXIS; }
inline float skd_left_plane(const uint8_t* node) { return load<float>(node + MC_SKD_LEFT_PLANE_AT); }
inline float skd_right_plane(const uint8_t* node) { return load<float>(node + MC_SKD_RIGHT_PLANE_AT); }

// The regions of the two children of an interior node with region
// [min, max] (readers that want boxes: validation tests, statistics).
inline void skd_child_regions(const uint8_t* node, const float min[3], const float max[3], float lmin[3],
                              float lmax[3], float rmin[3], float rmax[3]) {
  uint32_t a = skd_axis(load<uint32_t>(node + MC_SKD_PROPERTIES_AT));
  for (int k = 0; k < 3; ++k) lmin[k] = rmin[k] = min[k], lmax[k] = rmax[k] = max[k];
  lmax[a] = std::min(max[a], skd_left_plane(node));
  rmin[a] = std::max(min[a], skd_right_plane(node));
}

}  // namespace meshcast::layout
