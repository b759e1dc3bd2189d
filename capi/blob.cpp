// The C API's blobs: building, loading, saving, and their casts and point
// queries (meshcast/meshcast_c.h).
#include <atomic>
#include <cmath>
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "builder/auto_layout.h"
#include "builder/error_bounds.h"
#include "capi/casts.h"
#include "layout/blob_format.h"
#include "capi/handles.h"
#include "capi/status.h"
#include "meshcast/build.h"
#include "meshcast/closest_point.h"

using namespace meshcast;
using namespace meshcast::capi;

// The API's first versions of the sized structs (their size then).
namespace {
constexpr size_t kMeshV1 = sizeof(meshcast_mesh);
constexpr size_t kBuildOptionsV1 = sizeof(meshcast_build_options);
constexpr size_t kBlobInfoV1 = sizeof(meshcast_blob_info);

static_assert(sizeof(meshcast_closest_point) == sizeof(ClosestPoint) &&
              offsetof(meshcast_closest_point, distance) == offsetof(ClosestPoint, distance) &&
              offsetof(meshcast_closest_point, triangle) == offsetof(ClosestPoint, triangle) &&
              offsetof(meshcast_closest_point, u) == offsetof(ClosestPoint, u));
static_assert(sizeof(Vec3) == 3 * sizeof(float));

meshcast_mesh mesh_defaults() {
  meshcast_mesh m{};
  m.struct_size = sizeof m;
  m.index_bits = 32;
  return m;
}

meshcast_build_options build_defaults() {
  meshcast_build_options o{};
  o.struct_size = sizeof o;
  o.triangle_ids = 1;
  return o;
}

// A handle over bytes kept by `owner` (null: the caller's).
std::unique_ptr<meshcast_blob> blob_over(std::span<const uint8_t> bytes, std::shared_ptr<const void> owner,
                                         std::shared_ptr<const MappedBlob> mapped, const std::string& name) {
  BlobView view(bytes, name);
  auto blob = std::unique_ptr<meshcast_blob>(
      new meshcast_blob{std::move(owner), std::move(mapped), view, name, layout_name(view.layout())});
  return blob;
}

std::unique_ptr<meshcast_blob> blob_of(std::vector<uint8_t> bytes, const std::string& name) {
  auto kept = std::make_shared<const std::vector<uint8_t>>(std::move(bytes));
  return blob_over(*kept, kept, nullptr, name);
}

}  // namespace

