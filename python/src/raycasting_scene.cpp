// meshcast.RaycastingScene: Open3D's RaycastingScene (open3d.t.geometry)
// with its names, shapes, dtypes and sentinels, on a meshcast Scene. Each
// add_triangles() builds a blob in the recommended layout from the mesh
// taken relative to a float64 centre, the centre becoming its instance's
// translation: meshes far from the origin keep their precision.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <functional>
#include <algorithm>
#include <memory>
#include <span>
#include <mutex>
#include <optional>
#include <vector>

#include "meshcast/build.h"
#include "meshcast/scene.h"
#include "python/src/arrays.h"
#include "python/src/cast.h"
#include "cpu/crossings.h"
#include "python/src/points.h"

namespace meshcast::python {

namespace {

constexpr uint32_t kInvalidId = 0xFFFFFFFFu;  // Open3D's RaycastingScene.INVALID_ID

// The translation a mesh is stored relative to: its box's centre rounded
// to a multiple of g, the power of two at or above its largest extent. A
// mesh about the origin keeps a centre of 0 (float vertices stay exact);
// one far out is stored at most g from its centre, its vertices rounded
// to float there; and a mesh moved by a multiple of g gets the same
// vertices and the same answers, far out or not.
void storage_centre(const double lo[3], const double hi[3], double centre[3]) {
  double extent = 0;
  for (int k = 0; k < 3; ++k) extent = std::fmax(extent, hi[k] - lo[k]);
  int exponent = 1;  // extent = m 2^exponent, m in [0.5, 1): 2^exponent >= extent, exactly
  if (extent > 0 && std::isfinite(extent)) std::frexp(extent, &exponent);
  const double g = std::ldexp(1.0, exponent);
  for (int k = 0; k < 3; ++k) {
    const double mid = 0.5 * lo[k] + 0.5 * hi[k];
    const double c = std::nearbyint(mid / g) * g;
    centre[k] = std::isfinite(c) ? c : 0.0;  // a NaN or an overflow is left for check_mesh to name
  }
}

// primitive_normals, stored in 4 bytes a triangle: the unit normal mapped
// onto the octahedron |x| + |y| + |z| = 1, its lower half folded over the
// upper, and the square's two coordinates kept in 16 bits each. Decoded,
// a normal is off its double-precision direction by at most about 6e-5
// radians (python/tests measure it); 12 bytes of float32 would nearly
// double the scene's memory (the blob is about 14 bytes a triangle).
// -32768 (never a coordinate's code) marks a degenerate triangle's: no normal.
struct PackedNormal {
  int16_t x = INT16_MIN, y = INT16_MIN;
};
static_assert(sizeof(PackedNormal) == 4);
PackedNormal pack_normal(const double n[3]) {
  const double l1 = std::fabs(n[0]) + std::fabs(n[1]) + std::fabs(n[2]);
  if (!(l1 > 0) || !std::isfinite(l1)) return {};
  double x = n[0] / l1, y = n[1] / l1;
  if (n[2] < 0) {
    const double fx = (1 - std::fabs(y)) * (x >= 0 ? 1 : -1), fy = (1 - std::fabs(x)) * (y >= 0 ? 1 : -1);
    x = fx, y = fy;
  }
  return {int16_t(std::lround(x * 32767)), int16_t(std::lround(y * 32767))};
}
void unpack_normal(const PackedNormal& p, float out[3]) {
  if (p.x == INT16_MIN) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  double x = p.x / 32767.0, y = p.y / 32767.0;
  const double z = 1 - std::fabs(x) - std::fabs(y);
  if (z < 0) {
    const double fx = (1 - std::fabs(y)) * (x >= 0 ? 1 : -1), fy = (1 - std::fabs(x)) * (y >= 0 ? 1 : -1);
    x = fx, y = fy;
  }
  const double length = std::sqrt(x * x + y * y + z * z);
  out[0] = float(x / length), out[1] = float(y / length), out[2] = float(z / length);
}

// What a geometry keeps beside its blob (which the scene holds): its
// triangles' normals, and their corners for the crossings (crossings.h).
// Its blob's view and float64 centre serve the point queries, which walk
// each geometry's blob with the point in its frame.
struct Geometry {
  std::vector<PackedNormal> normals;
  TriangleCorners corners;
  BlobView view;
  double centre[3];
  Geometry(std::vector<PackedNormal> normals, std::span<const uint8_t> blob, const std::string& name,
           const double at[3])
      : normals(std::move(normals)), corners(blob), view(blob, name), centre{at[0], at[1], at[2]} {}
};
// Every geometry, as a cast sees them.
using Geometries = std::vector<std::shared_ptr<const Geometry>>;
// A frame's geometries' corners, by geometry (crossings.h).
using CornersOf = std::function<const TriangleCorners&(uint32_t geometry)>;

inline SceneHit scene_hit(const SceneHit& h) { return h; }
inline SceneHit scene_hit(const Hit& h) { return {h.t, geometry_of(h), h.triangle, h.u, h.v}; }

// The arrays an answer names its primitives with, Open3D's keys:
// geometry_ids, primitive_ids, primitive_uvs and primitive_normals, in the
// shape of the rays or points asked about.
struct PrimitiveArrays {
  py::array_t<uint32_t> geometry, primitive;
  py::array_t<float> uvs, normals;
  uint32_t* g_out;
  uint32_t* p_out;
  float* uv_out;
  float* n_out;
  explicit PrimitiveArrays(const std::vector<py::ssize_t>& shape)
      : geometry(shape), primitive(shape), uvs(shape_with(shape, 2)), normals(shape_with(shape, 3)),
        g_out(geometry.mutable_data()), p_out(primitive.mutable_data()), uv_out(uvs.mutable_data()),
        n_out(normals.mutable_data()) {}
  // Answer i: geometry (kInvalidId: none), its triangle, u and v, and that
  // triangle's normal from `geometries` (no GIL needed).
  template <class Geometries>
  void write(size_t i, uint32_t geometry_id, uint32_t triangle, float u, float v, const Geometries& geometries) {
    const bool found = geometry_id != kInvalidId;
    g_out[i] = geometry_id;
    p_out[i] = found ? triangle : kInvalidId;
    uv_out[2 * i] = u, uv_out[2 * i + 1] = v;
    unpack_normal(found ? geometries[geometry_id]->normals[triangle] : PackedNormal{}, n_out + 3 * i);
  }
  void add_to(py::dict& answer) const {
    answer["geometry_ids"] = geometry;
    answer["primitive_ids"] = primitive;
    answer["primitive_uvs"] = uvs;
    answer["primitive_normals"] = normals;
  }
};

class RaycastingScene {
 public:
  explicit RaycastingScene(uint32_t build_threads) : build_threads_(build_threads) {}
  uint32_t add_triangles(const py::handle& vertices, const py::handle& triangles) {
    double lo[3], hi[3], centre[3];
    vertex_box(vertices, lo, hi);
    storage_centre(lo, hi, centre);
    std::string name;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      name = "geometry " + std::to_string(geometries_.size());
    }
    Mesh mesh = mesh_from_arrays(vertices, triangles, centre);
    std::vector<PackedNormal> normals(mesh.triangle_count());
    std::vector<uint8_t> blob;
    {
      py::gil_scoped_release release;
      BuildOptions options;
      options.threads = build_threads_;
      blob = build_blob(mesh, options, name);
      // Open3D's primitive_normals: the unit geometric normal (b - a) x (c - a).
      for (size_t i = 0; i < mesh.triangle_count(); ++i) {
        double e1[3], e2[3];
        for (int k = 0; k < 3; ++k) {
          e1[k] = double(mesh.corner(i, 1)[k]) - mesh.corner(i, 0)[k];
          e2[k] = double(mesh.corner(i, 2)[k]) - mesh.corner(i, 0)[k];
        }
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        normals[i] = pack_normal(n);
      }
    }
    blob.shrink_to_fit();  // the builder's spare capacity would be memory the scene holds
    std::lock_guard<std::mutex> lock(mutex_);
    return add_geometry(std::move(blob), std::move(normals), centre, name);
  }

