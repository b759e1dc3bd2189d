#include "python/src/points.h"

#include <array>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

#include "cpu/point_order.h"
#include "python/src/arrays.h"
#include "python/src/parallel.h"

namespace meshcast::python {

double PointArrays::coordinate(size_t i, int k) const {
  return read_real(static_cast<const uint8_t*>(data.data()) + (3 * i + size_t(k)) * (is_double ? 8 : 4), is_double);
}

PointArrays points_from_array(const py::handle& input, const char* what) {
  PointArrays p;
  p.data = real_array(input, what);
  const py::array& a = p.data;
  if (a.ndim() < 1 || a.shape(a.ndim() - 1) != 3)
    throw py::value_error(std::string(what) + ": shape " + shape_text(a) + " is not (..., 3): each point is x, y, z");
  p.shape.assign(a.shape(), a.shape() + a.ndim() - 1);
  p.count = size_t(a.size() / 3);
  p.is_double = a.itemsize() == 8;
  for (size_t i = 0; i < p.count; ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(p.coordinate(i, k)))
        throw py::value_error(std::string(what) + "[" + std::to_string(i) + "]: coordinate " + std::to_string(k) +
                              " is " + std::to_string(p.coordinate(i, k)) + ", not a finite number");
  return p;
}

float checked_max_distance(double max_distance) {
  if (!(max_distance >= 0))
    throw py::value_error("max_distance: " + std::to_string(max_distance) + " is not a distance (0 to inf)");
  return float(max_distance);
}

// The points are cut into chunks along a Morton curve over all of them
// (cpu/point_order.h), not in the caller's order: a chunk of scattered
// points is then a patch of near ones, which the walk takes each from the
// last one's answer.
void nearest_points(const BlobView& view, const double* centre, const PointArrays& points, float max_distance,
                    uint32_t threads, std::vector<ClosestPoint>& out) {
  out.resize(points.count);
  const std::vector<size_t> order = morton_order(points.count, [&](size_t i, int k) { return points.coordinate(i, k); });
  const Chunks plan = plan_chunks(points.count, threads);
  std::atomic<uint64_t> beyond{0};
  for_each_chunk(plan, threads, [&](size_t chunk) {
    const size_t begin = plan.begin(chunk), n = plan.end(chunk) - begin;
    std::vector<Vec3> local(n);
    std::vector<ClosestPoint> found(n);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) local[i][k] = float(points.coordinate(order[begin + i], k) - (centre ? centre[k] : 0.0));
    beyond += view.closest_points(local, found, max_distance);
    for (size_t i = 0; i < n; ++i) out[order[begin + i]] = found[i];
  });
  // Finite in float64 but past float's range in the blob's frame (1e39):
  // refused, as a ray from there is, never answered as "nothing near".
  if (beyond > 0)
    throw std::invalid_argument(std::to_string(beyond.load()) + " query points lie beyond float's range (3.4e38) "
                                "from the mesh's stored frame");
}

void scene_nearest_points(const SceneSnapshot& frame, const PointArrays& points, double max_distance, uint8_t mask,
                          uint32_t threads, const std::function<void(size_t, const SceneClosestPoint&)>& use) {
  const std::vector<size_t> order = morton_order(points.count, [&](size_t i, int k) { return points.coordinate(i, k); });
  const Chunks plan = plan_chunks(points.count, threads);
  for_each_chunk(plan, threads, [&](size_t chunk) {
    const size_t begin = plan.begin(chunk), n = plan.end(chunk) - begin;
    std::vector<std::array<double, 3>> world(n);
    std::vector<SceneClosestPoint> found(n);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) world[i][k] = points.coordinate(order[begin + i], k);
    closest_points_snapshot(frame, world, found, max_distance, mask);
    for (size_t i = 0; i < n; ++i) use(order[begin + i], found[i]);
  });
}

}  // namespace meshcast::python