extern "C" {

void meshcast_mesh_init(meshcast_mesh* mesh) {
  if (mesh) *mesh = mesh_defaults();
}

void meshcast_build_options_init(meshcast_build_options* options) {
  if (options) *options = build_defaults();
}

meshcast_status meshcast_blob_build(const meshcast_mesh* mesh, const meshcast_build_options* options,
                                    meshcast_blob** out) {
  return guarded("meshcast_blob_build", [&] {
    *required(out, "out") = nullptr;
    const meshcast_mesh m = sized(required(mesh, "mesh"), mesh_defaults(), kMeshV1, "mesh");
    const meshcast_build_options o = sized(options, build_defaults(), kBuildOptionsV1, "options");
    if (m.index_bits != 16 && m.index_bits != 32)
      throw UsageError("mesh->index_bits " + std::to_string(m.index_bits) + ": 16 or 32");
    MeshView view;
    view.positions = m.vertices;
    view.vertex_count = size_t(m.vertex_count);
    view.vertex_stride = m.vertex_stride ? size_t(m.vertex_stride) : 3 * sizeof(float);
    view.indices = m.indices;
    view.triangle_count = size_t(m.triangle_count);
    view.index_type = m.index_bits == 16 ? IndexType::Uint16 : IndexType::Uint32;
    view.triangle_stride = size_t(m.triangle_stride);
    const std::string name = o.name ? o.name : "mesh";
    const bool automatic = o.layout && std::string(o.layout) == "auto";
    if (!automatic && (o.max_bytes_per_triangle != 0 || o.max_error != 0 || o.goal_memory != 0))
      throw UsageError("options: max_bytes_per_triangle, max_error and goal_memory choose among layouts: they need "
                       "layout \"auto\"");
    if (!(o.max_bytes_per_triangle >= 0) || !(o.max_error >= 0))
      throw UsageError("options: max_bytes_per_triangle and max_error are limits from 0 (none)");
    if (automatic) {
      AutoLimits limits;
      limits.goal = o.goal_memory ? AutoGoal::Memory : AutoGoal::Speed;
      limits.max_bytes_per_triangle = o.max_bytes_per_triangle;
      limits.max_error = o.max_error;
      limits.triangle_ids = o.triangle_ids != 0;
      limits.build_threads = o.threads;
      hand_out(blob_of(choose_layout(copy_mesh(view, name), limits, name).blob, name), out);
      return;
    }
    BuildOptions b;
    if (o.layout) b.layout = parse_layout_name(o.layout);
    b.threads = o.threads;
    b.triangle_ids = o.triangle_ids != 0;
    hand_out(blob_of(build_blob(view, b, name), name), out);
  });
}

meshcast_status meshcast_blob_load(const char* path, uint32_t flags, meshcast_blob** out) {
  return guarded("meshcast_blob_load", [&] {
    *required(out, "out") = nullptr;
    const std::string file = required(path, "path");
    if (flags & ~MESHCAST_LOAD_MAP) throw UsageError("flags " + std::to_string(flags) + ": 0 or MESHCAST_LOAD_MAP");
    if (flags & MESHCAST_LOAD_MAP) {
      auto mapped = std::make_shared<const MappedBlob>(file);
      hand_out(blob_over(mapped->bytes(), mapped, mapped, file), out);
    } else {
      hand_out(blob_of(load_blob(file), file), out);
    }
  });
}

meshcast_status meshcast_blob_from_memory(const void* bytes, uint64_t size, uint32_t flags, const char* name,
                                          meshcast_blob** out) {
  return guarded("meshcast_blob_from_memory", [&] {
    *required(out, "out") = nullptr;
    const auto* data = static_cast<const uint8_t*>(array(bytes, size, "bytes"));
    const std::string label = name ? name : "blob in memory";
    if (flags == MESHCAST_MEMORY_COPY)
      hand_out(blob_of(std::vector<uint8_t>(data, data + size), label), out);
    else if (flags == MESHCAST_MEMORY_BORROW)
      hand_out(blob_over({data, size_t(size)}, nullptr, nullptr, label), out);
    else
      throw UsageError("flags " + std::to_string(flags) + ": MESHCAST_MEMORY_COPY or MESHCAST_MEMORY_BORROW");
  });
}

meshcast_status meshcast_blob_save(const meshcast_blob* blob, const char* path) {
  return guarded("meshcast_blob_save", [&] { save_blob(required(path, "path"), live(blob, "blob")->view.bytes()); });
}

meshcast_status meshcast_blob_bytes(const meshcast_blob* blob, const void** bytes, uint64_t* size) {
  return guarded("meshcast_blob_bytes", [&] {
    const std::span<const uint8_t> b = live(blob, "blob")->view.bytes();
    *required(bytes, "bytes") = b.data();
    *required(size, "size") = b.size();
  });
}

meshcast_status meshcast_blob_info_get(const meshcast_blob* blob, meshcast_blob_info* info) {
  return guarded("meshcast_blob_info_get", [&] {
    const auto b = live(blob, "blob");
    meshcast_blob_info* to = required(info, "info");
    if (to->struct_size < kBlobInfoV1)
      throw UsageError("info->struct_size " + std::to_string(to->struct_size) + " is less than the " +
                       std::to_string(kBlobInfoV1) + " bytes of its first version");
    meshcast_blob_info i{};
    i.struct_size = to->struct_size;
    i.triangle_count = b->view.triangle_count();
    i.bytes = b->view.bytes().size();
    i.layout = b->layout.c_str();
    const layout::BlobHeader& h = layout::header_of(b->view.bytes().data());
    double diagonal2 = 0;
    for (int k = 0; k < 3; ++k) diagonal2 += std::pow(double(h.bounds_max[k]) - h.bounds_min[k], 2);
    i.error_bound = relative_error_bound(b->view.bytes(), std::sqrt(diagonal2));
    std::memcpy(static_cast<void*>(to), &i, std::min<size_t>(to->struct_size, sizeof i));
  });
}

meshcast_status meshcast_blob_release(meshcast_blob* blob) {
  return guarded("meshcast_blob_release", [&] { release(blob, "blob"); });
}

meshcast_status meshcast_blob_cast(const meshcast_blob* blob, const meshcast_ray* rays, uint64_t ray_count,
                                   const meshcast_query* query, meshcast_hit* hits, uint64_t hit_capacity,
                                   uint64_t* not_walkable) {
  return guarded("meshcast_blob_cast", [&] {
    const auto b = live(blob, "blob");
    cast_batch(rays, ray_count, query, hits, hit_capacity, not_walkable,
               [&](std::span<const Ray> r, std::span<Hit> h, const CastQuery& q) {
                 return b->view.trace(r, h, q.outputs, q.query, q.cull);
               });
  });
}

meshcast_status meshcast_blob_cast_all(const meshcast_blob* blob, const meshcast_ray* rays, uint64_t ray_count,
                                       const meshcast_query* query, uint32_t max_hits, uint32_t* found,
                                       meshcast_hit* hits, uint64_t hit_capacity, uint64_t* not_walkable) {
  return guarded("meshcast_blob_cast_all", [&] {
    const auto b = live(blob, "blob");
    cast_rows<HitLists>(rays, ray_count, query, max_hits, found, hits, hit_capacity, not_walkable,
                        [&](std::span<const Ray> r, HitLists& lists, const CastQuery& q) {
                          return b->view.trace_all_hits(r, lists, q.outputs, q.cull);
                        });
  });
}

meshcast_status meshcast_blob_closest_points(const meshcast_blob* blob, const float* points, uint64_t point_count,
                                             float max_distance, uint32_t threads, meshcast_closest_point* out,
                                             uint64_t out_capacity) {
  return guarded("meshcast_blob_closest_points", [&] {
    const auto b = live(blob, "blob");
    check_capacity(out_capacity, point_count, "out");
    const auto* p = reinterpret_cast<const Vec3*>(array(points, point_count, "points"));
    auto* o = reinterpret_cast<ClosestPoint*>(array(out, point_count, "out"));
    in_chunks(point_count, threads_of(threads), [&](size_t begin, size_t n) {
      return b->view.closest_points({p + begin, n}, {o + begin, n}, max_distance);
    });
  });
}

}  // extern "C"
