// A depth-shaded picture of a blob, cast one primary ray a pixel, like the
// figure of seed 000 §2 (hit points of a ray set marked in green).
#pragma once
#include <string>
#include <vector>

#include "cpu/ray.h"

namespace meshcast::tools {

struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  double ns_per_ray = 0;
};

// Camera in front of the blob's box (looking down -z, y up, as the public
// meshes are modelled), perspective, 30 degree vertical field of view.
Picture render(const std::vector<uint8_t>& blob, int width, int height, const std::vector<Ray>& markers,
               const std::vector<Hit>& marker_hits);

}  // namespace meshcast::tools
