// meshcast.RaycastingScene: Open3D's RaycastingScene (open3d.t.geometry)
// with its names, shapes, dtypes and sentinels, on a meshcast Scene. Each
// add_triangles() builds a blob from the mesh taken relative to a float64
// centre, the centre becoming its instance's translation: meshes far from
// the origin keep their precision. The blob is exact unless the user allows
// an error (GeometryLayout).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <cmath>
#include <cstring>
#include <functional>
#include <initializer_list>
#include <algorithm>
#include <memory>
#include <span>
#include <stdexcept>
#include <mutex>
#include <optional>
#include <vector>

#include "builder/error_bounds.h"
#include "layout/blob_format.h"
#include "layout/tree/leaves.h"
#include "meshcast/build.h"
#include "meshcast/errors.h"
#include "meshcast/scene.h"
#include "meshcast/winding_number.h"
#include "python/src/arrays.h"
#include "python/src/cast.h"
#include "python/src/pickled.h"
#include "cpu/crossings.h"
#include "python/src/points.h"
#include "python/src/vulkan_casters.h"

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

// The unit geometric normal (b - a) x (c - a) of corners a, b, c, packed.
PackedNormal normal_of(const float a[3], const float b[3], const float c[3]) {
  double e1[3], e2[3];
  for (int k = 0; k < 3; ++k) e1[k] = double(b[k]) - a[k], e2[k] = double(c[k]) - a[k];
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  return pack_normal(n);
}

// Each triangle's normal from the corners a blob stores, by the caller's
// triangle number (a triangle no leaf holds keeps the degenerate mark).
std::vector<PackedNormal> stored_normals(std::span<const uint8_t> blob) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  std::vector<PackedNormal> normals(h.triangle_count);
  layout::for_each_leaf(blob.data(), [&](uint32_t block, uint32_t count) {
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t triangle = layout::remap_entry(blob.data(), h, layout::slot_of(h, block, i));
      if (triangle >= normals.size()) continue;
      float v[3][3];
      layout::decode_triangle(blob.data(), h.tree_offset + block, i, v);
      normals[triangle] = normal_of(v[0], v[1], v[2]);
    }
  });
  return normals;
}

// What a pickled geometry's normals are checked by: a checksum of them
// joined with one of their blob's header (which holds the checksum of the
// whole blob), so normals altered, or another geometry's, are refused.
uint32_t normals_checksum(std::span<const uint8_t> blob, std::span<const uint8_t> normals) {
  return layout::checksum(blob.first(std::min(blob.size(), sizeof(layout::BlobHeader)))) * 16777619u ^
         layout::checksum(normals);
}

// What a geometry keeps beside its blob (which the scene holds): its
// triangles' normals, and their corners for the crossings (crossings.h).
// Its blob's view and float64 centre serve the point queries, which walk
// each geometry's blob with the point in its frame.
struct Geometry {
  TriangleCorners corners;
  BlobView view;
  double centre[3];
  // `given`: the mesh's normals, for a layout that moves its vertices; none
  // for one that keeps the mesh's floats, whose normals are the stored
  // corners' and are made by the first call that asks for them (a scene
  // queried for distances, signs or t alone never holds them).
  Geometry(std::vector<PackedNormal> given, std::span<const uint8_t> blob, const std::string& name, const double at[3])
      : corners(blob), view(blob, name), centre{at[0], at[1], at[2]}, normals_(std::move(given)) {
    if (!normals_.empty()) normals_made_.store(true);  // normals() then keeps them
  }
  // Open3D's primitive_normals, by triangle (made on first use: see above).
  const std::vector<PackedNormal>& normals() const {
    std::call_once(normals_making_, [this] {
      if (normals_.empty()) normals_ = stored_normals(view.bytes());
      normals_made_.store(true, std::memory_order_release);
    });
    return normals_;
  }
  // The normals held: none until made.
  std::span<const PackedNormal> held_normals() const {
    if (!normals_made_.load(std::memory_order_acquire)) return {};
    return normals_;
  }
  // The winding numbers' clusters, made by the first call that asks for them.
  const WindingNumbers& winding() const {
    std::call_once(winding_made_, [this] {
      winding_ = std::make_unique<const WindingNumbers>(view);
      winding_ready_ = true;
    });
    return *winding_;
  }
  size_t winding_bytes() const { return winding_ready_ ? winding_->nbytes() : 0; }

 private:
  mutable std::vector<PackedNormal> normals_;
  mutable std::once_flag normals_making_;
  mutable std::atomic<bool> normals_made_{false};
  mutable std::once_flag winding_made_;
  mutable std::unique_ptr<const WindingNumbers> winding_;
  mutable std::atomic<bool> winding_ready_{false};
};
// Every geometry, as a cast sees them.
using Geometries = std::vector<std::shared_ptr<const Geometry>>;
// A frame's geometries' corners, by geometry (crossings.h).
using CornersOf = std::function<const TriangleCorners&(uint32_t geometry)>;

