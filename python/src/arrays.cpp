#include "python/src/arrays.h"

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace meshcast::python {

std::string shape_text(const std::vector<py::ssize_t>& shape) {
  std::string s = "(";
  for (size_t d = 0; d < shape.size(); ++d) s += (d ? ", " : "") + std::to_string(shape[d]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

std::string shape_text(const py::array& a) {
  return shape_text(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()));
}

double read_real(const uint8_t* p, bool is_double_value) {
  if (is_double_value) {
    double d;
    std::memcpy(&d, p, 8);
    return d;
  }
  float f;
  std::memcpy(&f, p, 4);
  return f;
}

namespace {

bool is_double(const py::array& a) { return a.dtype().itemsize() == 8; }

std::string triple(const double v[3]) {
  std::ostringstream s;
  s.precision(9);
  s << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return s.str();
}

}  // namespace

py::array real_array(const py::handle& input, const char* what) {
  py::module_ np = py::module_::import("numpy");
  py::array a = np.attr("asarray")(input);
  const py::dtype type = a.dtype();
  const char kind = type.kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::value_error(std::string(what) + ": dtype " + py::str(py::object(type)).cast<std::string>() +
                          " is not a real number type (float32 or float64 expected)");
  // float32 and float64 in this machine's byte order are read where they
  // lie; the rest once converted: other byte orders (a big-endian file's
  // '>f4') to native, float16 and integers to float32 (exact for float16;
  // what the library computes in), float128 to float64. asarray with a
  // dtype keeps a number a 0-d array (ascontiguousarray makes it 1-d).
  const bool native = type.attr("isnative").cast<bool>();
  const size_t size = size_t(type.itemsize());
  const char* to = kind == 'f' && size >= 8 ? "float64" : "float32";
  if (!(kind == 'f' && (size == 4 || size == 8) && native)) a = np.attr("asarray")(a, py::arg("dtype") = to);
  if (!(a.flags() & py::array::c_style)) a = np.attr("ascontiguousarray")(a);
  return a;
}

RayD RayArrays::ray_d(size_t i) const {
  RayD r;
  const uint8_t* o = org + i * org_stride;
  const uint8_t* d = dir + i * dir_stride;
  const size_t os = org_double ? 8 : 4, ds = dir_double ? 8 : 4;
  for (int k = 0; k < 3; ++k) {
    r.org[k] = read_real(o + k * os, org_double);
    r.dir[k] = float(read_real(d + k * ds, dir_double));
  }
  r.tmax = tmax(i);
  r.tmin = tmin(i);
  return r;
}

Ray RayArrays::ray(size_t i) const {
  const RayD r = ray_d(i);
  return {{float(r.org[0]), float(r.org[1]), float(r.org[2])}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax, r.tmin};
}

RayArrays rays_from_six(const py::handle& input) {
  RayArrays r;
  py::array a = real_array(input, "rays");
  if (a.ndim() < 1 || a.shape(a.ndim() - 1) != 6)
    throw py::value_error("rays: shape " + shape_text(a) + " is not (..., 6): each ray is ox, oy, oz, dx, dy, dz");
  r.shape.assign(a.shape(), a.shape() + a.ndim() - 1);
  r.count = size_t(a.size() / 6);
  r.origins = r.directions = a;
  r.org = static_cast<const uint8_t*>(a.data());
  r.dir = r.org + 3 * a.itemsize();
  r.org_stride = r.dir_stride = 6 * a.itemsize();
  r.org_double = r.dir_double = is_double(a);
  return r;
}

RayArrays rays_from_pair(const py::handle& origins, const py::handle& directions) {
  RayArrays r;
  py::array o = real_array(origins, "origins"), d = real_array(directions, "directions");
  if (d.ndim() < 1 || d.shape(d.ndim() - 1) != 3)
    throw py::value_error("directions: shape " + shape_text(d) + " is not (..., 3)");
  if (o.ndim() < 1 || o.shape(o.ndim() - 1) != 3)
    throw py::value_error("origins: shape " + shape_text(o) + " is not (..., 3)");
  const bool shared_origin = o.ndim() == 1;
  if (!shared_origin) {
    bool same = o.ndim() == d.ndim();
    for (py::ssize_t k = 0; same && k < o.ndim(); ++k) same = o.shape(k) == d.shape(k);
    if (!same)
      throw py::value_error("origins " + shape_text(o) + " and directions " + shape_text(d) +
                            ": the same shape expected (or one origin, shape (3,), for every ray)");
  }
  r.shape.assign(d.shape(), d.shape() + d.ndim() - 1);
  r.count = size_t(d.size() / 3);
  r.origins = o;
  r.directions = d;
  r.org = static_cast<const uint8_t*>(o.data());
  r.dir = static_cast<const uint8_t*>(d.data());
  r.org_stride = shared_origin ? 0 : 3 * o.itemsize();
  r.dir_stride = 3 * d.itemsize();
  r.org_double = is_double(o);
  r.dir_double = is_double(d);
  return r;
}

namespace {

// One end of the segment: a number, or an array of the rays' shape.
void set_end(RayArrays& rays, const py::handle& value, const char* name, py::array& keep, float& scalar,
             const float*& values) {
  if (value.is_none()) return;
  py::array a = real_array(value, name);
  if (a.ndim() == 0) {
    scalar = float(read_real(static_cast<const uint8_t*>(a.data()), is_double(a)));
    return;
  }
  bool same = size_t(a.ndim()) == rays.shape.size();
  for (size_t k = 0; same && k < rays.shape.size(); ++k) same = a.shape(py::ssize_t(k)) == rays.shape[k];
  if (!same)
    throw py::value_error(std::string(name) + ": shape " + shape_text(a) + " is neither a number nor the rays' " +
                          shape_text(rays.shape));
  keep = py::module_::import("numpy").attr("ascontiguousarray")(a, py::arg("dtype") = "float32");
  values = static_cast<const float*>(keep.data());
}

}  // namespace

void set_segment(RayArrays& rays, const py::handle& t_min, const py::handle& t_max) {
  set_end(rays, t_min, "t_min", rays.t_min, rays.t_min_scalar, rays.t_min_values);
  set_end(rays, t_max, "t_max", rays.t_max, rays.t_max_scalar, rays.t_max_values);
}

namespace {

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

}  // namespace

namespace {

// Whether ray i breaks a rule of the walkers', and with `why`, which one
// in words (without its index). The words are made only when asked for: a
// batch of padded pixels answered as misses asks this of each of them.
bool breaks_a_rule(const RayArrays& rays, size_t i, bool float_origin, std::string* why) {
  RayD r = rays.ray_d(i);
  double o[3], d[3];
  for (int k = 0; k < 3; ++k) {
    // A blob walks the origin rounded to float: that is the one checked.
    o[k] = float_origin ? double(float(r.org[k])) : r.org[k];
    d[k] = read_real(rays.dir + i * rays.dir_stride + k * (rays.dir_double ? 8 : 4), rays.dir_double);
  }
  const auto broken = [why](const auto& words) {
    if (why) *why = words();
    return true;
  };
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(o[k])) return broken([&] { return "origin " + triple(o) + " is not finite"; });
  for (int k = 0; k < 3; ++k)
    if (std::fabs(o[k]) > kMaxCoordinate)
      return broken([&] { return "origin " + triple(o) + " lies beyond 2^100 on an axis"; });
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(d[k]) || !std::isfinite(r.dir[k]))
      return broken([&] { return "direction " + triple(d) + " is not finite (in float)"; });
  for (int k = 0; k < 3; ++k)
    if (std::fabs(r.dir[k]) > kMaxDirection)
      return broken([&] { return "direction " + triple(d) + " has a component beyond 2^126"; });
  if (std::fabs(r.dir[0]) < FLT_MIN && std::fabs(r.dir[1]) < FLT_MIN && std::fabs(r.dir[2]) < FLT_MIN)
    return broken([&] { return "direction " + triple(d) + " is zero (every component below FLT_MIN)"; });
  if (std::isnan(r.tmax) || r.tmax < 0) return broken([&] { return "t_max " + number(r.tmax) + " is NaN or negative"; });
  if (std::isnan(r.tmin) || r.tmin < 0) return broken([&] { return "t_min " + number(r.tmin) + " is NaN or negative"; });
  if (r.tmin > r.tmax)
    return broken([&] { return "t_min " + number(r.tmin) + " is above t_max " + number(r.tmax); });
  return false;
}

}  // namespace

