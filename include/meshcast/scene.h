// Scenes: many placed copies of a few blobs, cast against as one
// world, far larger than a float reaches.
//
//   meshcast::Scene scene;
//   meshcast::MeshId rock = scene.add_mesh(load_blob("rock.mcb"), "rock.mcb");
//   auto tree_file = std::make_shared<const meshcast::MappedBlob>("tree.mcb");
//   meshcast::MeshId tree = scene.add_mesh(tree_file, "tree.mcb");  // mapped, not copied
//   meshcast::InstanceId a = scene.add_instance(rock, transform);  // any number
//   scene.commit();                                                // the frame's changes are done
//   scene.trace(rays, hits);                                       // sees what was committed
//   scene.set_transform(a, moved);  scene.commit();                // next frame
//
// A blob is built once and walked by every instance of it: an instance
// brings a ray into the blob's own frame (the translation subtracted in
// double, then the inverse rotation and scale applied in float) and walks
// it with the walkers BlobView has. The ray's t is the same number in both
// frames (the direction is carried over with the origin), so hits report t
// in the world ray's units.
//
// Edits (add, remove, move, hide, mask) change nothing a trace sees until
// commit(), which builds the top-level tree over the enabled instances'
// world boxes into a new immutable snapshot. A trace holds the snapshot it
// started with, so a commit on another thread never shows it a half-made
// world: traces may run on any threads beside the one thread that edits and
// commits (the edits themselves are for one thread at a time).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/ray.h"

namespace meshcast {

// A ray whose origin is in double precision: worlds kilometres across keep
// their millimetres. A hit needs tmin <= t <= tmax, as Ray's (tmin last for
// the same reason). For a secondary ray, meshcast/ray.h's rule with m taken
// in the hit instance's frame, where the walk rounds: the largest of the
// hit point's coordinates less the instance's translation and of |t dir|
// (the primary t is a float). 48 bytes (4 of padding after tmin); a RAYD
// file keeps the first 40 (no tmin: read as 0).
struct RayD {
  double org[3];
  float dir[3];
  float tmax;
  float tmin = 0;
};
static_assert(sizeof(RayD) == 48, "RayD: the 40 bytes of a RAYD file record, tmin and padding");

// A float ray as a RayD: its origin taken as doubles.
inline RayD widened(const Ray& r) {
  return {{r.org[0], r.org[1], r.org[2]}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax, r.tmin};
}

// A hit in a scene: the instance and the triangle of its mesh (the index in
// the mesh the blob was built from), t in the world ray's units.
struct SceneHit {
  float t = INFINITY;  // INFINITY on a miss
  uint32_t instance = kNoHit;
  uint32_t triangle = kNoHit;
  float u = 0, v = 0;  // only with HitOutputs::Uv, as Hit's
};

// A scene's nearest point to a query point (Scene::closest_points): in the
// world, in double.
struct SceneClosestPoint {
  double point[3] = {0, 0, 0};
  double distance = INFINITY;   // INFINITY: none within the limit
  uint32_t instance = kNoHit;
  uint32_t triangle = kNoHit;   // of the instance's mesh, the caller's number
  float u = 0, v = 0;           // the point's barycentrics on the triangle's stored corners
};

// Query::All's answers on a scene, compact rows as HitLists: ray i found
// found[i] hits over every instance it reaches, the nearest min(found[i],
// max_hits) its row(i) in order of t, then instance, then triangle.
using SceneHitLists = HitRows<SceneHit>;

// Where an instance stands: world = rotation_scale * local + translation.
// The 3x3 is row-major and may rotate, scale (non-uniformly too) and mirror
// (a negative determinant); it must be invertible. The translation is in
// double: placements far from the origin keep their precision.
//
// Facing is the mesh's own, whatever the transform: a triangle's front face
// is decided in the mesh's frame (the world ray brought into it meets the
// corners as the mesh winds them), as Vulkan's and DirectX's ray tracing
// decide it. A mirrored copy of a closed mesh whose outside is its front
// keeps its outside in front, so Cull::Back from outside still hits it. An
// instance's flip_facing (Scene::add_instance, set_flip_facing; false by
// default, like VK_GEOMETRY_INSTANCE_TRIANGLE_FLIP_FACING_BIT_KHR) turns
// that instance's faces: its front is the mesh's back.
struct Transform {
  float rotation_scale[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double translation[3] = {0, 0, 0};
};

// A mesh or an instance a scene gave. `index` counts from 0 in the order
// they were added (a SceneHit's `instance` is its instance's index, for the
// caller's own tables); `scene` is the number of the scene that gave it,
// one a scene and never given twice in the process (as a caster's tickets
// carry the caster's), so an id handed to another scene is refused with
// UsageError, never taken for one of that scene's own. A scene moved keeps
// its number, and the ids it gave stay good.
template <class Kind>
struct SceneId {
  uint32_t index = UINT32_MAX;
  uint64_t scene = 0;
  friend bool operator==(const SceneId&, const SceneId&) = default;
};
struct MeshKind;
struct InstanceKind;
using MeshId = SceneId<MeshKind>;
using InstanceId = SceneId<InstanceKind>;

class SceneSnapshot;  // what one commit() made (internal: scene/snapshot.h)

class Scene {
 public:
  Scene();
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;