inline SceneHit scene_hit(const SceneHit& h) { return h; }
inline SceneHit scene_hit(const Hit& h) { return {h.t, geometry_of(h), h.triangle, h.u, h.v}; }

// out= of a RaycastingScene call: None, or a dict of arrays keyed as the
// answer is (ValueError naming a key the answer has not).
void check_out(const py::object& out, std::initializer_list<const char*> keys) {
  if (out.is_none()) return;
  if (!py::isinstance<py::dict>(out)) throw py::value_error("out: a dict of arrays (keyed as the answer's) expected");
  for (auto item : out.cast<py::dict>()) {
    const std::string key = py::str(item.first);
    if (std::none_of(keys.begin(), keys.end(), [&key](const char* k) { return key == k; })) {
      std::string known;
      for (const char* k : keys) known += (known.empty() ? "" : ", ") + std::string(k);
      throw py::value_error("out[\"" + key + "\"]: the answer has no such array (" + known + ")");
    }
  }
}

// The arrays an answer names its primitives with, Open3D's keys:
// geometry_ids, primitive_ids, and where asked for primitive_uvs and
// primitive_normals, in the shape of the rays or points asked about; each
// the caller's out[key] where given.
struct PrimitiveArrays {
  py::array_t<uint32_t> geometry, primitive;
  py::array_t<float> uvs, normals;
  uint32_t* g_out;
  uint32_t* p_out;
  float* uv_out = nullptr;
  float* n_out = nullptr;
  PrimitiveArrays(const std::vector<py::ssize_t>& shape, const py::object& out, bool with_uvs, bool with_normals)
      : geometry(answer_array<uint32_t>(out, "geometry_ids", shape)),
        primitive(answer_array<uint32_t>(out, "primitive_ids", shape)),
        g_out(geometry.mutable_data()),
        p_out(primitive.mutable_data()) {
    if (with_uvs) uvs = answer_array<float>(out, "primitive_uvs", shape_with(shape, 2)), uv_out = uvs.mutable_data();
    if (with_normals)
      normals = answer_array<float>(out, "primitive_normals", shape_with(shape, 3)), n_out = normals.mutable_data();
  }
  explicit PrimitiveArrays(const std::vector<py::ssize_t>& shape) : PrimitiveArrays(shape, py::none(), true, true) {}
  // Answer i: geometry (kInvalidId: none), its triangle, u and v, and that
  // triangle's normal from `geometries` (no GIL needed).
  template <class Geometries>
  void write(size_t i, uint32_t geometry_id, uint32_t triangle, float u, float v, const Geometries& geometries) {
    const bool found = geometry_id != kInvalidId;
    g_out[i] = geometry_id;
    p_out[i] = found ? triangle : kInvalidId;
    if (uv_out) uv_out[2 * i] = u, uv_out[2 * i + 1] = v;
    if (n_out) unpack_normal(found ? geometries[geometry_id]->normals()[triangle] : PackedNormal{}, n_out + 3 * i);
  }
  void add_to(py::dict& answer) const {
    answer["geometry_ids"] = geometry;
    answer["primitive_ids"] = primitive;
    if (uv_out) answer["primitive_uvs"] = uvs;
    if (n_out) answer["primitive_normals"] = normals;
  }
};

// backend="cpu" or "vulkan" (ValueError otherwise): whether the GPU casts.
bool on_gpu(const std::string& backend) {
  if (backend != "cpu" && backend != "vulkan") throw py::value_error("backend \"" + backend + "\": cpu or vulkan");
  return backend == "vulkan";
}

// A ray's every hit where the first walk kept the nearest kMaxHitsLimit of
// `found`: walked again from the farthest t kept, as often as it takes.
// The hits at that t are taken from the new walk alone (which of them a
// full row kept is the walk's choice), so each hit is listed once. Returns
// the row; `dropped` counts what is left out when more than kMaxHitsLimit
// hits lie at one t (no later walk could get past them).
template <class Target, class Record>
std::vector<Record> whole_row(const Target& target, const RayArrays& rays, size_t i, std::span<const Record> kept,
                              uint32_t found, uint64_t& dropped) {
  using RayRecord = typename Target::RayRecord;
  std::vector<Record> row(kept.begin(), kept.end());
  RayRecord ray;
  target.pack(rays, i, 1, &ray);
  HitRows<Record> more;
  more.max_hits = kMaxHitsLimit;
  while (found > kMaxHitsLimit) {
    const float from = row.back().t;
    const size_t before = row.size();
    while (!row.empty() && row.back().t == from) row.pop_back();
    const bool stuck = row.size() + kMaxHitsLimit <= before;  // a whole row at one t
    // A walk compares t_min with the t it reports: every hit reported at
    // `from` is found again from there.
    ray.tmin = from;
    more.clear();
    target.trace_all(std::span<const RayRecord>(&ray, 1), more, HitOutputs::Uv, Cull::None);
    const std::span<const Record> next = more.row(0);
    row.insert(row.end(), next.begin(), next.end());
    found = more.found[0];
    if (stuck && found > kMaxHitsLimit) {
      dropped += found - kMaxHitsLimit;
      break;
    }
  }
  return row;
}