  // A scene of the same geometries, each blob and its normals copied (copy
  // and deepcopy in Python): adding to one leaves the other as it was.
  std::unique_ptr<RaycastingScene> copy() const {
    auto twin = std::make_unique<RaycastingScene>(build_threads_);
    std::lock_guard<std::mutex> lock(mutex_), twin_lock(twin->mutex_);
    for (size_t g = 0; g < geometries_.size(); ++g) {
      const Geometry& from = *geometries_[g];
      const std::span<const uint8_t> bytes = from.view.bytes();
      twin->add_geometry(std::vector<uint8_t>(bytes.begin(), bytes.end()), from.normals, from.centre,
                         "geometry " + std::to_string(g));
    }
    return twin;
  }

  py::dict cast_rays(const py::handle& rays_in, long long nthreads) {
    RayArrays rays = rays_from_six(rays_in);
    const uint32_t threads = thread_count(nthreads);
    py::array_t<float> t(rays.shape);
    float* t_out = t.mutable_data();
    PrimitiveArrays primitives(rays.shape);
    Refused refused;
    {
      py::gil_scoped_release release;
      const Frame f = frame();
      refused = f.visit([&](const auto& target) {
        return cast_hits(target, rays, Query::Closest, Cull::None, HitOutputs::Uv, threads,
                         [&](size_t i, const auto& h) {
                           t_out[i] = h.t;
                           primitives.write(i, geometry_of(h), h.triangle, h.u, h.v, *f.geometries);
                         });
      });
    }
    raise_for_refused(rays, refused, false);
    py::dict answer;
    answer["t_hit"] = t;
    primitives.add_to(answer);
    return answer;
  }

