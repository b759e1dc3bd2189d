// The C API's scenes: meshes, instances, commits, casts and point queries
// (meshcast/meshcast_c.h).
#include <array>
#include <memory>
#include <span>
#include <string>

#include "capi/casts.h"
#include "capi/handles.h"
#include "capi/status.h"

using namespace meshcast;
using namespace meshcast::capi;

namespace {

Transform transform_of(const meshcast_transform* t) {
  Transform out;
  if (!t) return out;
  std::copy(t->rotation_scale, t->rotation_scale + 9, out.rotation_scale);
  std::copy(t->translation, t->translation + 3, out.translation);
  return out;
}

uint8_t mask_of(uint32_t mask) {
  if (mask > 0xFF) throw UsageError("mask " + std::to_string(mask) + ": 8 bits (0..255)");
  return uint8_t(mask);
}

bool flag_of(uint32_t flag, const char* what) {
  if (flag > 1) throw UsageError(std::string(what) + " " + std::to_string(flag) + ": 0 or 1");
  return flag == 1;
}

// The C++ ids the C records carry (the scene refuses another scene's);
// reserved stays 0, for a field a later version may give it.
template <class Kind, class Record>
SceneId<Kind> id_of(const Record& id, const char* what) {
  if (id.reserved != 0)
    throw UsageError(std::string(what) + ".reserved " + std::to_string(id.reserved) + ": 0 expected");
  return SceneId<Kind>{id.index, id.scene};
}
MeshId mesh_of(const meshcast_mesh_id& id) { return id_of<MeshKind>(id, "mesh"); }
InstanceId instance_of(const meshcast_instance_id& id) { return id_of<InstanceKind>(id, "instance"); }

}  // namespace

