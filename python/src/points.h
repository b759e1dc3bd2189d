// Point queries for the package: (..., 3) arrays of query points, and the
// nearest points of a blob's stored mesh to them on the package's threads,
// each point taken into the blob's frame (less the geometry's float64
// centre, then rounded to float) as a ray's origin is.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/scene.h"

namespace meshcast::python {

namespace py = pybind11;

struct PointArrays {
  std::vector<py::ssize_t> shape;  // the leading shape: the answers take it
  size_t count = 0;
  py::array data;  // C-contiguous float32 or float64
  bool is_double = false;
  double coordinate(size_t i, int k) const;
};

// ValueError naming `what` for a shape other than (..., 3), and naming the
// first point with a NaN or infinite coordinate (no distance is meant for it).
PointArrays points_from_array(const py::handle& input, const char* what);

// max_distance as the caller gave it: a number from 0 to infinity
// (ValueError naming it otherwise).
float checked_max_distance(double max_distance);

// The nearest point to each of `points` within `max_distance`, walked on
// `threads` threads without the GIL (the caller releases it), into out
// (resized to the points): in the blob's frame, `centre` (null: none)
// subtracted from each point first.
void nearest_points(const BlobView& view, const double* centre, const PointArrays& points, float max_distance,
                    uint32_t threads, std::vector<ClosestPoint>& out);

// The nearest point of a scene's frame to each of `points` (world
// coordinates, in double: Scene::closest_points), on `threads` threads
// without the GIL (the caller releases it), each handed to use(i, answer).
void scene_nearest_points(const SceneSnapshot& frame, const PointArrays& points, double max_distance, uint8_t mask,
                          uint32_t threads, const std::function<void(size_t, const SceneClosestPoint&)>& use);

}  // namespace meshcast::python
