// A depth-shaded picture of a blob, cast one primary ray a pixel, like the
// figure of seed 000 §2 (hit points of a ray set marked in green).
#pragma once
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "cpu/intersect.h"
#include "meshcast/scene.h"

namespace meshcast::tools {

struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  double ns_per_ray = 0;
};

// Casts a batch: the CPU walker by default, or a GPU method.
using CastFn = std::function<void(std::span<const Ray>, std::span<Hit>)>;

// Camera in front of the blob's box (looking down -z, y up, as the public
// meshes are modelled), perspective, 30 degree vertical field of view.
// `cast` null: the CPU walker on `blob`.
Picture render(const std::vector<uint8_t>& blob, int width, int height, const std::vector<Ray>& markers,
               const std::vector<Hit>& marker_hits, const CastFn& cast = nullptr);

// The same camera and shading over a scene: framed on the committed
// instances' world box, the camera's rays in double (a scene far from the
// origin keeps its detail).
Picture render_scene(const Scene& scene, int width, int height);

}  // namespace meshcast::tools