// The layout each geometry is built in. By default the exact cluster
// (OctTreeCompressed/ClusterFloat3SOA8): every answer is the float mesh's,
// as Open3D's are. `max_error` (a fraction of the mesh's diagonal) lets the
// compact cluster (ClusterBitPackSOA8, about 30% fewer bytes) in where its
// stated bound is within it; `layout` names one outright.
struct GeometryLayout {
  std::optional<std::string> named;
  double max_error = 0;

  // Refuses a mistyped layout name or a max_error that is no fraction, when
  // the scene is made (or unpickled), not at its first add_triangles.
  static GeometryLayout checked(std::optional<std::string> named, double max_error) {
    if (!(max_error >= 0) || !std::isfinite(max_error))
      throw py::value_error("RaycastingScene: max_error must be a finite fraction >= 0, not " + std::to_string(max_error));
    if (named) parse_layout_name(*named);
    return {std::move(named), max_error};
  }

  std::vector<uint8_t> build(const Mesh& mesh, BuildOptions options, const std::string& name) const {
    if (named) {
      options.layout = parse_layout_name(*named);
      std::vector<uint8_t> blob = build_blob(mesh, options, name);
      const double bound = relative_error_bound(blob, mesh.bounds().diagonal());
      if (max_error > 0 && bound > max_error)
        throw InputError(name + ": layout " + *named + " states an error of " + std::to_string(bound) +
                         " of the diagonal, over max_error=" + std::to_string(max_error));
      return blob;
    }
    // The compact cluster is built only where its grid's half step is
    // within max_error: a second build (the exact cluster after it) is left
    // for a max_error within a rounding of the largest coordinate above that.
    const Layout compact{TreeFormat::OctTreeCompressed, TriangleFormat::ClusterBitPackSOA8};
    if (max_error > 0 && relative_error_floor(mesh, uint32_t(compact.triangles)) <= max_error) {
      options.layout = compact;
      std::vector<uint8_t> blob = build_blob(mesh, options, name);
      if (relative_error_bound(blob, mesh.bounds().diagonal()) <= max_error) return blob;
    }
    options.layout = {TreeFormat::OctTreeCompressed, TriangleFormat::ClusterFloat3SOA8};
    return build_blob(mesh, options, name);
  }
};

class RaycastingScene {
 public:
  RaycastingScene(uint32_t build_threads, GeometryLayout layout) : build_threads_(build_threads), layout_(std::move(layout)) {}
  uint32_t add_triangles(const py::handle& vertices, const py::handle& triangles) {
    double lo[3], hi[3], centre[3];
    vertex_box(vertices, lo, hi);
    storage_centre(lo, hi, centre);
    std::string name;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      name = "geometry " + std::to_string(geometries_.size());
    }
    std::vector<PackedNormal> normals;
    std::vector<uint8_t> blob;
    {
      // The mesh's copy lives in this block alone: freed before the trim
      // below, it is not left in the process's heap.
      Mesh mesh = mesh_from_arrays(vertices, triangles, centre);
      py::gil_scoped_release release;
      BuildOptions options;
      options.threads = build_threads_;
      blob = layout_.build(mesh, options, name);
      // Open3D's primitive_normals are the mesh's: kept now where the layout
      // moves vertices (their normals would differ), else made from the
      // blob when first asked for (Geometry).
      if (moves_vertices(layout::header_of(blob.data()).triangle_format)) {
        normals.resize(mesh.triangle_count());
        for (size_t i = 0; i < mesh.triangle_count(); ++i) {
          const Vec3 a = mesh.corner(i, 0), b = mesh.corner(i, 1), c = mesh.corner(i, 2);
          const float fa[3] = {a.x, a.y, a.z}, fb[3] = {b.x, b.y, b.z}, fc[3] = {c.x, c.y, c.z};
          normals[i] = normal_of(fa, fb, fc);
        }
      }
    }
    blob.shrink_to_fit();  // the builder's spare capacity would be memory the scene holds
    uint32_t id;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      id = add_geometry(std::move(blob), std::move(normals), centre, name);
    }
