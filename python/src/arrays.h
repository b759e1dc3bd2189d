// numpy arrays in and out: the shapes and dtypes the package takes, read
// where they lie when they are C-contiguous and of a dtype the walk reads
// (float32 or float64), converted once otherwise; and the arrays it answers
// into, new or the caller's `out=`.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <string>
#include <vector>

#include "meshcast/mesh.h"
#include "meshcast/ray.h"
#include "meshcast/scene.h"

namespace meshcast::python {

namespace py = pybind11;

// A real-valued array as float32 or float64, C-contiguous: float32 and
// float64 arrays kept (copied once when not contiguous), integers and
// float16 converted to float32. ValueError naming `what` for complex,
// boolean, object and string arrays.
py::array real_array(const py::handle& input, const char* what);
// `shape` with one more axis of n: an answer of n values a ray or point.
inline std::vector<py::ssize_t> shape_with(std::vector<py::ssize_t> shape, py::ssize_t n) {
  shape.push_back(n);
  return shape;
}
// An array's shape as Python writes it: "(4, 3)", "(3,)".
std::string shape_text(const py::array& a);
std::string shape_text(const std::vector<py::ssize_t>& shape);
// A float32 or float64 value at p (numpy may hand over unaligned memory).
double read_real(const uint8_t* p, bool is_double_value);

// Rays as the caller gave them: origins and directions (...,3) each, or
// one (...,6) array whose first three columns are the origin. The leading
// shape is the rays' shape: the answers take it.
struct RayArrays {
  std::vector<py::ssize_t> shape;  // the leading shape
  size_t count = 0;
  py::array origins, directions;   // C-contiguous float32 or float64 (one array twice for (...,6))
  const uint8_t* org = nullptr;    // the first ray's origin x and direction x
  const uint8_t* dir = nullptr;
  // Bytes from one ray's origin (direction) to the next's: 0 for one
  // origin (3,) that every direction shares (a sensor's rays).
  size_t org_stride = 0, dir_stride = 0;
  bool org_double = false, dir_double = false;
  // t_min and t_max: a scalar each, or an array of the rays' shape (float32).
  py::array t_min, t_max;
  float t_min_scalar = 0, t_max_scalar = INFINITY;
  const float* t_min_values = nullptr;
  const float* t_max_values = nullptr;

  float tmin(size_t i) const { return t_min_values ? t_min_values[i] : t_min_scalar; }
  float tmax(size_t i) const { return t_max_values ? t_max_values[i] : t_max_scalar; }
  // Ray i, its origin rounded to float (a blob's own frame is float).
  Ray ray(size_t i) const;
  // Rays [begin, begin + n) as the walk's records (Ray or RayD), each
  // origin less `offset` in double (a stored geometry's centre; null: none)
  // and then, for a Ray, rounded to float, as a scene brings a ray into an
  // instance's frame: one loop for each pair of the arrays' types, the
  // batch's innermost copy.
  template <class R>
  void pack(size_t begin, size_t n, R* out, const double* offset = nullptr) const;
  // Ray i with its origin as the caller gave it (float32 widened exactly).
  RayD ray_d(size_t i) const;
};

// origins may also be one point (3,) that every ray starts from.
namespace detail {
template <class O, class D, class R>
void pack_rays(const RayArrays& a, size_t begin, size_t n, R* out, const double* offset) {
  using Coordinate = std::remove_reference_t<decltype(out->org[0])>;
  const double zero[3] = {0, 0, 0};
  const double* c = offset ? offset : zero;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* o = a.org + (begin + i) * a.org_stride;
    const uint8_t* d = a.dir + (begin + i) * a.dir_stride;
    O oc[3];
    D dc[3];
    std::memcpy(oc, o, sizeof oc);  // numpy may hand over unaligned memory
    std::memcpy(dc, d, sizeof dc);
    R& r = out[i];
    for (int k = 0; k < 3; ++k) {
      r.org[k] = Coordinate(double(oc[k]) - c[k]);
      r.dir[k] = float(dc[k]);
    }
    r.tmax = a.tmax(begin + i);
    r.tmin = a.tmin(begin + i);
  }
}
}  // namespace detail

template <class R>
void RayArrays::pack(size_t begin, size_t n, R* out, const double* offset) const {
  if (org_double)
    dir_double ? detail::pack_rays<double, double>(*this, begin, n, out, offset)
               : detail::pack_rays<double, float>(*this, begin, n, out, offset);
  else
    dir_double ? detail::pack_rays<float, double>(*this, begin, n, out, offset)
               : detail::pack_rays<float, float>(*this, begin, n, out, offset);
}

RayArrays rays_from_pair(const py::handle& origins, const py::handle& directions);
RayArrays rays_from_six(const py::handle& rays);
// t_min and t_max: None for the default, a number, or an array of the
// rays' shape (ValueError otherwise, naming the argument).
void set_segment(RayArrays& rays, const py::handle& t_min, const py::handle& t_max);

// Why a ray is refused (ValueError: "rays[12]: ..."), checked in the order
// a reader would look, or "" for a ray the walkers take. What they refuse
// is what ray_is_walkable refuses (meshcast/ray.h); the scene's rays check
// their origins in double, whatever their type.
// `float_origin`: the origin as a blob walks it, rounded to float.
std::string refusal(const RayArrays& rays, size_t i, bool float_origin);
// The rays a cast's walk refused: how many, and the first of them in the
// caller's order (cast.h finds it again ray by ray in the chunks that
// refused any: a refusal is rare, and a walk reports only a count).
struct Refused {
  uint64_t count = 0;
  size_t first = SIZE_MAX;
};

// What a cast does with a ray that is not one (refusal() says why: a NaN,
// an infinity, a zero direction, t_min above t_max): raise ValueError
// naming it, or answer it as a miss (Open3D's way; padded pixels of a
// camera's rays are common). "raise" or "miss": ValueError otherwise.
enum class Invalid { Raise, Miss };
Invalid parse_invalid(const std::string& name);

// After a batch that refused rays: ValueError naming the first of them,
// with its refusal(), or, for a ray fine in the world that the frame of
// some geometry cannot take (a translation puts its origin beyond the
// walkers' range there), saying so. With Invalid::Miss the rays that are
// not rays keep the miss the walk answered; a ray fine in the world is
// never answered as a miss: the geometry it cannot see may lie on it.
void raise_for_refused(const RayArrays& rays, const Refused& refused, bool float_origin,
                       Invalid invalid = Invalid::Raise);

// A mesh from (V,3) vertices and (T,3) triangles: indices int32, uint32 or
// int64 (any integer dtype is read), each checked against the vertex count;
// vertices float32 or float64. The vertices are taken less `centre` (in
// double) and rounded to float.
Mesh mesh_from_arrays(const py::handle& vertices, const py::handle& triangles, const double centre[3]);
// The vertices' box in double (for a centre), ValueError for a wrong shape.
void vertex_box(const py::handle& vertices, double lo[3], double hi[3]);

// An answer array: the caller's out[key] when `out` has it (checked: a
// writable C-contiguous array of that dtype and shape, ValueError naming
// the key otherwise), else a new one.
template <class T>
py::array_t<T> answer_array(const py::object& out, const char* key, const std::vector<py::ssize_t>& shape);

// out= must be None or a dict whose keys the answer has: t, triangle, uv
// where `uv`, instance where `instance` (ValueError otherwise).
void check_out_keys(const py::object& out, bool instance, bool uv);

// "closest", "any", "all"; "none", "back", "front": ValueError otherwise.
Query parse_query(const std::string& name);
Cull parse_cull(const std::string& name);

}  // namespace meshcast::python