  py::array test_occlusions(const py::handle& rays_in, const py::handle& tnear, const py::handle& tfar,
                            long long nthreads) {
    RayArrays rays = rays_from_six(rays_in);
    set_segment(rays, tnear, tfar);
    const uint32_t threads = thread_count(nthreads);
    py::array_t<bool> occluded(rays.shape);
    bool* out = occluded.mutable_data();
    Refused refused;
    {
      py::gil_scoped_release release;
      refused = frame().visit([&](const auto& target) {
        return cast_hits(target, rays, Query::Any, Cull::None, HitOutputs::None, threads,
                         [out](size_t i, const auto& h) { out[i] = h.triangle != kNoHit; });
      });
    }
    raise_for_refused(rays, refused, false);
    return occluded;
  }

  py::array count_intersections(const py::handle& rays_in, long long nthreads) {
    const RayArrays rays = rays_from_six(rays_in);
    py::array_t<int32_t> counts(rays.shape);
    int32_t* out = counts.mutable_data();
    every_hit(rays, HitOutputs::None, nthreads, [&](const auto& all, const CornersOf& corners_of) {
      all.for_each_row([&](size_t i, uint32_t found, auto row) {
        uint64_t n = found - row.size();  // beyond the kept hits: each counted
        crossings(row, rays.ray(i).dir, corners_of, [&n](const auto&) { ++n; });
        out[i] = int32_t(std::min<uint64_t>(n, INT32_MAX));
      });
    });
    return counts;
  }

  py::dict list_intersections(const py::handle& rays_in, long long nthreads) {
    const RayArrays rays = rays_from_six(rays_in);
    if (rays.count >= UINT32_MAX)
      throw py::value_error("list_intersections: " + std::to_string(rays.count) +
                            " rays; ray_ids and ray_splits are 32-bit (at most 2^32 - 2 rays)");
    // The crossings of each ray, then the arrays of their total.
    std::vector<SceneHit> listed;
    std::vector<uint32_t> splits_of(rays.count + 1, 0);
    uint64_t dropped = 0;
    every_hit(rays, HitOutputs::Uv, nthreads, [&](const auto& all, const CornersOf& corners_of) {
      listed.reserve(all.hits());
      all.for_each_row([&](size_t i, uint32_t found, auto row) {
        splits_of[i] = uint32_t(listed.size());
        dropped += found - row.size();
        crossings(row, rays.ray(i).dir, corners_of, [&listed](const auto& h) { listed.push_back(scene_hit(h)); });
      });
      splits_of[rays.count] = uint32_t(listed.size());
    });
    if (listed.size() > UINT32_MAX)
      throw py::value_error("list_intersections: " + std::to_string(listed.size()) +
                            " hits; ray_splits is 32-bit (at most 2^32 - 1 hits a call: cast fewer rays)");
    const py::ssize_t n = py::ssize_t(rays.count), h = py::ssize_t(listed.size());
    py::array_t<uint32_t> splits({n + 1}), ray_ids({h}), geometry({h}), primitive({h});
    py::array_t<float> uvs({h, py::ssize_t(2)}), t({h});
    uint32_t* s_out = splits.mutable_data();
    uint32_t* r_out = ray_ids.mutable_data();
    uint32_t* g_out = geometry.mutable_data();
    uint32_t* p_out = primitive.mutable_data();
    float* uv_out = uvs.mutable_data();
    float* t_out = t.mutable_data();
    {
      py::gil_scoped_release release;
      std::copy(splits_of.begin(), splits_of.end(), s_out);
      for (size_t i = 0; i < rays.count; ++i)
        for (uint32_t j = s_out[i]; j < s_out[i + 1]; ++j) {
          const SceneHit& hit = listed[j];
          r_out[j] = uint32_t(i);
          g_out[j] = hit.instance;
          p_out[j] = hit.triangle;
          uv_out[2 * j] = hit.u;
          uv_out[2 * j + 1] = hit.v;
          t_out[j] = hit.t;
        }
    }
    // A warning the caller's filter turns into an error raises it.
    if (dropped && PyErr_WarnEx(PyExc_RuntimeWarning,
                                ("list_intersections: " + std::to_string(dropped) + " hits beyond " +
                                 std::to_string(kMaxHitsLimit) + " a ray were left out (count_intersections counts them)")
                                    .c_str(),
                                1) < 0)
      throw py::error_already_set();
    py::dict answer;
    answer["ray_splits"] = splits;
    answer["ray_ids"] = ray_ids;
    answer["geometry_ids"] = geometry;
    answer["primitive_ids"] = primitive;
    answer["primitive_uvs"] = uvs;
    answer["t_hit"] = t;
    return answer;
  }