#ifdef __GLIBC__
    // The build's scratch (several times the blob) and the mesh's copy are
    // freed, but glibc keeps freed pages in the process unless asked (once
    // large blocks have been freed, it serves the next ones from its heap
    // rather than from their own mappings): hand them back, so a process's
    // memory is the structures it holds.
    malloc_trim(0);
#endif
    return id;
  }

  // A scene of the same geometries, each blob and its normals copied (copy
  // and deepcopy in Python): adding to one leaves the other as it was.
  std::unique_ptr<RaycastingScene> copy() const {
    auto twin = std::make_unique<RaycastingScene>(build_threads_, layout_);
    std::lock_guard<std::mutex> lock(mutex_), twin_lock(twin->mutex_);
    for (size_t g = 0; g < geometries_.size(); ++g) {
      const Geometry& from = *geometries_[g];
      const std::span<const uint8_t> bytes = from.view.bytes();
      const std::span<const PackedNormal> normals = from.held_normals();
      twin->add_geometry(std::vector<uint8_t>(bytes.begin(), bytes.end()),
                         std::vector<PackedNormal>(normals.begin(), normals.end()), from.centre,
                         "geometry " + std::to_string(g));
    }
    return twin;
  }

  // What a pickled scene holds: (2, build threads, layout name or None,
  // max_error, geometries), each geometry (blob bytes, normals bytes,
  // centre, normals' checksum): the structures as they are, not the meshes,
  // so nothing is built again and the answers are the same bits. The
  // normals are pickled only where the layout moves the mesh's vertices (the
  // mesh's own, which no blob holds), under a checksum of them and their
  // blob, as strong as the blob's own; any other geometry's are made from
  // its blob again where it arrives (its checksum and validation cover
  // them), so a pickle's word about them is never needed.
  py::tuple state() const {
    py::list geometries;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& g : geometries_) {
      const std::span<const uint8_t> bytes = g->view.bytes();
      const bool kept = moves_vertices(uint32_t(g->view.layout().triangles));
      const std::span<const PackedNormal> normals = kept ? g->held_normals() : std::span<const PackedNormal>();
      const std::span<const uint8_t> normal_bytes(reinterpret_cast<const uint8_t*>(normals.data()), normals.size_bytes());
      geometries.append(py::make_tuple(
          py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
          py::bytes(reinterpret_cast<const char*>(normal_bytes.data()), normal_bytes.size()),
          py::make_tuple(g->centre[0], g->centre[1], g->centre[2]), normals_checksum(bytes, normal_bytes)));
    }
    return py::make_tuple(2, build_threads_, layout_.named ? py::object(py::str(*layout_.named)) : py::object(py::none()),
                          layout_.max_error, geometries);
  }

  // The scene of a state(): every blob validated as a loaded one is. A state
  // of version 1 (the normals pickled for every geometry, no checksum) still
  // loads: a geometry's normals made from its blob where the layout keeps
  // the mesh's floats, the pickled ones taken where it moves them (nothing
  // there to check them by).
  static std::unique_ptr<RaycastingScene> from_state(const py::object& pickled_state) {
    const std::string of = "RaycastingScene: the pickled state";
    const py::tuple state = pickled<py::tuple>(pickled_state, of, "a tuple");
    const long long version = state.size() == 5 ? pickled<long long>(state[0], of + "'s version", "an int") : 0;
    if (version != 1 && version != 2)
      throw py::value_error("RaycastingScene: a pickled state of another version of meshcast");
    auto scene = std::make_unique<RaycastingScene>(
        pickled<uint32_t>(state[1], of + "'s build threads", "an int from 0 to 2^32 - 1"),
        GeometryLayout::checked(pickled<std::optional<std::string>>(state[2], of + "'s layout", "a str or None"),
                                pickled<double>(state[3], of + "'s max_error", "a float")));
    std::lock_guard<std::mutex> lock(scene->mutex_);
    for (const py::handle item : pickled<py::list>(state[4], of + "'s geometries", "a list")) {
      const std::string name = "geometry " + std::to_string(scene->geometries_.size());
      const std::string what = of + "'s " + name;
      const py::tuple g = pickled<py::tuple>(item, what, "a tuple");
      if (g.size() != (version == 1 ? 3u : 4u))
        throw py::value_error("RaycastingScene: " + name + " of the pickled state is malformed");
      const std::string_view blob_bytes = pickled<py::bytes>(g[0], what + "'s blob", "bytes"),
                             normal_bytes = pickled<py::bytes>(g[1], what + "'s normals", "bytes");
      const auto centre = pickled<std::vector<double>>(g[2], what + "'s centre", "a tuple of 3 floats");
      if (centre.size() != 3 || !std::isfinite(centre[0]) || !std::isfinite(centre[1]) || !std::isfinite(centre[2]))
        throw py::value_error("RaycastingScene: " + name + " of the pickled state has a centre that is not 3 finite numbers");
      const std::span<const uint8_t> blob(reinterpret_cast<const uint8_t*>(blob_bytes.data()), blob_bytes.size()),
          normal_span(reinterpret_cast<const uint8_t*>(normal_bytes.data()), normal_bytes.size());
      if (version == 2 && pickled<uint32_t>(g[3], what + "'s checksum", "an int from 0 to 2^32 - 1") !=
                              normals_checksum(blob, normal_span))
        throw py::value_error("RaycastingScene: " + name + " of the pickled state has normals or a blob that do not "
                              "match its checksum (a damaged or altered pickle)");
      // Whether the layout moves the mesh's vertices, read from the header
      // the blob is validated by as it joins the scene (InputError naming
      // what is wrong; one too short for a header is refused there).
      layout::BlobHeader header{};
      if (blob.size() >= sizeof header) std::memcpy(&header, blob.data(), sizeof header);
      const bool kept = blob.size() >= sizeof header && moves_vertices(header.triangle_format);
      // Made from the blob when asked for where the layout keeps the mesh's
      // floats; a version-1 state's are those same normals, and not read.
      if (!kept && version == 2 && !normal_bytes.empty())
        throw py::value_error("RaycastingScene: " + name + " of the pickled state has normals; its layout's are "
                              "made from its blob");
      std::vector<PackedNormal> normals(kept ? normal_bytes.size() / sizeof(PackedNormal) : 0);
      std::memcpy(normals.data(), normal_bytes.data(), normals.size() * sizeof(PackedNormal));
      // A scene left half made by an error below is dropped.
      scene->add_geometry(std::vector<uint8_t>(blob_bytes.begin(), blob_bytes.end()), std::move(normals), centre.data(),
                          name);
      const uint32_t triangles = scene->geometries_.back()->view.triangle_count();
      if (kept && normal_bytes.size() != size_t(triangles) * sizeof(PackedNormal))
        throw py::value_error("RaycastingScene: " + name + " of the pickled state has " +
                              std::to_string(normal_bytes.size()) + " bytes of normals for " +
                              std::to_string(triangles) + " triangles");
    }
    return scene;
  }

  py::dict cast_rays(const py::handle& rays_in, long long nthreads, bool uvs, bool normals, const py::object& out,
                     const std::string& backend) {
    RayArrays rays = rays_from_six(rays_in);
    const uint32_t threads = thread_count(nthreads);
    const bool gpu = on_gpu(backend);
    check_out(out, {"t_hit", "geometry_ids", "primitive_ids", "primitive_uvs", "primitive_normals"});
    py::array_t<float> t = answer_array<float>(out, "t_hit", rays.shape);
    float* t_out = t.mutable_data();
    PrimitiveArrays primitives(rays.shape, out, uvs, normals);
    const HitOutputs outputs = uvs ? HitOutputs::Uv : HitOutputs::None;
    Refused refused;
    {
      py::gil_scoped_release release;
      const auto write = [&](const Geometries& geometries) {
        return [&, of = &geometries](size_t i, const auto& h) {
          t_out[i] = h.t;
          primitives.write(i, geometry_of(h), h.triangle, h.u, h.v, *of);
        };
      };
      if (gpu) {
        cast_on_gpu(rays, Query::Closest, outputs, write);
      } else {
        const Frame f = frame();
        refused = f.visit([&](const auto& target) {
          return cast_hits(target, rays, Query::Closest, Cull::None, outputs, threads, write(*f.geometries));
        });
      }
    }
    raise_for_refused(rays, refused, false, Invalid::Miss);
    py::dict answer;
    answer["t_hit"] = t;
    primitives.add_to(answer);
    return answer;
  }

  py::array test_occlusions(const py::handle& rays_in, const py::handle& tnear, const py::handle& tfar,
                            long long nthreads, const py::object& out_array, const std::string& backend) {
    RayArrays rays = rays_from_six(rays_in);
    set_segment(rays, tnear, tfar);
    const uint32_t threads = thread_count(nthreads);
    const bool gpu = on_gpu(backend);
    py::dict out;
    if (!out_array.is_none()) out["out"] = out_array;
    py::array_t<bool> occluded = answer_array<bool>(out, "out", rays.shape);
    bool* answer = occluded.mutable_data();
    const auto write = [answer](const Geometries&) {
      return [answer](size_t i, const auto& h) { answer[i] = h.triangle != kNoHit; };
    };
    Refused refused;
    {
      py::gil_scoped_release release;
      if (gpu)
        cast_on_gpu(rays, Query::Any, HitOutputs::None, write);
      else
        refused = frame().visit([&](const auto& target) {
          return cast_hits(target, rays, Query::Any, Cull::None, HitOutputs::None, threads, write({}));
        });
    }
    raise_for_refused(rays, refused, false, Invalid::Miss);
    return occluded;
  }

  py::array count_intersections(const py::handle& rays_in, long long nthreads) {
    const RayArrays rays = rays_from_six(rays_in);
    py::array_t<int32_t> counts(rays.shape);
    int32_t* out = counts.mutable_data();
    every_hit(rays, HitOutputs::None, nthreads, [&](const auto& for_each_row, const CornersOf& corners_of) {
      for_each_row([&](size_t i, uint64_t dropped, auto row) {
        uint64_t n = dropped;  // left out of the row (at one t): each counted
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
    every_hit(rays, HitOutputs::Uv, nthreads, [&](const auto& for_each_row, const CornersOf& corners_of) {
      for_each_row([&](size_t i, uint64_t row_dropped, auto row) {
        if (listed.size() > UINT32_MAX) return;  // raised below
        splits_of[i] = uint32_t(listed.size());
        dropped += row_dropped;
        crossings(row, rays.ray(i).dir, corners_of, [&listed](const auto& h) { listed.push_back(scene_hit(h)); });
      });
      splits_of[rays.count] = uint32_t(std::min<size_t>(listed.size(), UINT32_MAX));
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
                                ("list_intersections: " + std::to_string(dropped) + " hits were left out: more than " +
                                 std::to_string(kMaxHitsLimit) + " of one ray at one t (count_intersections counts them)")
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
  // compute_closest_points): the scene's point query, each geometry's blob
  // walked in its frame, at one distance the lower geometry id.
  py::dict compute_closest_points(const py::handle& points_in, long long nthreads) {
    const PointArrays points = points_from_array(points_in, "query_points");
    py::array_t<float> point(shape_with(points.shape, 3));
    float* p_out = point.mutable_data();
    PrimitiveArrays primitives(points.shape);
    {
      py::gil_scoped_release release;
      const Frame f = frame();
      // An instance is its geometry (kInvalidId: none).
      f.nearest(points, thread_count(nthreads), [&](size_t i, const SceneClosestPoint& c) {
        for (int k = 0; k < 3; ++k) p_out[3 * i + k] = c.instance == kInvalidId ? NAN : float(c.point[k]);
        primitives.write(i, c.instance, c.triangle, c.u, c.v, *f.geometries);
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
      f.nearest(points, thread_count(nthreads), [&](size_t i, const SceneClosestPoint& c) { out[i] = float(c.distance); });
    }
    return distance;
  }

  // The scene's generalized winding number at each point: every
  // geometry's, summed (WindingNumbers, in each geometry's frame), and
  // the bound on its error, expanded to `tolerance`.
  py::dict winding_numbers(const py::handle& points_in, long long nthreads, double tolerance) {
    const PointArrays points = points_from_array(points_in, "query_points");
    if (!(tolerance > 0 && tolerance < 1))
      throw py::value_error("tolerance: " + std::to_string(tolerance) + " is not in (0, 1)");
    py::array_t<double> w(points.shape), bound(points.shape);
    double* w_out = w.mutable_data();
    double* bound_out = bound.mutable_data();
    {
      py::gil_scoped_release release;
      for_each_winding_chunk(points, nthreads, [&](const Geometries& geometries, size_t begin, size_t n) {
        const std::vector<WindingNumbers::Answer> sum = summed(geometries, points, begin, n, tolerance);
        for (size_t i = 0; i < n; ++i) w_out[begin + i] = sum[i].w, bound_out[begin + i] = sum[i].bound;
      });
    }
    py::dict answer;
    answer["winding_number"] = w;
    answer["bound"] = bound;
    return answer;
  }

  // Whether the scene's winding number is above 1/2 in magnitude at each
  // point: summed loosely first (a bound of a few tenths decides the
  // points near 0 or 1, most of them), then tightly where that leaves it
  // in doubt, then over every triangle where the tight bound still does.
  py::array winding_inside(const py::handle& points_in, long long nthreads) {
    const PointArrays points = points_from_array(points_in, "query_points");
    py::array_t<bool> in(points.shape);
    bool* in_out = in.mutable_data();
    {
      py::gil_scoped_release release;
      for_each_winding_chunk(points, nthreads, [&](const Geometries& geometries, size_t begin, size_t n) {
        std::vector<size_t> doubt(n);
        for (size_t i = 0; i < n; ++i) doubt[i] = begin + i;
        for (const double tolerance : WindingNumbers::kInsideTolerances) {
          std::vector<size_t> still;
          // The points in doubt, one at a time (n = 1 from each).
          for (const size_t i : doubt) {
            const WindingNumbers::Answer a = summed(geometries, points, i, 1, tolerance)[0];
            if (std::fabs(std::fabs(a.w) - 0.5) > a.bound)
              in_out[i] = std::fabs(a.w) > 0.5;
            else
              still.push_back(i);
          }
          doubt.swap(still);
        }
        for (const size_t i : doubt) {
          double total = 0;
          for (const auto& g : geometries) total += g->winding().exact(local_point(points, i, g->centre));
          in_out[i] = std::fabs(total) > 0.5;
        }
      });
    }
    return in;
  }
  // The bytes the scene holds: every geometry's blob, its normals (and the
  // corners' table, once a ray through an edge made it, and the winding
  // numbers' clusters, once a call asked for them) and the top level over
  // the instances.
  size_t nbytes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t bytes = scene_.owned_blob_bytes() + scene_.top_level_bytes();
    for (const auto& g : geometries_)
      bytes += g->held_normals().size_bytes() + g->corners.nbytes() + g->winding_bytes();
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
    // The nearest point of any geometry to each point, use(i, nearest) for
    // each (on the call's threads, in any order). One geometry's blob is
    // walked alone, with each point in its frame as float (the centre
    // subtracted in double): the scene's answer where the centre is 0 (the
    // triangles it places in the world are then the blob's own), within
    // the point's float rounding elsewhere, without the scene's top level
    // and its placing of every triangle tested (a third of a point's time
    // on a mesh of large, flat triangles). A point the float frame cannot
    // take (beyond 3.4e38 of the centre) is left to the scene.
    template <class Use>
    void nearest(const PointArrays& points, uint32_t threads, const Use& use) const {
      if (single) {
        std::vector<ClosestPoint> found;
        bool in_range = true;
        try {
          nearest_points(*single, centre, points, INFINITY, threads, found);
        } catch (const std::invalid_argument&) {
          in_range = false;
        }
        if (in_range) {
          for (size_t i = 0; i < points.count; ++i) {
            const ClosestPoint& c = found[i];
            SceneClosestPoint s;
            if (c.triangle != kNoHit) {
              s.instance = 0, s.triangle = c.triangle, s.distance = c.distance, s.u = c.u, s.v = c.v;
              for (int k = 0; k < 3; ++k) s.point[k] = double(c.point[k]) + centre[k];
            }
            use(i, s);
          }
          return;
        }
      }
      scene_nearest_points(*target.frame, points, INFINITY, 0xFF, threads, use);
    }
  };
  Frame frame() {
    std::lock_guard<std::mutex> lock(mutex_);
    return frame_locked();
  }
  Frame frame_locked() {
    if (changed_) {
      scene_.commit();
      committed_ = std::make_shared<const Geometries>(geometries_);
      changed_ = false;
    }
    Frame f{SceneTarget(scene_, 0xFF), committed_};
    if (committed_->size() == 1) f.single = &(*committed_)[0]->view, f.centre = (*committed_)[0]->centre;
    return f;
  }
  // backend="vulkan": the rays in one batch through the host layer's scene
  // method on the GPU, each hit handed to write(geometries)(i, hit).
  // Without the GIL. A ray that is not one is the GPU's miss.
  template <class Write>
  void cast_on_gpu(const RayArrays& rays, Query query, HitOutputs outputs, const Write& write) {
    if (rays.count == 0) return;
    std::vector<RayD> world(rays.count);
    rays.pack(0, rays.count, world.data());
    std::vector<SceneHit> hits(rays.count);
    std::unique_lock<std::mutex> gpu_lock;
    host::Caster& caster = gpu_.get(
        outputs, [](const host::CasterOptions& options) { return std::make_unique<host::Caster>(options); }, gpu_lock);
    host::Ticket ticket;
    std::shared_ptr<const Geometries> geometries;
    {
      std::lock_guard<std::mutex> lock(mutex_);  // the scene as committed now, no edit meanwhile
      geometries = frame_locked().geometries;
      ticket = caster.submit(scene_, world, {query, Cull::None, 0xFF});
    }
    caster.wait(ticket, hits);
    const auto each = write(*geometries);
    for (size_t i = 0; i < rays.count; ++i) each(i, hits[i]);
  }
  // Every hit of every ray, handed to use(for_each_row, corners_of)
  // without the GIL: for_each_row(row) calls row(i, dropped, hits) for
  // each ray i in order, its hits nearest first (a ray of more than
  // kMaxHitsLimit walked again for the rest: whole_row), for the
  // crossings to be told from with the corners of the frame they were
  // found in. A ray that is not one has no hits.
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
        const auto for_each_row = [&](const auto& row) {
          all.for_each_row([&](size_t i, uint32_t found, auto kept) {
            if (found <= kept.size()) return row(i, uint64_t(0), kept);
            uint64_t dropped = 0;
            const auto whole = whole_row(target, rays, i, kept, found, dropped);
            row(i, dropped, decltype(kept)(whole.data(), whole.size()));
          });
        };
        use(for_each_row, CornersOf([&geometries](uint32_t g) -> const TriangleCorners& { return geometries[g]->corners; }));
      });
    }
    raise_for_refused(rays, refused, false, Invalid::Miss);
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
    changed_ = true;
    return id.index;
  }
  // A point in a geometry's frame, as its blob stores the mesh.
  static Vec3 local_point(const PointArrays& points, size_t i, const double centre[3]) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = float(points.coordinate(i, k) - centre[k]);
    return p;
  }
  // Points begin..begin + n: every geometry's winding number summed.
  static std::vector<WindingNumbers::Answer> summed(const Geometries& geometries, const PointArrays& points,
                                                    size_t begin, size_t n, double tolerance) {
    std::vector<Vec3> local(n);
    std::vector<WindingNumbers::Answer> part(n), sum(n);
    for (const auto& g : geometries) {
      for (size_t i = 0; i < n; ++i) local[i] = local_point(points, begin + i, g->centre);
      g->winding().evaluate(local, part, tolerance);
      for (size_t i = 0; i < n; ++i) sum[i].w += part[i].w, sum[i].bound += part[i].bound;
    }
    return sum;
  }
  // chunk(geometries, begin, n) for the points in chunks on the call's
  // threads, the geometries' clusters made first. Without the GIL.
  template <class Chunk>
  void for_each_winding_chunk(const PointArrays& points, long long nthreads, const Chunk& chunk) {
    const uint32_t threads = thread_count(nthreads);
    const Frame f = frame();
    const Geometries& geometries = *f.geometries;
    for (const auto& g : geometries) g->winding();  // made once, before the threads
    const Chunks plan = plan_chunks(points.count, threads);
    for_each_chunk(plan, threads, [&](size_t c) { chunk(geometries, plan.begin(c), plan.end(c) - plan.begin(c)); });
  }
  const uint32_t build_threads_;  // BuildOptions::threads of add_triangles (0: every core)
  const GeometryLayout layout_;
  mutable std::mutex mutex_;  // the geometries added, and the frame committed
  Scene scene_;
  Geometries geometries_;  // every geometry's, added so far
  std::shared_ptr<const Geometries> committed_ = std::make_shared<const Geometries>();
  bool changed_ = false;
  VulkanCasters gpu_;  // backend="vulkan"'s scene casters, made on first use (and gone before the scene)
};

}  // namespace

void register_raycasting_scene(py::module_& m) {
  py::class_<RaycastingScene>(m, "_RaycastingScene")
      .def(py::init([](long long nthreads, std::optional<std::string> layout, double max_error) {
             // Open3D's: the threads its build uses (0: every core).
             return std::make_unique<RaycastingScene>(nthreads == 0 ? 0 : thread_count(nthreads),
                                                      GeometryLayout::checked(std::move(layout), max_error));
           }),
           py::arg("nthreads") = 0, py::arg("layout") = py::none(), py::arg("max_error") = 0.0)
      .def("add_triangles", &RaycastingScene::add_triangles, py::arg("vertex_positions"), py::arg("triangle_indices"))
      .def("cast_rays", &RaycastingScene::cast_rays, py::arg("rays"), py::arg("nthreads") = 0,
           py::arg("uvs") = true, py::arg("normals") = true, py::arg("out") = py::none(), py::arg("backend") = "cpu")
      .def("test_occlusions", &RaycastingScene::test_occlusions, py::arg("rays"), py::arg("tnear") = 0.0,
           py::arg("tfar") = INFINITY, py::arg("nthreads") = 0, py::arg("out") = py::none(),
           py::arg("backend") = "cpu")
      .def("count_intersections", &RaycastingScene::count_intersections, py::arg("rays"), py::arg("nthreads") = 0)
      .def("list_intersections", &RaycastingScene::list_intersections, py::arg("rays"), py::arg("nthreads") = 0)
      .def("compute_closest_points", &RaycastingScene::compute_closest_points, py::arg("query_points"),
           py::arg("nthreads") = 0)
      .def("compute_distance", &RaycastingScene::compute_distance, py::arg("query_points"), py::arg("nthreads") = 0)
      .def("winding_numbers", &RaycastingScene::winding_numbers, py::arg("query_points"), py::arg("nthreads") = 0,
           py::arg("tolerance") = 1e-2)
      .def("winding_inside", &RaycastingScene::winding_inside, py::arg("query_points"), py::arg("nthreads") = 0)
      .def("copy", &RaycastingScene::copy)
      .def(py::pickle([](const RaycastingScene& s) -> py::object { return s.state(); },
                      [](const py::object& state) { return RaycastingScene::from_state(state); }))
      .def_property_readonly("nbytes", &RaycastingScene::nbytes);
  m.attr("INVALID_ID") = kInvalidId;
}

}  // namespace meshcast::python