extern "C" {

void meshcast_transform_identity(meshcast_transform* transform) {
  if (!transform) return;
  *transform = meshcast_transform{{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}};
}

meshcast_status meshcast_scene_create(meshcast_scene** out) {
  return guarded("meshcast_scene_create", [&] {
    *required(out, "out") = nullptr;
    hand_out(std::make_unique<meshcast_scene>(), out);
  });
}

meshcast_status meshcast_scene_add_mesh(meshcast_scene* scene, const meshcast_blob* blob, meshcast_mesh_id* mesh) {
  return guarded("meshcast_scene_add_mesh", [&] {
    const auto s = live(scene, "scene");
    const auto b = live(blob, "blob");
    meshcast_mesh_id* out = required(mesh, "mesh");
    // A mapped blob's mapping is shared; any other blob is referenced, its
    // bytes kept alive by the scene.
    MeshId id;
    if (b->mapped) {
      id = s->scene.add_mesh(b->mapped, b->name);
    } else {
      s->owners.push_back(b->owner);
      id = s->scene.add_mesh(b->view, b->name);
    }
    *out = meshcast_mesh_id{id.scene, id.index, 0};
  });
}

meshcast_status meshcast_scene_add_instance(meshcast_scene* scene, meshcast_mesh_id mesh,
                                            const meshcast_transform* transform, uint32_t mask, uint32_t flip_facing,
                                            meshcast_instance_id* instance) {
  return guarded("meshcast_scene_add_instance", [&] {
    const auto s = live(scene, "scene");
    meshcast_instance_id* out = required(instance, "instance");
    const InstanceId id = s->scene.add_instance(mesh_of(mesh), transform_of(transform), mask_of(mask),
                                                flag_of(flip_facing, "flip_facing"));
    *out = meshcast_instance_id{id.scene, id.index, 0};
  });
}

meshcast_status meshcast_scene_set_transform(meshcast_scene* scene, meshcast_instance_id instance,
                                             const meshcast_transform* transform) {
  return guarded("meshcast_scene_set_transform", [&] {
    live(scene, "scene")->scene.set_transform(instance_of(instance), transform_of(required(transform, "transform")));
  });
}

meshcast_status meshcast_scene_set_mask(meshcast_scene* scene, meshcast_instance_id instance, uint32_t mask) {
  return guarded("meshcast_scene_set_mask", [&] { live(scene, "scene")->scene.set_mask(instance_of(instance), mask_of(mask)); });
}

meshcast_status meshcast_scene_set_flip_facing(meshcast_scene* scene, meshcast_instance_id instance, uint32_t flip_facing) {
  return guarded("meshcast_scene_set_flip_facing", [&] {
    live(scene, "scene")->scene.set_flip_facing(instance_of(instance), flag_of(flip_facing, "flip_facing"));
  });
}

meshcast_status meshcast_scene_set_enabled(meshcast_scene* scene, meshcast_instance_id instance, uint32_t enabled) {
  return guarded("meshcast_scene_set_enabled", [&] {
    live(scene, "scene")->scene.set_enabled(instance_of(instance), flag_of(enabled, "enabled"));
  });
}

meshcast_status meshcast_scene_remove_instance(meshcast_scene* scene, meshcast_instance_id instance) {
  return guarded("meshcast_scene_remove_instance", [&] { live(scene, "scene")->scene.remove_instance(instance_of(instance)); });
}

meshcast_status meshcast_scene_commit(meshcast_scene* scene) {
  return guarded("meshcast_scene_commit", [&] { live(scene, "scene")->scene.commit(); });
}

meshcast_status meshcast_scene_cast(const meshcast_scene* scene, const meshcast_ray_d* rays, uint64_t ray_count,
                                    const meshcast_query* query, meshcast_scene_hit* hits, uint64_t hit_capacity,
                                    uint64_t* not_walkable) {
  return guarded("meshcast_scene_cast", [&] {
    const auto s = live(scene, "scene");
    cast_batch(rays, ray_count, query, hits, hit_capacity, not_walkable,
               [&](std::span<const RayD> r, std::span<SceneHit> h, const CastQuery& q) {
                 return s->scene.trace(r, h, q.outputs, q.query, q.cull, q.mask);
               });
  });
}

meshcast_status meshcast_scene_cast_all(const meshcast_scene* scene, const meshcast_ray_d* rays, uint64_t ray_count,
                                        const meshcast_query* query, uint32_t max_hits, uint32_t* found,
                                        meshcast_scene_hit* hits, uint64_t hit_capacity, uint64_t* not_walkable) {
  return guarded("meshcast_scene_cast_all", [&] {
    const auto s = live(scene, "scene");
    cast_rows<SceneHitLists>(rays, ray_count, query, max_hits, found, hits, hit_capacity, not_walkable,
                             [&](std::span<const RayD> r, SceneHitLists& lists, const CastQuery& q) {
                               return s->scene.trace_all_hits(r, lists, q.outputs, q.cull, q.mask);
                             });
  });
}

meshcast_status meshcast_scene_closest_points(const meshcast_scene* scene, const double* points, uint64_t point_count,
                                              double max_distance, uint32_t mask, uint32_t threads,
                                              meshcast_scene_closest_point* out, uint64_t out_capacity) {
  return guarded("meshcast_scene_closest_points", [&] {
    const auto s = live(scene, "scene");
    check_capacity(out_capacity, point_count, "out");
    const uint8_t m = mask_of(mask);
    const auto* p = reinterpret_cast<const std::array<double, 3>*>(array(points, point_count, "points"));
    auto* o = reinterpret_cast<SceneClosestPoint*>(array(out, point_count, "out"));
    in_chunks(point_count, threads_of(threads), [&](size_t begin, size_t n) {
      return s->scene.closest_points({p + begin, n}, {o + begin, n}, max_distance, m);
    });
  });
}

meshcast_status meshcast_scene_release(meshcast_scene* scene) {
  return guarded("meshcast_scene_release", [&] { release(scene, "scene"); });
}

}  // extern "C"