  // The nearest point of every geometry to each query point (Open3D's
  // compute_closest_points): each geometry's blob walked with the points
  // in its frame, the nearest kept, at one distance the lower geometry id.
  py::dict compute_closest_points(const py::handle& points_in, long long nthreads) {
    const PointArrays points = points_from_array(points_in, "query_points");
    py::array_t<float> point(shape_with(points.shape, 3));
    float* p_out = point.mutable_data();
    PrimitiveArrays primitives(points.shape);
    {
      py::gil_scoped_release release;
      const Frame f = frame();
      nearest_of_all(*f.geometries, points, thread_count(nthreads), [&](size_t i, uint32_t g, const ClosestPoint& c) {
        for (int k = 0; k < 3; ++k)
          p_out[3 * i + k] = g == kInvalidId ? NAN : float(double(c.point[k]) + (*f.geometries)[g]->centre[k]);
        primitives.write(i, g, c.triangle, c.u, c.v, *f.geometries);
      });
    }
    py::dict answer;
    answer["points"] = point;
    primitives.add_to(answer);
    return answer;
  }

  // The distance to the nearest point of any geometry (float32; inf for a
  // scene without geometry).
  py::array compute_distance(const py::handle& points_in, long long nthreads) {
    const PointArrays points = points_from_array(points_in, "query_points");
    py::array_t<float> distance(points.shape);
    float* out = distance.mutable_data();
    {
      py::gil_scoped_release release;
      const Frame f = frame();
      nearest_of_all(*f.geometries, points, thread_count(nthreads),
                     [&](size_t i, uint32_t, const ClosestPoint& c) { out[i] = c.distance; });
    }
    return distance;
  }

  // The bytes the scene holds: every geometry's blob, its normals (and the
  // corners' table, once a ray through an edge made it) and the top level
  // over the instances.
  size_t nbytes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t bytes = scene_.owned_blob_bytes() + scene_.top_level_bytes();
    for (const auto& g : geometries_) bytes += g->normals.capacity() * sizeof(PackedNormal) + g->corners.nbytes();
    return bytes;
  }