std::string refusal(const RayArrays& rays, size_t i, bool float_origin) {
  std::string why;
  return breaks_a_rule(rays, i, float_origin, &why) ? "rays[" + std::to_string(i) + "]: " + why : "";
}

Invalid parse_invalid(const std::string& name) {
  if (name == "raise") return Invalid::Raise;
  if (name == "miss") return Invalid::Miss;
  throw py::value_error("invalid \"" + name + "\": raise or miss");
}

void raise_for_refused(const RayArrays& rays, const Refused& refused, bool float_origin, Invalid invalid) {
  if (refused.count == 0) return;
  if (refused.first >= rays.count)  // a walk counted a ray that, walked alone, it took: never expected
    throw py::value_error(std::to_string(refused.count) + " of " + std::to_string(rays.count) +
                          " rays refused by the walk (none of them when cast alone)");
  const size_t i = refused.first;
  std::string why = refusal(rays, i, float_origin);
  if (invalid == Invalid::Miss) {
    // The walk answered every refused ray as a miss. That is the answer
    // the caller asked for where the ray is not a ray; one fine in the
    // world that some geometry's frame could not take (below) is not, and
    // is still raised.
    uint64_t not_rays = 0;
    for (size_t j = i; j < rays.count; ++j) not_rays += breaks_a_rule(rays, j, float_origin, nullptr);
    if (not_rays == refused.count) return;
    if (!why.empty())
      throw py::value_error(std::to_string(refused.count - not_rays) + " of " + std::to_string(rays.count) +
                            " rays cannot be walked in the frame of a geometry they pass: their origins lie beyond "
                            "2^100 of that geometry's position (or its scale takes a direction beyond 2^126); cast "
                            "them from nearer the geometry");
  }
  if (why.empty()) {
    // The ray is fine in the world but not in the frame of a geometry it
    // passes: that frame's rounding would answer it wrongly, so it is not
    // answered at all.
    RayD r = rays.ray_d(i);
    double d[3] = {r.dir[0], r.dir[1], r.dir[2]};
    why = "rays[" + std::to_string(i) + "]: origin " + triple(r.org) + ", direction " + triple(d) +
          " cannot be walked in the frame of a geometry it passes: the origin lies beyond 2^100 of that geometry's "
          "position (or its scale takes the direction beyond 2^126); cast it from nearer the geometry";
  }
  throw py::value_error(why + " (" + std::to_string(refused.count) + " of " + std::to_string(rays.count) +
                        " rays refused)");
}

