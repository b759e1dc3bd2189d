// meshcast.Scene: instances of blobs, placed with a 3x3 rotation-scale and a
// float64 translation, edited and committed, cast against with float32 or
// float64 rays (the origins kept in double: meshcast/scene.h).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <random>
#include <vector>

#include "meshcast/errors.h"
#include "meshcast/scene.h"
#include "python/src/answers.h"
#include "python/src/arrays.h"
#include "python/src/blob_api.h"
#include "python/src/cast.h"
#include "python/src/parallel.h"
#include "python/src/pickled.h"
#include "python/src/points.h"

namespace meshcast::python {

namespace {

struct Placed {
  uint32_t mesh = 0;  // the mesh's index
  Transform transform;
  uint8_t mask = 0xFF;
  bool flip_facing = false, enabled = true, removed = false;
};

// A scene's number for the ids it gives Python (meshcast/_scene_ids.py):
// drawn at random, so that a scene pickled into another process keeps one
// no scene of that process has.
uint64_t drawn_scene_number() {
  std::random_device device;
  return (uint64_t(device()) << 32) ^ uint64_t(device());
}

// Python's ids: the int subclasses meshcast/_scene_ids.py defines.
py::object python_id(const char* kind, uint32_t index, uint64_t number) {
  return py::module_::import("meshcast._scene_ids").attr(kind)(index, number);
}

class PyScene {
 public:
  explicit PyScene(uint64_t scene_number = drawn_scene_number()) : number(scene_number) {}