  // A blob every instance of it walks, validated once (InputError naming
  // `name`: what BlobView checks, and bounds that are a finite box). Three
  // ways to hand it over, the same validation and walks for each:
  //
  // The scene keeps the bytes: a vector moved in is kept where it lies (no
  // copy), one passed as an lvalue is copied.
  MeshId add_mesh(std::vector<uint8_t> blob, const std::string& name);
  // A mapped blob file the scene shares: the scene, every snapshot of it and
  // every caster batch holding one keep the mapping alive; the bytes are
  // read where they are mapped, never copied (a GPU scene method copies
  // them to the device). UsageError for a null pointer.
  MeshId add_mesh(std::shared_ptr<const MappedBlob> file, const std::string& name);
  // The bytes a BlobView reads (already validated: not checked again),
  // referenced, neither copied nor owned: they must stay unchanged and
  // outlive the scene, every snapshot taken from it (a caster's batch holds
  // one until it is collected) and every trace through them; a GPU scene
  // method reads them only while a batch is begun, to upload them.
  MeshId add_mesh(const BlobView& blob, const std::string& name);
  // The bytes instances of `mesh` walk (the scene's copy, or the caller's
  // where it shares or references them). UsageError for an unknown mesh or
  // another scene's.
  std::span<const uint8_t> mesh_blob(MeshId mesh) const;
  // The memory the scene holds for blob copies (add_mesh of a vector: each
  // vector's capacity, spare bytes included); shared and referenced
  // blobs are the caller's memory, not counted.
  size_t owned_blob_bytes() const;

  // An instance of `mesh`, enabled, with an 8-bit mask (a ray's mask must
  // share a bit with it for the instance to be walked) and its faces as the
  // mesh has them, or turned with `flip_facing` (see Transform: Cull::Back
  // then drops the mesh's front faces). UsageError for an unknown mesh or
  // another scene's, a transform that is not finite or not invertible, a
  // 3x3 or inverse entry beyond 2^40, a translation or world box beyond
  // 2^100 (kMaxCoordinate), or a 2^31st instance.
  InstanceId add_instance(MeshId mesh, const Transform& transform, uint8_t mask = 0xFF, bool flip_facing = false);
  // Each edit of an instance: UsageError for an unknown or removed id, or
  // another scene's. A new transform keeps the instance's mask and flip_facing.
  void set_transform(InstanceId instance, const Transform& transform);
  void set_mask(InstanceId instance, uint8_t mask);
  void set_flip_facing(InstanceId instance, bool flip_facing);
  void set_enabled(InstanceId instance, bool enabled);
  // The id is not given again.
  void remove_instance(InstanceId instance);

  // The frame's changes are done: from now on traces see them (and not before: see snapshot()).
  void commit();