void vertex_box(const py::handle& vertices, double lo[3], double hi[3]) {
  py::array v = real_array(vertices, "vertices");
  if (v.ndim() != 2 || v.shape(1) != 3) throw py::value_error("vertices: shape " + shape_text(v) + " is not (V, 3)");
  const uint8_t* p = static_cast<const uint8_t*>(v.data());
  const bool dbl = is_double(v);
  const size_t size = dbl ? 8 : 4;
  for (int k = 0; k < 3; ++k) lo[k] = INFINITY, hi[k] = -INFINITY;
  for (py::ssize_t i = 0; i < v.shape(0); ++i)
    for (int k = 0; k < 3; ++k) {
      const double x = read_real(p + (size_t(i) * 3 + k) * size, dbl);
      lo[k] = std::fmin(lo[k], x);  // fmin: a NaN is left for check_mesh to name
      hi[k] = std::fmax(hi[k], x);
    }
}

Mesh mesh_from_arrays(const py::handle& vertices, const py::handle& triangles, const double centre[3]) {
  py::array v = real_array(vertices, "vertices");
  if (v.ndim() != 2 || v.shape(1) != 3) throw py::value_error("vertices: shape " + shape_text(v) + " is not (V, 3)");
  py::module_ np = py::module_::import("numpy");
  py::array t = np.attr("asarray")(triangles);
  const char kind = t.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::value_error("triangles: dtype " + py::str(t.dtype()).cast<std::string>() +
                          " is not an integer type (int32, uint32 or int64 expected)");
  if (t.ndim() != 2 || t.shape(1) != 3)
    throw py::value_error("triangles: shape " + shape_text(t) + " is not (T, 3)");
  const size_t vertex_count = size_t(v.shape(0));
  if (vertex_count > UINT32_MAX)
    throw py::value_error("vertices: " + std::to_string(vertex_count) + " of them, beyond 2^32 (32-bit indices)");
  // uint64 would wrap negatives; int64 holds every int32, uint32 and int64.
  py::array_t<int64_t> indices = np.attr("ascontiguousarray")(
      kind == 'u' && t.dtype().itemsize() == 8 ? np.attr("minimum")(t, uint64_t(INT64_MAX)) : t,
      py::arg("dtype") = "int64");
  Mesh mesh;
  mesh.triangles.resize(size_t(t.shape(0)));
  const int64_t* in = indices.data();
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int64_t index = in[i * 3 + k];
      if (index < 0 || uint64_t(index) >= vertex_count)  // named as the caller's array holds it, not as converted
        throw py::value_error("triangles[" + std::to_string(i) + ", " + std::to_string(k) + "] = " +
                              py::str(t[py::make_tuple(i, k)]).cast<std::string>() + ": a vertex index must lie in [0, " +
                              std::to_string(vertex_count) + ")");
      mesh.triangles[i][k] = uint32_t(index);
    }
  const uint8_t* p = static_cast<const uint8_t*>(v.data());
  const bool dbl = is_double(v);
  const size_t size = dbl ? 8 : 4;
  mesh.vertices.resize(vertex_count);
  for (size_t i = 0; i < vertex_count; ++i)
    for (int k = 0; k < 3; ++k) mesh.vertices[i][k] = float(read_real(p + (i * 3 + k) * size, dbl) - centre[k]);
  return mesh;
}