  py::object add_mesh(const std::shared_ptr<PyBlob>& blob) {
    // A mapped file is shared with the scene; bytes built here are
    // referenced, and the Blob kept alive beside the scene.
    const MeshId id = blob->mapped() ? scene.add_mesh(blob->mapped_file(), blob->name())
                                     : scene.add_mesh(blob->view(), blob->name());
    blobs.push_back(blob);
    return python_id("MeshId", id.index, number);
  }
  py::object add_instance(uint32_t mesh, const Transform& t, uint8_t mask, bool flip_facing) {
    const InstanceId id = scene.add_instance(MeshId{mesh, scene.number()}, t, mask, flip_facing);
    instances.resize(size_t(id.index) + 1);
    instances[id.index] = {mesh, t, mask, flip_facing};
    edited = true;
    return python_id("InstanceId", id.index, number);
  }
  // The index a Python id stands for: one this scene gave (or a copy of
  // it), or a plain int taken as an index; another scene's is refused.
  uint32_t index_of(const py::handle& id, const char* kind, const char* who) const {
    const py::object scene_id = py::module_::import("meshcast._scene_ids").attr("SceneId");
    if (py::isinstance(id, scene_id)) {
      const py::object given_by = id.attr("scene");
      if (!given_by.equal(py::int_(number)))
        throw UsageError(std::string(who) + ": " + kind + " " + py::repr(id).cast<std::string>() +
                         " was given by another scene, not this one");
    }
    // Any integer (numpy's too, as casts answer them), never a bool.
    if (py::isinstance<py::bool_>(id) || !PyIndex_Check(id.ptr()))
      throw py::type_error(std::string(who) + ": a " + kind + " id (an int) expected, " +
                           py::str(py::type::of(id).attr("__name__")).cast<std::string>() + " found");
    const py::int_ whole = py::reinterpret_steal<py::int_>(PyNumber_Index(id.ptr()));
    if (!whole) throw py::error_already_set();
    const bool fits = PyObject_RichCompareBool(whole.ptr(), py::int_(0).ptr(), Py_GE) == 1 &&
                      PyObject_RichCompareBool(whole.ptr(), py::int_(0xFFFFFFFFu).ptr(), Py_LE) == 1;
    if (!fits)
      throw UsageError(std::string(who) + ": " + kind + " " + py::repr(whole).cast<std::string>() +
                       " is unknown (ids count from 0 to 2^32 - 1)");
    return whole.cast<uint32_t>();
  }
  InstanceId instance_id(const py::handle& id, const char* who) const {
    return InstanceId{index_of(id, "instance", who), scene.number()};
  }
  // The instance's record, after the library has accepted an edit of it
  // (its error names an unknown or removed id first).
  Placed& edit(InstanceId i) {
    edited = true;
    return instances.at(i.index);
  }
  void set_enabled(const py::handle& id, bool enabled) {
    const InstanceId i = instance_id(id, "Scene.set_enabled");
    scene.set_enabled(i, enabled);
    edit(i).enabled = enabled;
  }
  void remove_instance(const py::handle& id) {
    const InstanceId i = instance_id(id, "Scene.remove_instance");
    scene.remove_instance(i);
    edit(i).removed = true;
  }
  std::vector<std::shared_ptr<PyBlob>> blobs;  // before the scene: they outlive it
  // The number the ids this scene gives Python carry: its own, or, for a
  // scene unpickled, the number of the scene pickled.
  uint64_t number;
  Scene scene;
  // Each instance as last edited: set_transform's parts left as they were,
  // and what a pickled Scene replays.
  std::vector<Placed> instances;
  bool edited = false;  // edits not yet committed
};

// The transform with the parts given (None: `t`'s kept).
Transform transform_from(const py::handle& rotation_scale, const py::handle& translation, Transform t = {}) {
  if (!rotation_scale.is_none()) {
    py::array m = real_array(rotation_scale, "rotation_scale");
    if (m.ndim() != 2 || m.shape(0) != 3 || m.shape(1) != 3)
      throw py::value_error("rotation_scale: a (3, 3) matrix expected");
    py::array_t<float> f = py::module_::import("numpy").attr("ascontiguousarray")(m, py::arg("dtype") = "float32");
    for (int k = 0; k < 9; ++k) t.rotation_scale[k] = f.data()[k];
  }
  if (!translation.is_none()) {
    py::array v = real_array(translation, "translation");
    if (v.ndim() != 1 || v.shape(0) != 3) throw py::value_error("translation: a (3,) vector expected");
    py::array_t<double> d = py::module_::import("numpy").attr("ascontiguousarray")(v, py::arg("dtype") = "float64");
    for (int k = 0; k < 3; ++k) t.translation[k] = d.data()[k];
  }
  return t;
}

uint8_t checked_mask(long long mask) {
  if (mask < 0 || mask > 255) throw py::value_error("mask " + std::to_string(mask) + ": from 0 to 255 (8 bits)");
  return uint8_t(mask);
}

py::dict cast_scene(PyScene& s, const py::handle& origins, const py::handle& directions, const py::handle& t_min,
                    const py::handle& t_max, const std::string& query_name, const std::string& cull_name,
                    long long mask, long long max_hits, bool uv, const py::object& out, long long nthreads,
                    const std::string& invalid_name) {
  const Query query = parse_query(query_name);
  const Invalid invalid = parse_invalid(invalid_name);
  const Cull cull = parse_cull(cull_name);
  const uint32_t kept = checked_max_hits(max_hits);
  RayArrays rays = rays_from_pair(origins, directions);
  set_segment(rays, t_min, t_max);
  const HitOutputs outputs = uv ? HitOutputs::Uv : HitOutputs::None;
  const uint32_t threads = thread_count(nthreads);
  return cast_answer(SceneTarget(s.scene, checked_mask(mask)), rays, query, cull, outputs, kept, threads, out, false,
                     invalid);
}

// The nearest point of the committed scene to each world point, on the
// call's threads (meshcast/scene.h: Scene::closest_points).
py::dict closest_points_scene(const PyScene& s, const py::handle& points_in, double max_distance, long long mask,
                              long long nthreads) {
  const PointArrays points = points_from_array(points_in, "points");
  if (!(max_distance >= 0))
    throw py::value_error("max_distance: " + std::to_string(max_distance) + " is not a distance (0 to inf)");
  const uint8_t seen = checked_mask(mask);
  const uint32_t threads = thread_count(nthreads);
  py::array_t<double> point(shape_with(points.shape, 3)), distance(points.shape);
  py::array_t<uint32_t> instance(points.shape), triangle(points.shape);
  py::array_t<float> uv(shape_with(points.shape, 2));
  double* p_out = point.mutable_data();
  double* d_out = distance.mutable_data();
  uint32_t* i_out = instance.mutable_data();
  uint32_t* t_out = triangle.mutable_data();
  float* uv_out = uv.mutable_data();
  {
    py::gil_scoped_release release;
    scene_nearest_points(*s.scene.snapshot(), points, max_distance, seen, threads,
                         [&](size_t i, const SceneClosestPoint& c) {
                           for (int k = 0; k < 3; ++k) p_out[3 * i + k] = c.triangle == kNoHit ? NAN : c.point[k];
                           d_out[i] = c.distance;
                           i_out[i] = c.instance;
                           t_out[i] = c.triangle;
                           uv_out[2 * i] = c.u, uv_out[2 * i + 1] = c.v;
                         });
  }
  py::dict answer;
  answer["point"] = point;
  answer["distance"] = distance;
  answer["instance"] = instance;
  answer["triangle"] = triangle;
  answer["uv"] = uv;
  return answer;
}

// A committed scene's state: (2, blobs, instances, number), each instance
// (mesh, rotation_scale (9 floats, row-major), translation (3 doubles),
// mask, flip_facing, enabled, removed), and the number its ids carry.
// Version 1's (no number) loads as a scene of a number of its own.
py::object scene_state(const PyScene& s) {
  if (s.edited)
    throw py::value_error("Scene: edits since the last commit(); commit them (or undo them) before pickling");
  py::list blobs, instances;
  for (const auto& b : s.blobs) blobs.append(b);
  for (const Placed& p : s.instances) {
    py::list m, t;
    for (float v : p.transform.rotation_scale) m.append(v);
    for (double v : p.transform.translation) t.append(v);
    instances.append(py::make_tuple(p.mesh, m, t, p.mask, p.flip_facing, p.enabled, p.removed));
  }
  return py::make_tuple(2, blobs, instances, s.number);
}

std::unique_ptr<PyScene> scene_from_state(const py::object& pickled_state) {
  const std::string of = "Scene: the pickled state";
  const py::tuple state = pickled<py::tuple>(pickled_state, of, "a tuple");
  const long long version = state.empty() ? 0 : pickled<long long>(state[0], of + "'s version", "an int");
  if (!(version == 1 && state.size() == 3) && !(version == 2 && state.size() == 4))
    throw py::value_error("Scene: a pickled state of another version of meshcast");
  auto s = version == 2 ? std::make_unique<PyScene>(pickled<uint64_t>(state[3], of + "'s number", "an int"))
                        : std::make_unique<PyScene>();
  for (const py::handle b : pickled<py::list>(state[1], of + "'s blobs", "a list")) {
    const std::string what = of + "'s blob " + std::to_string(s->blobs.size());
    if (!py::isinstance<PyBlob>(b)) throw pickled_error(b, what, "a meshcast.Blob");
    s->add_mesh(b.cast<std::shared_ptr<PyBlob>>());
  }
  for (const py::handle item : pickled<py::list>(state[2], of + "'s instances", "a list")) {
    const std::string what = of + "'s instance " + std::to_string(s->instances.size());
    const py::tuple i = pickled<py::tuple>(item, what, "a tuple");
    if (i.size() != 7) throw py::value_error("Scene: a malformed pickled instance");
    const auto m = pickled<std::vector<float>>(i[1], what + " rotation_scale", "a list of 9 floats");
    const auto t = pickled<std::vector<double>>(i[2], what + " translation", "a list of 3 floats");
    if (m.size() != 9 || t.size() != 3) throw py::value_error("Scene: a malformed pickled instance");
    Transform placed;
    std::copy(m.begin(), m.end(), placed.rotation_scale);
    std::copy(t.begin(), t.end(), placed.translation);
    const py::object id = s->add_instance(pickled<uint32_t>(i[0], what + " mesh", "a mesh index (an int)"), placed,
                                          checked_mask(pickled<long long>(i[3], what + " mask", "an int")),
                                          pickled<bool>(i[4], what + " flip_facing", "a bool"));
    if (!pickled<bool>(i[5], what + " enabled", "a bool")) s->set_enabled(id, false);
    if (pickled<bool>(i[6], what + " removed", "a bool")) s->remove_instance(id);
  }
  s->scene.commit();
  s->edited = false;
  return s;
}

}  // namespace

void register_scene(py::module_& m) {
  py::class_<PyScene>(m, "Scene", R"(Instances of blobs, cast against as one world.

world = rotation_scale @ local + translation; the translation is float64, so
worlds far larger than a float reaches keep their precision. Edits are seen
by casts after commit(). One thread edits and commits; any number cast.
Pickled (pickle, Dask, multiprocessing), a committed scene travels as its
blobs, each once (a mapped one as its file's path), and its instance table.)")
      .def(py::init<>())
      .def("add_mesh", &PyScene::add_mesh, py::arg("blob"),
           "Adds a Blob (kept alive by the scene); returns its MeshId (0, 1, ... in order).")
      .def(
          "add_instance",
          [](PyScene& s, const py::handle& mesh, const py::handle& rotation_scale, const py::handle& translation,
             long long mask, bool flip_facing) {
            const Transform t = transform_from(rotation_scale, translation);
            return s.add_instance(s.index_of(mesh, "mesh", "Scene.add_instance"), t, checked_mask(mask), flip_facing);
          },
          py::arg("mesh"), py::arg("rotation_scale") = py::none(), py::arg("translation") = py::none(),
          py::arg("mask") = 0xFF, py::arg("flip_facing") = false,
          R"(A placed copy of a mesh; returns its InstanceId (0, 1, ... in order).

Ids are ints that remember their scene: another scene refuses them
(ValueError); a plain int is taken as an index of this scene.)")
      .def(
          "set_transform",
          [](PyScene& s, const py::handle& id, const py::handle& rotation_scale, const py::handle& translation) {
            const InstanceId i = s.instance_id(id, "Scene.set_transform");
            if (i.index >= s.instances.size()) {
              s.scene.set_transform(i, Transform{});  // the library's error, naming the instance
            }
            const Transform t = transform_from(rotation_scale, translation, s.instances[i.index].transform);
            s.scene.set_transform(i, t);
            s.edit(i).transform = t;
          },
          py::arg("instance"), py::arg("rotation_scale") = py::none(), py::arg("translation") = py::none(),
          "A new rotation_scale, translation or both; a part not given is kept.")
      .def(
          "set_mask",
          [](PyScene& s, const py::handle& id, long long mask) {
            const InstanceId i = s.instance_id(id, "Scene.set_mask");
            s.scene.set_mask(i, checked_mask(mask));
            s.edit(i).mask = uint8_t(mask);
          },
          py::arg("instance"), py::arg("mask"))
      .def(
          "set_flip_facing",
          [](PyScene& s, const py::handle& id, bool flip) {
            const InstanceId i = s.instance_id(id, "Scene.set_flip_facing");
            s.scene.set_flip_facing(i, flip);
            s.edit(i).flip_facing = flip;
          },
          py::arg("instance"), py::arg("flip_facing"))
      .def("set_enabled", &PyScene::set_enabled, py::arg("instance"), py::arg("enabled"))
      .def("remove_instance", &PyScene::remove_instance, py::arg("instance"))
      // The GIL held: edits from other Python threads wait (the library
      // takes edits and commits from one thread at a time).
      .def(
          "commit",
          [](PyScene& s) {
            s.scene.commit();
            s.edited = false;
          },
          "The edits so far are done: casts from now on see them.")
      // Pickled as its blobs (each pickled once, as its bytes or the path of
      // its mapped file) and its instance table, replayed and committed.
      .def(py::pickle(&scene_state, &scene_from_state))
      .def_property_readonly("instance_count", [](const PyScene& s) { return s.scene.instance_count(); })
      .def("cast", &cast_scene, py::arg("origins"), py::arg("directions"), py::arg("t_min") = py::none(),
           py::arg("t_max") = py::none(), py::arg("query") = "closest", py::arg("cull") = "none",
           py::arg("mask") = 0xFF, py::arg("max_hits") = 16, py::arg("uv") = false, py::arg("out") = py::none(),
           py::arg("nthreads") = 0, py::arg("invalid") = "raise", R"(Casts rays against the committed instances.

origins: (..., 3) float32 or float64 (float64 origins are walked in
double as far as each instance's frame), or one (3,) origin for every
ray. directions: (..., 3), need not be normalized; t is in their units.
t_min, t_max: None (0 and inf), a number, or an array of the rays' shape;
a hit needs t_min <= t <= t_max.
query: "closest" (the nearest hit), "any" (a hit, the first found:
occlusion) or "all" (every hit, nearest first).
cull: "none" (two-sided), "back" or "front" (the front face's corners
run counter-clockwise seen from the ray's origin; an instance's
flip_facing and a mirroring transform swap them).
mask: instances whose mask shares a bit with it are seen (0 to 255).
max_hits: query="all" keeps the nearest max_hits of each ray (1 to 4096;
"found" counts them all).
uv: also answer each hit's barycentrics of corners 1 and 2.
out: a dict of arrays to write the answer into (keys as below, C-
contiguous, the answer's dtype and shape; closest and any only).
nthreads: the cast's threads (0: every core).
invalid: "raise" (ValueError naming the first ray with a NaN or
infinite component, a zero direction or t_min above t_max) or "miss"
(such a ray answered as a miss).

Returns a dict of arrays in the rays' shape: "t" (float32, inf on a miss),
"instance" and "triangle" (uint32, NO_HIT on a miss), with uv=True "uv"
(..., 2). query="all": "found" (N,) uint32, "offsets" (N + 1,) int64, and
"t", "instance", "triangle" (and "uv") of the kept hits, ray i's from
offsets[i] to offsets[i + 1].)")
      .def("closest_points", &closest_points_scene, py::arg("points"), py::arg("max_distance") = INFINITY,
           py::arg("mask") = 0xFF, py::arg("nthreads") = 0, R"(The nearest point of the committed instances to each world point.

points: (..., 3) float32 or float64 (finite; kept in double). max_distance:
none farther is answered (inclusive). mask: instances whose mask shares a
bit with it are seen. nthreads: the call's threads (0: every core). Each
instance near enough is walked in its own frame and its triangles placed
in the world, so the distance is the world's under any rotation and
scale, uneven ones too. OctTreeCompressed meshes alone (the recommended
layout and OctTreeCompressed/Float3SOA8).

Returns a dict of arrays in the points' shape: "point" (..., 3) float64
(NaN where none), "distance" float64 (inf where none), "instance" and
"triangle" uint32 (NO_HIT where none), "uv" (..., 2) float32, the
point's barycentrics on the triangle's stored corners; at one distance
the lower instance, then the lower triangle.)");
}

}  // namespace meshcast::python