  // The hit of each world ray under `query` (Closest or Any; All has
  // trace_all_hits) against the committed scene, among the instances whose mask shares a bit with
  // `mask`; `cull` as BlobView::trace, the front face as the instance's
  // mesh has it (turned by its flip_facing; a mirroring transform changes
  // nothing, see Transform); `outputs`: Uv at most (a scene hit has no point).
  // Returns the rays not walkable: a non-finite origin or one beyond 2^100,
  // a direction, t_max or t_min BlobView would refuse (answered as misses), or a
  // ray some instance's frame cannot take (its direction scaled past the
  // walkers' range: that instance is not walked, the others are). UsageError
  // when hits is shorter than rays, for Query::All or HitOutputs::Point, and as snapshot().
  uint64_t trace(std::span<const RayD> rays, std::span<SceneHit> hits, HitOutputs outputs = HitOutputs::None,
                 Query query = Query::Closest, Cull cull = Cull::None, uint8_t mask = 0xFF) const;
  // Float rays, their origins taken as doubles.
  uint64_t trace(std::span<const Ray> rays, std::span<SceneHit> hits, HitOutputs outputs = HitOutputs::None,
                 Query query = Query::Closest, Cull cull = Cull::None, uint8_t mask = 0xFF) const;
  // Query::All: every hit of each ray along its segment over the committed
  // scene into `lists`, compact rows (meshcast/ray.h: cleared, then a row a
  // ray holding its kept hits alone; lists.max_hits, 1 to kMaxHitsLimit,
  // the most a row keeps), as BlobView::trace_all_hits. Returns the rays
  // not walkable, as trace() does.
  uint64_t trace_all_hits(std::span<const RayD> rays, SceneHitLists& lists, HitOutputs outputs = HitOutputs::None,
                          Cull cull = Cull::None, uint8_t mask = 0xFF) const;

  // The nearest point of the committed scene to each world point (in
  // double), within max_distance (inclusive), among the instances whose
  // mask shares a bit with `mask`: each instance near enough is walked in
  // its own frame, and each of its triangles placed in the world (its
  // corners through the inverse of the instance's float to_local, as a
  // ray's walk places them) before its nearest point is found, so the
  // distance is the world's under any rotation and scale, uniform or not.
  // At one distance the lower instance, then the lower triangle. Returns
  // how many points had a NaN or infinite coordinate (answered as none
  // found). OctTreeCompressed meshes alone: UsageError naming another
  // layout, when out is shorter than points, or for a negative or NaN
  // max_distance.
  uint64_t closest_points(std::span<const std::array<double, 3>> points, std::span<SceneClosestPoint> out,
                          double max_distance = INFINITY, uint8_t mask = 0xFF) const;

  // What the last commit() made, for a caster that keeps a batch on the scene it was submitted to (traces see that
  // frame). UsageError for a scene given a mesh or an instance but never committed (commit it first).
  std::shared_ptr<const SceneSnapshot> snapshot() const;

  // The number every id this scene gives carries (see SceneId).
  uint64_t number() const;

  size_t instance_count() const;  // not removed, committed or not
  // What the scene holds besides its meshes' blobs: the instances' records,
  // the top level it builds and refits, and the snapshots it keeps (the
  // last two; a batch in flight may hold an older one too).
  size_t top_level_bytes() const;

 private:
  struct Edits;
  Edits& edits(const char* who) const;  // UsageError naming `who` on a moved-from scene
  MeshId add_validated(const BlobView& view, std::shared_ptr<const void> owner, const std::string& name);
  std::unique_ptr<Edits> edits_;  // and the committed snapshot, behind a mutex
};

// A snapshot's point queries: the same as Scene's, on the frame it holds.
uint64_t closest_points_snapshot(const SceneSnapshot& snapshot, std::span<const std::array<double, 3>> points,
                                 std::span<SceneClosestPoint> out, double max_distance = INFINITY, uint8_t mask = 0xFF);

// A snapshot's traces: the same as Scene's, on the frame it holds.
uint64_t trace_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, std::span<SceneHit> hits,
                        HitOutputs outputs = HitOutputs::None, Query query = Query::Closest, Cull cull = Cull::None,
                        uint8_t mask = 0xFF);
uint64_t trace_all_hits_snapshot(const SceneSnapshot& snapshot, std::span<const RayD> rays, SceneHitLists& lists,
                                 HitOutputs outputs = HitOutputs::None, Cull cull = Cull::None, uint8_t mask = 0xFF);

}  // namespace meshcast
