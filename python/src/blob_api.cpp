#include "python/src/blob_api.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

#include "builder/auto_layout.h"
#include "layout/blob_format.h"
#include "meshcast/build.h"
#include "python/src/answers.h"
#include "python/src/arrays.h"
#include "python/src/cast.h"
#include "python/src/points.h"
#if MESHCAST_READER
#include "meshcast/read.h"
#endif

namespace meshcast::python {

PyBlob::PyBlob(std::vector<uint8_t> bytes, std::string name) : owned_(std::move(bytes)), name_(std::move(name)) {
  view_.emplace(owned_, name_);
}

PyBlob::PyBlob(std::shared_ptr<const MappedBlob> file, std::string name, std::string path)
    : mapped_(std::move(file)), name_(std::move(name)), path_(std::move(path)) {
  view_.emplace(mapped_->bytes(), name_);
}

host::Caster& PyBlob::vulkan(HitOutputs outputs, std::unique_lock<std::mutex>& lock) {
  return gpu_.get(
      outputs,
      [this](const host::CasterOptions& options) { return std::make_unique<host::Caster>(view_->bytes(), name_, options); },
      lock);
}

namespace {

// backend="vulkan": the batch through the blob's Vulkan caster (the host
// layer's GPU method for its layout), answered as the CPU's casts are.
py::dict cast_on_gpu(PyBlob& blob, const RayArrays& rays, const host::BatchQuery& query, HitOutputs outputs,
                     const py::object& out, Invalid invalid) {
  const bool uv = has(outputs, HitOutputs::Uv);
  refuse_out_for_all(query.query, out);
  std::optional<OneHitAnswer<Hit>> one;
  if (query.query != Query::All) one.emplace(out, rays.shape, uv);
  AllHits<BlobTarget> all;
  all.parts.resize(1);
  all.parts[0].max_hits = query.max_hits;
  {
    py::gil_scoped_release release;
    if (rays.count > UINT32_MAX)
      throw py::value_error(std::to_string(rays.count) + " rays in one Vulkan cast, more than a batch holds (2^32 - 1)");
    std::unique_lock<std::mutex> lock;
    host::Caster& caster = blob.vulkan(outputs, lock);
    // The rays converted straight into the batch's room: the device's own
    // mapped memory when the GPU answers it.
    const host::OpenBatch batch = caster.open(uint32_t(rays.count), query);
    rays.pack(0, rays.count, batch.rays.data());
    for (size_t i = 0; i < rays.count; ++i)
      if (!ray_is_walkable(batch.rays[i])) {
        if (all.refused.count++ == 0) all.refused.first = i;
      }
    const host::Ticket ticket = caster.submit(batch);
    if (one) {
      std::vector<Hit> hits(rays.count);
      caster.wait(ticket, hits);
      for (size_t i = 0; i < rays.count; ++i) one->write(i, hits[i]);
    } else {
      caster.wait(ticket, all.parts[0]);
    }
  }
  raise_for_refused(rays, all.refused, true, invalid);
  return one ? one->dict() : all_hits_answer(all, rays.count, uv);
}

py::dict cast_blob(const PyBlob& blob, const py::handle& origins, const py::handle& directions,
                   const py::handle& t_min, const py::handle& t_max, const std::string& query_name,
                   const std::string& cull_name, long long max_hits, bool uv, const py::object& out,
                   const std::string& backend, long long nthreads, const std::string& packets_name,
                   const std::string& invalid_name) {
  const Query query = parse_query(query_name);
  const Invalid invalid = parse_invalid(invalid_name);
  if (packets_name != "auto" && packets_name != "off")
    throw py::value_error("packets \"" + packets_name + "\": auto or off");
  const Packets packets = packets_name == "off" ? Packets::Off : Packets::Auto;
  const Cull cull = parse_cull(cull_name);
  if (backend != "cpu" && backend != "vulkan") throw py::value_error("backend \"" + backend + "\": cpu or vulkan");
  const uint32_t kept = checked_max_hits(max_hits);
  RayArrays rays = rays_from_pair(origins, directions);
  set_segment(rays, t_min, t_max);
  const HitOutputs outputs = uv ? HitOutputs::Uv : HitOutputs::None;
  const uint32_t threads = thread_count(nthreads);
  if (backend == "vulkan") return cast_on_gpu(const_cast<PyBlob&>(blob), rays, {query, cull, kept}, outputs, out, invalid);
  return cast_answer(BlobTarget{blob.view(), nullptr, packets}, rays, query, cull, outputs, kept, threads, out, true,
                     invalid);
}

// The nearest point of the stored mesh to each query point.
py::dict closest_points_blob(const PyBlob& blob, const py::handle& points_in, double max_distance, long long nthreads) {
  const PointArrays points = points_from_array(points_in, "points");
  const float limit = checked_max_distance(max_distance);
  // Refused by name even for no points (the walk checks it a chunk).
  if (blob.view().layout().tree != TreeFormat::OctTreeCompressed)
    throw py::value_error("closest_points: point queries walk OctTreeCompressed blobs (the recommended layout, and "
                          "the exact OctTreeCompressed/Float3SOA8); this blob is " + layout_name(blob.view().layout()));
  const uint32_t threads = thread_count(nthreads);
  py::array_t<float> point(shape_with(points.shape, 3)), distance(points.shape), uv(shape_with(points.shape, 2));
  py::array_t<uint32_t> triangle(points.shape);
  float* p_out = point.mutable_data();
  float* d_out = distance.mutable_data();
  float* uv_out = uv.mutable_data();
  uint32_t* t_out = triangle.mutable_data();
  {
    py::gil_scoped_release release;
    std::vector<ClosestPoint> found;
    nearest_points(blob.view(), nullptr, points, limit, threads, found);
    for (size_t i = 0; i < found.size(); ++i) {
      const ClosestPoint& c = found[i];
      for (int k = 0; k < 3; ++k) p_out[3 * i + k] = c.triangle == kNoHit ? NAN : c.point[k];
      d_out[i] = c.distance;
      t_out[i] = c.triangle;
      uv_out[2 * i] = c.u, uv_out[2 * i + 1] = c.v;
    }
  }
  py::dict answer;
  answer["point"] = point;
  answer["distance"] = distance;
  answer["triangle"] = triangle;
  answer["uv"] = uv;
  return answer;
}

std::shared_ptr<PyBlob> build(const py::handle& vertices, const py::handle& triangles, const std::string& layout,
                              const py::object& max_bytes_given, long long leaf_size, long long threads,
                              const std::string& name) {
  if (leaf_size < 0 || leaf_size > 31)
    throw py::value_error("leaf_size " + std::to_string(leaf_size) + ": from 1 to 31 (0: the layout's own)");
  const uint32_t build_threads = threads == 0 ? 0 : thread_count(threads, "threads");
  const double no_centre[3] = {0, 0, 0};
  const Mesh mesh = mesh_from_arrays(vertices, triangles, no_centre);
  // The value as the caller gave it (1000, nan, 1e+39, 1000.5), as Python writes it.
  const std::string max_bytes_text = py::str(max_bytes_given).cast<std::string>();
  const double max_bytes = py::float_(max_bytes_given);
  if (std::isnan(max_bytes)) throw py::value_error("max_bytes: " + max_bytes_text + " is not a number of bytes");
  if (max_bytes < 0) throw py::value_error("max_bytes: " + max_bytes_text + " is negative");
  std::vector<uint8_t> bytes;
  {
    py::gil_scoped_release release;
    if (layout == "auto") {
      AutoLimits limits;
      limits.max_bytes_per_triangle = max_bytes / double(std::max<size_t>(1, mesh.triangle_count()));
      limits.build_threads = build_threads;
      if (leaf_size) throw InputError(name + ": leaf_size is the automatic layout's to choose (name a layout to set it)");
      try {
        bytes = choose_layout(mesh, limits, name).blob;
      } catch (const InputError& e) {
        if (!(max_bytes > 0)) throw;
        // The automatic layout speaks of bytes a triangle: say what the caller's whole-blob limit became.
        throw InputError("max_bytes " + max_bytes_text + " over " + std::to_string(mesh.triangle_count()) +
                         " triangles: " + e.what());
      }
    } else {
      BuildOptions options;
      options.layout = parse_layout_name(layout);
      options.leaf_size = uint32_t(leaf_size);
      options.threads = build_threads;
      bytes = build_blob(mesh, options, name);
      if (max_bytes > 0 && double(bytes.size()) > max_bytes)
        throw InputError(name + ": the " + layout + " blob is " + std::to_string(bytes.size()) +
                         " bytes, above max_bytes " + max_bytes_text +
                         " (layout=\"auto\" chooses a layout within it)");
    }
  }
  return std::make_shared<PyBlob>(std::move(bytes), name);
}

}  // namespace

uint32_t checked_max_hits(long long max_hits) {
  if (max_hits < 1 || max_hits > kMaxHitsLimit)
    throw py::value_error("max_hits " + std::to_string(max_hits) + ": from 1 to " + std::to_string(kMaxHitsLimit));
  return uint32_t(max_hits);
}

void register_blob(py::module_& m) {
  py::class_<PyBlob, std::shared_ptr<PyBlob>>(m, "Blob", R"(A mesh's ray-cast structure: one byte buffer, validated once.

Made by meshcast.build(), meshcast.load() (the file read into memory, or
memory-mapped with mmap=True) or meshcast.from_bytes(). Any number of
Python threads may cast through one Blob at once. Pickled (pickle, Dask,
multiprocessing), a mapped Blob travels as its file's path, size and
checksum (mapped once a process, see meshcast.load), any other as its
bytes.)")
      .def_property_readonly("layout", [](const PyBlob& b) { return layout_name(b.view().layout()); },
                             "The layout: tree format / triangle format.")
      .def_property_readonly("triangle_count", [](const PyBlob& b) { return b.view().triangle_count(); })
      .def_property_readonly("nbytes", [](const PyBlob& b) { return b.view().bytes().size(); },
                             "The blob's bytes: all the memory the structure takes (the mesh included).")
      .def_property_readonly("mapped", &PyBlob::mapped, "Whether the bytes are a file's, mapped read-only (load(path, mmap=True)).")
      .def_property_readonly("name", &PyBlob::name)
      .def_property_readonly(
          "path", [](const PyBlob& b) { return b.mapped() ? py::object(py::str(b.path())) : py::object(py::none()); },
          "The file a mapped blob reads, as an absolute path (what the Blob pickles as); None for bytes in memory.")
      .def_property_readonly(
          "checksum", [](const PyBlob& b) { return layout::header_of(b.view().bytes().data()).checksum; },
          "The checksum in the blob's header (FNV-1a, 32 bits, over every byte; verified when the blob was\n"
          "built, loaded or mapped): with nbytes, what tells a pickled Blob's file from another.")
      .def(
          "save", [](const PyBlob& b, const std::string& path) { save_blob(path, b.view().bytes()); },
          py::arg("path"), "Writes the blob to a file (replaced whole, or left as it was).")
      .def(
          "to_bytes",
          [](const PyBlob& b) {
            const auto bytes = b.view().bytes();
            return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
          },
          "The blob's bytes, copied.")
      .def("cast", &cast_blob, py::arg("origins"), py::arg("directions"), py::arg("t_min") = py::none(),
           py::arg("t_max") = py::none(), py::arg("query") = "closest", py::arg("cull") = "none",
           py::arg("max_hits") = 16, py::arg("uv") = false, py::arg("out") = py::none(), py::arg("backend") = "cpu",
           py::arg("nthreads") = 0, py::arg("packets") = "auto", py::arg("invalid") = "raise",
           R"(Casts rays against the mesh.

origins: (..., 3) float32 or float64 (rounded to float32: the blob's
frame), or one (3,) origin for every ray. directions: (..., 3), need not
be normalized; t is in their units.
t_min, t_max: None (0 and inf), a number, or an array of the rays' shape;
a hit needs t_min <= t <= t_max.
query: "closest" (the nearest hit), "any" (a hit, the first found:
occlusion) or "all" (every hit, nearest first).
cull: "none" (two-sided), "back" or "front" (the front face's corners
run counter-clockwise seen from the ray's origin).
max_hits: query="all" keeps the nearest max_hits of each ray (1 to 4096;
"found" counts them all).
uv: also answer each hit's barycentrics of corners 1 and 2.
out: a dict of arrays to write the answer into (keys as below, C-
contiguous, the answer's dtype and shape; closest and any only).
backend: "cpu" (meshcast's threads) or "vulkan" (the GPU; RuntimeError
where the machine has none). The answers are the same.
nthreads: the cast's threads (0: every core).
packets: "auto" walks rays of one origin 8 at a time, "off" one by one
(the same answers).
invalid: "raise" (ValueError naming the first ray with a NaN or
infinite component, a zero direction or t_min above t_max) or "miss"
(such a ray answered as a miss).

Returns a dict of arrays in the rays' shape: "t" (float32, inf on a miss)
and "triangle" (uint32, NO_HIT on a miss), with uv=True "uv" (..., 2).
query="all": "found" (N,) uint32, "offsets" (N + 1,) int64, and "t",
"triangle" (and "uv") of the kept hits, ray i's from offsets[i] to
offsets[i + 1].)")
      .def("closest_points", &closest_points_blob, py::arg("points"), py::arg("max_distance") = INFINITY,
           py::arg("nthreads") = 0, R"(The nearest point of the mesh to each query point.

points: (..., 3) float32 or float64. max_distance: points with nothing
that near get triangle NO_HIT, distance inf and a NaN point. Answers a
dict of arrays shaped like the points: point (..., 3) float32, distance
float32, triangle uint32, uv (..., 2) float32 (point = (1 - u - v) a +
u b + v c of the stored corners). Worked out in double from the stored
triangles: exact on an exact layout, within the layout's stated bound of
the input mesh on a quantized one. The recommended layout and
OctTreeCompressed/Float3SOA8 take point queries; another layout raises
ValueError naming it.)")
      .def("__repr__", [](const PyBlob& b) {
        return "<meshcast.Blob " + b.name() + ": " + layout_name(b.view().layout()) + ", " +
               std::to_string(b.view().triangle_count()) + " triangles, " + std::to_string(b.view().bytes().size()) +
               " bytes" + (b.mapped() ? ", mapped" : "") + ">";
      });

  m.def("_build", &build, py::arg("vertices"), py::arg("triangles"), py::arg("layout") = "auto",
        py::arg("max_bytes") = 0, py::arg("leaf_size") = 0, py::arg("threads") = 0, py::arg("name") = "mesh");
  m.def(
      "_load",
      [](const std::string& path, bool mmap, std::string name) {
        if (name.empty()) name = path;
        if (mmap) return std::make_shared<PyBlob>(std::make_shared<const MappedBlob>(path), name, path);
        std::vector<uint8_t> bytes;
        {
          py::gil_scoped_release release;
          bytes = load_blob(path);
        }
        return std::make_shared<PyBlob>(std::move(bytes), name);
      },
      py::arg("path"), py::arg("mmap") = false, py::arg("name") = "");
  m.def(
      "_from_bytes",
      [](const py::bytes& data, const std::string& name) {
        const std::string_view s = data;
        return std::make_shared<PyBlob>(std::vector<uint8_t>(s.begin(), s.end()), name);
      },
      py::arg("data"), py::arg("name") = "bytes");
  m.def("layouts", [] {
    std::vector<std::string> names;
    for (const Layout& l : all_layouts()) names.push_back(layout_name(l));
    return names;
  }, "Every layout meshcast.build takes by name.");
#if MESHCAST_READER
  m.def(
      "_read_mesh",
      [](const std::string& path) {
        Mesh mesh;
        {
          py::gil_scoped_release release;
          mesh = read_mesh(path);
        }
        py::array_t<float> v({py::ssize_t(mesh.vertices.size()), py::ssize_t(3)});
        py::array_t<uint32_t> t({py::ssize_t(mesh.triangles.size()), py::ssize_t(3)});
        std::memcpy(v.mutable_data(), mesh.vertices.data(), mesh.vertices.size() * sizeof(Vec3));
        std::memcpy(t.mutable_data(), mesh.triangles.data(), mesh.triangles.size() * sizeof(Triangle));
        return py::make_tuple(v, t);
      },
      py::arg("path"));
#endif
}

}  // namespace meshcast::python
