#include "tools/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "meshcast/blob.h"
#include "layout/blob_format.h"
#include "tools/common.h"

namespace meshcast::tools {

Picture render(const std::vector<uint8_t>& blob, int width, int height, const std::vector<Ray>& markers,
               const std::vector<Hit>& marker_hits, const CastFn& cast) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  float c[3], e[3];
  for (int a = 0; a < 3; ++a) c[a] = 0.5f * (h.bounds_min[a] + h.bounds_max[a]), e[a] = h.bounds_max[a] - h.bounds_min[a];
  float radius = 0.5f * std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  const float fov = 30.0f * float(M_PI) / 180.0f;
  float dist = radius / std::sin(fov / 2);
  float eye[3] = {c[0], c[1], c[2] + dist};
  float focal = 0.5f * float(height) / std::tan(fov / 2);
  std::vector<Ray> rays(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      rays[size_t(y) * width + x] = {{eye[0], eye[1], eye[2]},
                                     {x + 0.5f - 0.5f * width, 0.5f * height - (y + 0.5f), -focal},
                                     INFINITY};
  BlobView view(blob, "render");
  std::vector<Hit> hits(rays.size());
  auto t0 = std::chrono::steady_clock::now();
  if (cast) cast(rays, hits);
  else view.trace(rays, hits);
  Picture p{width, height, std::vector<uint8_t>(rays.size() * 3, 0), ms_since(t0) * 1e6 / double(rays.size())};
  // Depth along the view axis, near = bright.
  float near = INFINITY, far = 0;
  for (const Hit& hit : hits)
    if (hit.triangle != MC_NO_HIT) near = std::min(near, hit.t), far = std::max(far, hit.t);
  for (size_t i = 0; i < hits.size(); ++i) {
    uint8_t* px = &p.rgb[i * 3];
    if (hits[i].triangle == MC_NO_HIT) {
      px[0] = 24, px[1] = 28, px[2] = 40;
      continue;
    }
    float d = far > near ? (hits[i].t - near) / (far - near) : 0.0f;
    uint8_t g = uint8_t(std::clamp(235.0f - 190.0f * d, 0.0f, 255.0f));
    px[0] = px[1] = px[2] = g;
  }
  // Hit points of the marker rays, projected into the picture.
  for (size_t i = 0; i < markers.size() && i < marker_hits.size(); ++i) {
    if (marker_hits[i].triangle == MC_NO_HIT) continue;
    const Ray& r = markers[i];
    float q[3];
    for (int a = 0; a < 3; ++a) q[a] = r.org[a] + marker_hits[i].t * r.dir[a] - eye[a];
    if (!(q[2] < -1e-6f * radius)) continue;
    float fx = std::floor(0.5f * width + focal * q[0] / -q[2]), fy = std::floor(0.5f * height - focal * q[1] / -q[2]);
    if (!(fx >= 0 && fy >= 0 && fx < float(width) && fy < float(height))) continue;
    int x = int(fx), y = int(fy);
    // Only hits the camera sees: not behind the surface of their pixel.
    if (x < 0 || y < 0 || x >= width || y >= height) continue;
    const Hit& seen = hits[size_t(y) * width + x];
    const Ray& pixel = rays[size_t(y) * width + x];
    float len = std::sqrt(pixel.dir[0] * pixel.dir[0] + pixel.dir[1] * pixel.dir[1] + pixel.dir[2] * pixel.dir[2]);
    if (seen.triangle == MC_NO_HIT ||
        std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) > seen.t * len + 0.01f * radius)
      continue;
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        int xx = x + dx, yy = y + dy;
        if (xx < 0 || yy < 0 || xx >= width || yy >= height) continue;
        uint8_t* px = &p.rgb[(size_t(yy) * width + xx) * 3];
        px[0] = 40, px[1] = 200, px[2] = 60;
      }
  }
  return p;
}

}  // namespace meshcast::tools