template <class T>
py::array_t<T> answer_array(const py::object& out, const char* key, const std::vector<py::ssize_t>& shape) {
  if (!out.is_none()) {
    py::dict given = out.cast<py::dict>();
    if (given.contains(key)) {
      py::object o = given[key];
      const std::string name = std::string("out[\"") + key + "\"]";
      if (!py::isinstance<py::array>(o)) throw py::value_error(name + " is not a numpy array");
      py::array a = o.cast<py::array>();
      if (!a.dtype().is(py::dtype::of<T>()))
        throw py::value_error(name + ": dtype " + py::str(a.dtype()).cast<std::string>() + " where " +
                              py::str(py::dtype::of<T>()).cast<std::string>() + " is written");
      bool same = size_t(a.ndim()) == shape.size();
      for (size_t k = 0; same && k < shape.size(); ++k) same = a.shape(py::ssize_t(k)) == shape[k];
      if (!same) throw py::value_error(name + ": shape " + shape_text(a) + " where the answer's is " + shape_text(shape));
      if (!(a.flags() & py::array::c_style)) throw py::value_error(name + " is not C-contiguous");
      if (!a.writeable()) throw py::value_error(name + " is read-only");
      return py::reinterpret_borrow<py::array_t<T>>(o);
    }
  }
  return py::array_t<T>(shape);
}

template py::array_t<float> answer_array<float>(const py::object&, const char*, const std::vector<py::ssize_t>&);
template py::array_t<uint32_t> answer_array<uint32_t>(const py::object&, const char*,
                                                      const std::vector<py::ssize_t>&);
template py::array_t<int32_t> answer_array<int32_t>(const py::object&, const char*, const std::vector<py::ssize_t>&);
template py::array_t<bool> answer_array<bool>(const py::object&, const char*, const std::vector<py::ssize_t>&);
template py::array_t<int64_t> answer_array<int64_t>(const py::object&, const char*, const std::vector<py::ssize_t>&);

Query parse_query(const std::string& name) {
  if (name == "closest") return Query::Closest;
  if (name == "any") return Query::Any;
  if (name == "all") return Query::All;
  throw py::value_error("query \"" + name + "\": closest, any or all");
}

Cull parse_cull(const std::string& name) {
  if (name == "none") return Cull::None;
  if (name == "back") return Cull::Back;
  if (name == "front") return Cull::Front;
  throw py::value_error("cull \"" + name + "\": none, back or front");
}

void check_out_keys(const py::object& out, bool instance, bool uv) {
  if (out.is_none()) return;
  if (!py::isinstance<py::dict>(out)) throw py::value_error("out: a dict of arrays (keyed as the answer's) expected");
  for (auto item : out.cast<py::dict>()) {
    const std::string key = py::str(item.first);
    if (key != "t" && key != "triangle" && !(uv && key == "uv") && !(instance && key == "instance"))
      throw py::value_error("out[\"" + key + "\"]: the answer has no such array (t, " +
                            (instance ? "instance, " : "") + "triangle" + (uv ? ", uv" : "; uv with uv=True") + ")");
  }
}

}  // namespace meshcast::python
