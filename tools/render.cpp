#include "tools/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "meshcast/blob.h"
#include "layout/blob_format.h"
#include "scene/snapshot.h"
#include "meshcast/errors.h"
#include "tools/common.h"

namespace meshcast::tools {

namespace {

// A camera in front of a box (centre c, double), looking down -z with y up
// from far enough back to see its bounding sphere in a 30 degree vertical
// field of view; one primary ray a pixel.
struct Camera {
  double eye[3];
  float focal, radius;
  int width, height;
  Camera(const double c[3], double box_radius, int w, int h) : radius(float(box_radius)), width(w), height(h) {
    const double fov = 30.0 * M_PI / 180.0;
    eye[0] = c[0], eye[1] = c[1], eye[2] = c[2] + box_radius / std::sin(fov / 2);
    focal = float(0.5 * h / std::tan(fov / 2));
  }
  void direction(int x, int y, float d[3]) const {
    d[0] = x + 0.5f - 0.5f * float(width), d[1] = 0.5f * float(height) - (float(y) + 0.5f), d[2] = -focal;
  }
};

// Depth shading: nearer is brighter, a miss the background.
std::vector<uint8_t> shade_depth(const std::vector<float>& t) {
  std::vector<uint8_t> rgb(t.size() * 3);
  float near = INFINITY, far = 0;
  for (float d : t)
    if (d != INFINITY) near = std::min(near, d), far = std::max(far, d);
  for (size_t i = 0; i < t.size(); ++i) {
    uint8_t* px = &rgb[i * 3];
    if (t[i] == INFINITY) {
      px[0] = 24, px[1] = 28, px[2] = 40;
      continue;
    }
    float d = far > near ? (t[i] - near) / (far - near) : 0.0f;
    uint8_t g = uint8_t(std::clamp(235.0f - 190.0f * d, 0.0f, 255.0f));
    px[0] = px[1] = px[2] = g;
  }
  return rgb;
}

}  // namespace

Picture render_scene(const Scene& scene, int width, int height) {
  const std::shared_ptr<const SceneSnapshot> s = scene.snapshot();
  if (s->top.wide.empty()) throw InputError("render: the scene places no enabled instance");
  const layout::TopLevel& top = s->top;
  double c[3], r2 = 0;
  for (int a = 0; a < 3; ++a) c[a] = 0.5 * (top.min[a] + top.max[a]), r2 += 0.25 * (top.max[a] - top.min[a]) * (top.max[a] - top.min[a]);
  const Camera cam(c, std::sqrt(r2), width, height);
  std::vector<RayD> rays(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      RayD& r = rays[size_t(y) * width + x];
      for (int a = 0; a < 3; ++a) r.org[a] = cam.eye[a];
      cam.direction(x, y, r.dir);
      r.tmax = INFINITY;
    }
  std::vector<SceneHit> hits(rays.size());
  auto t0 = std::chrono::steady_clock::now();
  scene.trace(rays, hits);
  const double ns = ms_since(t0) * 1e6 / double(rays.size());
  std::vector<float> t(hits.size());
  for (size_t i = 0; i < hits.size(); ++i) t[i] = hits[i].t;
  return {width, height, shade_depth(t), ns};
}

Picture render(const std::vector<uint8_t>& blob, int width, int height, const std::vector<Ray>& markers,
               const std::vector<Hit>& marker_hits, const CastFn& cast) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  double c[3], r2 = 0;
  for (int a = 0; a < 3; ++a) {
    c[a] = 0.5 * (double(h.bounds_min[a]) + h.bounds_max[a]);
    r2 += 0.25 * (double(h.bounds_max[a]) - h.bounds_min[a]) * (double(h.bounds_max[a]) - h.bounds_min[a]);
  }
  const Camera cam(c, std::sqrt(r2), width, height);
  const float eye[3] = {float(cam.eye[0]), float(cam.eye[1]), float(cam.eye[2])}, focal = cam.focal, radius = cam.radius;
  std::vector<Ray> rays(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Ray& r = rays[size_t(y) * width + x];
      for (int a = 0; a < 3; ++a) r.org[a] = eye[a];
      cam.direction(x, y, r.dir);
      r.tmax = INFINITY;
    }
  BlobView view(blob, "render");
  std::vector<Hit> hits(rays.size());
  auto t0 = std::chrono::steady_clock::now();
  if (cast) cast(rays, hits);
  else view.trace(rays, hits);
  const double ns = ms_since(t0) * 1e6 / double(rays.size());
  std::vector<float> depth(hits.size());
  for (size_t i = 0; i < hits.size(); ++i) depth[i] = hits[i].triangle == MC_NO_HIT ? INFINITY : hits[i].t;
  Picture p{width, height, shade_depth(depth), ns};
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
