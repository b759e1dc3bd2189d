// meshcast.RaycastingScene: Open3D's RaycastingScene (open3d.t.geometry)
// with its names, shapes, dtypes and sentinels, on a meshcast Scene. Each
// add_triangles() builds a blob in the recommended layout from the mesh
// taken relative to a float64 centre, the centre becoming its instance's
// translation: meshes far from the origin keep their precision.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <vector>

#include "meshcast/build.h"
#include "meshcast/scene.h"
#include "python/src/arrays.h"
#include "python/src/cast.h"

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
  const double g = extent > 0 && std::isfinite(extent) ? std::exp2(std::ceil(std::log2(extent))) : 1.0;
  for (int k = 0; k < 3; ++k) {
    const double mid = 0.5 * lo[k] + 0.5 * hi[k];
    centre[k] = std::isfinite(mid) ? std::nearbyint(mid / g) * g : 0.0;
  }
}

class RaycastingScene {
 public:
  uint32_t add_triangles(const py::handle& vertices, const py::handle& triangles) {
    double lo[3], hi[3], centre[3];
    vertex_box(vertices, lo, hi);
    storage_centre(lo, hi, centre);
    const std::string name = "geometry " + std::to_string(normals_.size());
    Mesh mesh = mesh_from_arrays(vertices, triangles, centre);
    std::vector<float> normals(mesh.triangle_count() * 3);
    std::vector<uint8_t> blob;
    {
      py::gil_scoped_release release;
      blob = build_blob(mesh, BuildOptions{}, name);
      // Open3D's primitive_normals: the unit geometric normal (b - a) x (c - a).
      for (size_t i = 0; i < mesh.triangle_count(); ++i) {
        double e1[3], e2[3];
        for (int k = 0; k < 3; ++k) {
          e1[k] = double(mesh.corner(i, 1)[k]) - mesh.corner(i, 0)[k];
          e2[k] = double(mesh.corner(i, 2)[k]) - mesh.corner(i, 0)[k];
        }
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k) normals[3 * i + k] = length > 0 ? float(n[k] / length) : 0.0f;
      }
    }
    std::lock_guard<std::mutex> lock(mutex_);
    const MeshId mesh_id = scene_.add_mesh(std::move(blob), name);
    Transform placed;
    for (int k = 0; k < 3; ++k) placed.translation[k] = centre[k];
    const InstanceId id = scene_.add_instance(mesh_id, placed);
    normals_.push_back(std::move(normals));
    changed_ = true;
    return id;
  }

  py::dict cast_rays(const py::handle& rays_in, uint32_t nthreads) {
    RayArrays rays = rays_from_six(rays_in);
    std::vector<py::ssize_t> shape2 = rays.shape, shape3 = rays.shape;
    shape2.push_back(2);
    shape3.push_back(3);
    py::array_t<float> t(rays.shape), uvs(shape2), normals(shape3);
    py::array_t<uint32_t> geometry(rays.shape), primitive(rays.shape);
    float* t_out = t.mutable_data();
    float* uv_out = uvs.mutable_data();
    float* n_out = normals.mutable_data();
    uint32_t* g_out = geometry.mutable_data();
    uint32_t* p_out = primitive.mutable_data();
    uint64_t refused;
    {
      py::gil_scoped_release release;
      commit();
      refused = cast_hits(SceneTarget{scene_}, rays, Query::Closest, Cull::None, HitOutputs::Uv, thread_count(nthreads),
                          [&](size_t i, const SceneHit& h) {
                            t_out[i] = h.t;
                            g_out[i] = h.instance;
                            p_out[i] = h.triangle;
                            uv_out[2 * i] = h.u;
                            uv_out[2 * i + 1] = h.v;
                            const float* n = h.instance != kNoHit ? &normals_[h.instance][3 * size_t(h.triangle)]
                                                                  : kNoNormal;
                            for (int k = 0; k < 3; ++k) n_out[3 * i + k] = n[k];
                          });
    }
    raise_for_refused(rays, refused);
    py::dict answer;
    answer["t_hit"] = t;
    answer["geometry_ids"] = geometry;
    answer["primitive_ids"] = primitive;
    answer["primitive_uvs"] = uvs;
    answer["primitive_normals"] = normals;
    return answer;
  }

  py::array test_occlusions(const py::handle& rays_in, const py::handle& tnear, const py::handle& tfar,
                            uint32_t nthreads) {
    RayArrays rays = rays_from_six(rays_in);
    set_segment(rays, tnear, tfar);
    py::array_t<bool> occluded(rays.shape);
    bool* out = occluded.mutable_data();
    uint64_t refused;
    {
      py::gil_scoped_release release;
      commit();
      refused = cast_hits(SceneTarget{scene_}, rays, Query::Any, Cull::None, HitOutputs::None, thread_count(nthreads),
                          [out](size_t i, const SceneHit& h) { out[i] = h.triangle != kNoHit; });
    }
    raise_for_refused(rays, refused);
    return occluded;
  }

  py::array count_intersections(const py::handle& rays_in, uint32_t nthreads) {
    RayArrays rays = rays_from_six(rays_in);
    AllHits<SceneTarget> all;
    {
      py::gil_scoped_release release;
      commit();
      // One hit kept a ray: the walk counts them all (HitRows::found).
      all = cast_all(SceneTarget{scene_}, rays, Cull::None, HitOutputs::None, 1, thread_count(nthreads));
    }
    raise_for_refused(rays, all.refused);
    py::array_t<int32_t> counts(rays.shape);
    int32_t* out = counts.mutable_data();
    all.gather([out](size_t i, uint32_t found, size_t) { out[i] = int32_t(std::min<uint32_t>(found, INT32_MAX)); },
               [](size_t, const SceneHit&) {});
    return counts;
  }

  py::dict list_intersections(const py::handle& rays_in, uint32_t nthreads) {
    RayArrays rays = rays_from_six(rays_in);
    AllHits<SceneTarget> all;
    {
      py::gil_scoped_release release;
      commit();
      all = cast_all(SceneTarget{scene_}, rays, Cull::None, HitOutputs::Uv, kMaxHitsLimit, thread_count(nthreads));
    }
    raise_for_refused(rays, all.refused);
    const py::ssize_t n = py::ssize_t(rays.count), h = py::ssize_t(all.hits());
    py::array_t<uint32_t> splits({n + 1}), ray_ids({h}), geometry({h}), primitive({h});
    py::array_t<float> uvs({h, py::ssize_t(2)}), t({h});
    uint32_t* s_out = splits.mutable_data();
    uint32_t* r_out = ray_ids.mutable_data();
    uint32_t* g_out = geometry.mutable_data();
    uint32_t* p_out = primitive.mutable_data();
    float* uv_out = uvs.mutable_data();
    float* t_out = t.mutable_data();
    uint64_t dropped = 0;
    {
      py::gil_scoped_release release;
      all.gather(
          [&](size_t i, uint32_t found, size_t offset) {
            s_out[i] = uint32_t(offset);
            if (found > kMaxHitsLimit) dropped += found - kMaxHitsLimit;
          },
          [&](size_t j, const SceneHit& hit) {
            g_out[j] = hit.instance;
            p_out[j] = hit.triangle;
            uv_out[2 * j] = hit.u;
            uv_out[2 * j + 1] = hit.v;
            t_out[j] = hit.t;
          });
      s_out[rays.count] = uint32_t(all.hits());
      for (size_t i = 0; i < rays.count; ++i)
        for (uint32_t j = s_out[i]; j < s_out[i + 1]; ++j) r_out[j] = uint32_t(i);
    }
    if (dropped)
      PyErr_WarnEx(PyExc_RuntimeWarning,
                   ("list_intersections: " + std::to_string(dropped) + " hits beyond " +
                    std::to_string(kMaxHitsLimit) + " a ray were left out (count_intersections counts them)")
                       .c_str(),
                   1);
    py::dict answer;
    answer["ray_splits"] = splits;
    answer["ray_ids"] = ray_ids;
    answer["geometry_ids"] = geometry;
    answer["primitive_ids"] = primitive;
    answer["primitive_uvs"] = uvs;
    answer["t_hit"] = t;
    return answer;
  }

  // The bytes the scene holds: every geometry's blob, its normals and the
  // top level over the instances.
  size_t nbytes() const {
    size_t bytes = scene_.owned_blob_bytes() + scene_.top_level_bytes();
    for (const auto& n : normals_) bytes += n.capacity() * sizeof(float);
    return bytes;
  }

 private:
  // The geometries added so far become what casts see, once.
  void commit() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (changed_) scene_.commit();
    changed_ = false;
  }
  static constexpr float kNoNormal[3] = {0, 0, 0};
  std::mutex mutex_;
  Scene scene_;
  std::vector<std::vector<float>> normals_;  // a unit normal a triangle, a geometry's in its order
  bool changed_ = false;
};

}  // namespace

void register_raycasting_scene(py::module_& m) {
  py::class_<RaycastingScene>(m, "_RaycastingScene")
      .def(py::init([](uint32_t) { return std::make_unique<RaycastingScene>(); }), py::arg("nthreads") = 0)
      .def("add_triangles", &RaycastingScene::add_triangles, py::arg("vertex_positions"), py::arg("triangle_indices"))
      .def("cast_rays", &RaycastingScene::cast_rays, py::arg("rays"), py::arg("nthreads") = 0)
      .def("test_occlusions", &RaycastingScene::test_occlusions, py::arg("rays"), py::arg("tnear") = 0.0,
           py::arg("tfar") = INFINITY, py::arg("nthreads") = 0)
      .def("count_intersections", &RaycastingScene::count_intersections, py::arg("rays"), py::arg("nthreads") = 0)
      .def("list_intersections", &RaycastingScene::list_intersections, py::arg("rays"), py::arg("nthreads") = 0)
      .def_property_readonly("nbytes", &RaycastingScene::nbytes);
  m.attr("INVALID_ID") = kInvalidId;
}

}  // namespace meshcast::python