 private:
  // What a cast walks: the last commit of the scene and the normals of its
  // geometries, taken together, committing the geometries added since the
  // last cast first. Casts on other threads keep the frame they took. With
  // one geometry its blob is walked alone, each ray brought into its frame
  // as the scene would bring it (the centre subtracted in double, then
  // rounded to float; the instance's rotation is the identity): the same
  // answers without the scene's top level and instance records.
  struct Frame {
    SceneTarget target;
    std::shared_ptr<const Geometries> geometries;
    const BlobView* single = nullptr;
    const double* centre = nullptr;
    template <class Fn>
    auto visit(const Fn& fn) const -> decltype(fn(target)) {
      if (single) return fn(BlobTarget{*single, centre});
      return fn(target);
    }
  };
  Frame frame() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (changed_) {
      scene_.commit();
      committed_ = std::make_shared<const Geometries>(geometries_);
      changed_ = false;
    }
    Frame f{SceneTarget(scene_, 0xFF), committed_};
    if (committed_->size() == 1) f.single = &*first_, f.centre = first_centre_;
    return f;
  }
  // Every hit of every ray (as many as a row keeps: kMaxHitsLimit; the
  // rest counted), handed to use(all, corners_of) without the GIL, for the
  // crossings to be told from with the corners of the frame they were
  // found in.
  template <class Use>
  void every_hit(const RayArrays& rays, HitOutputs outputs, long long nthreads, const Use& use) {
    const uint32_t threads = thread_count(nthreads);
    Refused refused;
    {
      py::gil_scoped_release release;
      const Frame f = frame();
      f.visit([&](const auto& target) {
        const auto all = cast_all(target, rays, Cull::None, outputs, kMaxHitsLimit, threads);
        refused = all.refused;
        const Geometries& geometries = *f.geometries;
        if (refused.count == 0) use(all, CornersOf([&geometries](uint32_t g) -> const TriangleCorners& { return geometries[g]->corners; }));
      });
    }
    // Before any answer array reaches the caller: a refused ray has none.
    raise_for_refused(rays, refused, false);
  }
  // The scene's next geometry and its instance, placed at `centre`; the
  // caller holds the lock.
  uint32_t add_geometry(std::vector<uint8_t> blob, std::vector<PackedNormal> normals, const double centre[3],
                        const std::string& name) {
    const MeshId mesh_id = scene_.add_mesh(std::move(blob), name);
    Transform placed;
    for (int k = 0; k < 3; ++k) placed.translation[k] = centre[k];
    const InstanceId id = scene_.add_instance(mesh_id, placed);
    geometries_.push_back(std::make_shared<const Geometry>(std::move(normals), scene_.mesh_blob(mesh_id), name, centre));
    if (id == 0) {  // the one geometry's blob (validated again: cheap beside its build)
      first_.emplace(scene_.mesh_blob(mesh_id), name);
      std::copy(centre, centre + 3, first_centre_);
    }
    changed_ = true;
    return id;
  }
  // Each point's nearest over the geometries, handed to use(i, geometry,
  // answer) (geometry kInvalidId: none). Without the GIL.
  template <class Use>
  static void nearest_of_all(const Geometries& geometries, const PointArrays& points, uint32_t threads, const Use& use) {
    std::vector<ClosestPoint> best(points.count), found;
    std::vector<uint32_t> best_geometry(points.count, kInvalidId);
    for (uint32_t g = 0; g < geometries.size(); ++g) {
      nearest_points(geometries[g]->view, geometries[g]->centre, points, INFINITY, threads, found);
      for (size_t i = 0; i < points.count; ++i)
        if (found[i].triangle != kNoHit && found[i].distance < best[i].distance)
          best[i] = found[i], best_geometry[i] = g;
    }
    for (size_t i = 0; i < points.count; ++i) use(i, best_geometry[i], best[i]);
  }
  const uint32_t build_threads_;  // BuildOptions::threads of add_triangles (0: every core)
  mutable std::mutex mutex_;  // the geometries added, and the frame committed
  Scene scene_;
  Geometries geometries_;  // every geometry's, added so far
  std::shared_ptr<const Geometries> committed_ = std::make_shared<const Geometries>();
  std::optional<BlobView> first_;  // geometry 0's blob (in the scene), walked alone while it is the only one
  double first_centre_[3] = {0, 0, 0};
  bool changed_ = false;
};

}  // namespace

void register_raycasting_scene(py::module_& m) {
  py::class_<RaycastingScene>(m, "_RaycastingScene")
      .def(py::init([](long long nthreads) {
             // Open3D's: the threads its build uses (0: every core).
             return std::make_unique<RaycastingScene>(nthreads == 0 ? 0 : thread_count(nthreads));
           }),
           py::arg("nthreads") = 0)
      .def("add_triangles", &RaycastingScene::add_triangles, py::arg("vertex_positions"), py::arg("triangle_indices"))
      .def("cast_rays", &RaycastingScene::cast_rays, py::arg("rays"), py::arg("nthreads") = 0)
      .def("test_occlusions", &RaycastingScene::test_occlusions, py::arg("rays"), py::arg("tnear") = 0.0,
           py::arg("tfar") = INFINITY, py::arg("nthreads") = 0)
      .def("count_intersections", &RaycastingScene::count_intersections, py::arg("rays"), py::arg("nthreads") = 0)
      .def("list_intersections", &RaycastingScene::list_intersections, py::arg("rays"), py::arg("nthreads") = 0)
      .def("compute_closest_points", &RaycastingScene::compute_closest_points, py::arg("query_points"),
           py::arg("nthreads") = 0)
      .def("compute_distance", &RaycastingScene::compute_distance, py::arg("query_points"), py::arg("nthreads") = 0)
      .def("copy", &RaycastingScene::copy)
      .def_property_readonly("nbytes", &RaycastingScene::nbytes);
  m.attr("INVALID_ID") = kInvalidId;
}

}  // namespace meshcast::python
