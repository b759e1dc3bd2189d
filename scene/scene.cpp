// Scene: the caller's edits, and commit() turning them into a snapshot.
#include "meshcast/scene.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <cmath>

#include "scene/build_top_level.h"
#include "scene/snapshot.h"
#include "cpu/walk_table.h"
#include "layout/blob_format.h"
#include "layout/message_text.h"
#include "meshcast/errors.h"

namespace meshcast {

namespace {
// The numbers scenes are given, the first 1 (0 is no scene's: a
// default-made id's).
std::atomic<uint64_t> next_scene_number{1};
}  // namespace

struct Scene::Edits {
  const uint64_t number = next_scene_number.fetch_add(1, std::memory_order_relaxed);
  std::vector<std::shared_ptr<const SceneMesh>> meshes;
  size_t owned_bytes = 0;  // the meshes' blobs the scene copied (add_mesh of a vector)
  struct Instance {
    layout::PlacedInstance placed;  // the walk's record, kept up to date
    bool enabled = true, removed = false;
  };
  std::vector<Instance> instances;  // by InstanceId
  std::vector<WorldBox> boxes;      // by InstanceId: what builds and refits read
  size_t live = 0;
  // Whether anything was edited since the last commit (a commit of nothing
  // keeps the snapshot it has).
  bool changed = true;
  // Since the last build of the top level: whether an instance was added,
  // removed, shown or hidden (the tree must be built again), and how many
  // commits refit it instead (moves and masks only).
  bool rebuild = true;
  uint32_t refits = 0;
  // The last build, refitted since: its wide nodes, anchor and root box
  // (`placed` unused) and the instance at each place of the tree; what
  // snapshots copy.
  layout::TopLevel built;
  std::vector<uint32_t> order;
  // A snapshot's storage, and whether what snapshot() handed out of it is
  // still held (by a trace, a caster's batch, or the scene as its last
  // commit). The handed-out pointer's deleter clears `held` with release
  // ordering once its last holder lets go, after that holder's last read;
  // commit() loads it with acquire before writing into the storage again.
  // The reference count of a shared_ptr cannot be read so (use_count() is
  // a relaxed load), and a standalone fence after it, correct as it is,
  // is an ordering ThreadSanitizer cannot see.
  struct Frame {
    SceneSnapshot snapshot;
    std::atomic<bool> held{false};
  };
  // The last two snapshots made. Once nothing holds the older one, the
  // next commit writes into it: its arrays are reused, not allocated and
  // faulted in again every frame. Each frame also lives as long as what
  // was handed out of it (the deleter keeps it), so a batch outlives the
  // scene.
  std::shared_ptr<Frame> current, previous;
  // What traces see: the last commit, read and replaced under the mutex
  // (traces may run on other threads than the one that commits).
  mutable std::mutex committed_mutex;
  std::shared_ptr<const SceneSnapshot> committed = std::make_shared<SceneSnapshot>();
  // Whether a mesh or an instance was added before the first commit (set
  // by the thread that edits, read by traces on any thread): such a
  // scene's casts are refused until it is committed, never answered as
  // the empty world its first snapshot is. Under committed_mutex, as is
  // whether it was ever committed.
  bool added_before_commit = false, ever_committed = false;
  void note_added() {
    std::lock_guard<std::mutex> lock(committed_mutex);
    if (!ever_committed) added_before_commit = true;
  }

  // Where an id of another scene is refused, naming both scenes.
  template <class Kind>
  void check_ours(SceneId<Kind> id, const char* kind, const char* who) const {
    if (id.scene != number)
      throw UsageError(std::string(who) + ": " + kind + " " + std::to_string(id.index) + " was given by " +
                       (id.scene == 0 ? std::string("no scene (a default-made id)")
                                      : "another scene (scene " + std::to_string(id.scene) + ")") +
                       ", not this one (scene " + std::to_string(number) + ")");
  }
  const SceneMesh& mesh(MeshId id, const char* who) const {
    check_ours(id, "mesh", who);
    if (id.index >= meshes.size())
      throw UsageError(std::string(who) + ": mesh " + std::to_string(id.index) + " is unknown (" +
                       std::to_string(meshes.size()) + " added)");
    return *meshes[id.index];
  }
  Instance& at(InstanceId id, const char* who) {
    check_ours(id, "instance", who);
    if (id.index >= instances.size() || instances[id.index].removed)
      throw UsageError(std::string(who) + ": instance " + std::to_string(id.index) + " is unknown or removed");
    return instances[id.index];
  }
};

namespace {

// The inverse of the 3x3 (in double, then rounded to float) and the world
// box of the mesh's bounds under the transform: centre
// M c + T and half extents |M| e, in double, padded by 2^-20 of their size
// (the rounding of the float inverse; what a ray's own rounding adds is the
// walk's slack, see scene_trace.cpp) and by the double sums' own rounding,
// each bound rounded outward.
void place(layout::PlacedInstance& p, WorldBox& box, const Transform& t, const SceneMesh& mesh, const char* who) {
  const float* m = t.rotation_scale;
  for (int i = 0; i < 9; ++i)
    if (!(std::fabs(m[i]) <= 0x1p40f))
      throw UsageError(std::string(who) + ": rotation_scale[" + std::to_string(i) + "] " + number_text(m[i]) +
                       " is not finite or beyond 2^40");
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(t.translation[a]) <= double(kMaxCoordinate)))
      throw UsageError(std::string(who) + ": translation[" + std::to_string(a) + "] " + number_text(t.translation[a]) +
                       " is not finite or beyond 2^100");
  auto e = [&](int r, int c) { return double(m[3 * r + c]); };
  const double cof[9] = {e(1, 1) * e(2, 2) - e(1, 2) * e(2, 1), e(0, 2) * e(2, 1) - e(0, 1) * e(2, 2),
                         e(0, 1) * e(1, 2) - e(0, 2) * e(1, 1), e(1, 2) * e(2, 0) - e(1, 0) * e(2, 2),
                         e(0, 0) * e(2, 2) - e(0, 2) * e(2, 0), e(0, 2) * e(1, 0) - e(0, 0) * e(1, 2),
                         e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0), e(0, 1) * e(2, 0) - e(0, 0) * e(2, 1),
                         e(0, 0) * e(1, 1) - e(0, 1) * e(1, 0)};
  const double det = e(0, 0) * cof[0] + e(0, 1) * cof[3] + e(0, 2) * cof[6];
  bool usable = det != 0 && std::isfinite(det);
  for (int i = 0; i < 9 && usable; ++i) {
    p.to_local[i] = float(cof[i] / det);
    usable = std::isfinite(p.to_local[i]) && std::fabs(p.to_local[i]) <= 0x1p40f;
  }
  if (!usable)
    throw UsageError(std::string(who) + ": rotation_scale is not invertible (determinant " + number_text(det) +
                     ") or its inverse has an entry beyond 2^40");
  for (int a = 0; a < 3; ++a) p.translation[a] = t.translation[a];
  const layout::BlobHeader& h = layout::header_of(mesh.bytes.data());
  double c[3], half[3];
  for (int a = 0; a < 3; ++a)
    c[a] = 0.5 * (double(h.bounds_min[a]) + h.bounds_max[a]), half[a] = 0.5 * (double(h.bounds_max[a]) - h.bounds_min[a]);
  for (int r = 0; r < 3; ++r) {
    // `magnitude` bounds every term the centre sums: the double sums'
    // roundings (the bounds' centre, the products, the additions; a few
    // 2^-53 of it) are covered by 2^-49 of it. Far from the origin that is
    // what keeps a small instance's box from collapsing to its centre: at
    // 10^16 half an ulp of the translation is 2, more than a unit sphere.
    double centre = t.translation[r], extent = 0, magnitude = std::fabs(t.translation[r]);
    for (int k = 0; k < 3; ++k) {
      centre += e(r, k) * c[k], extent += std::fabs(e(r, k)) * half[k];
      magnitude += std::fabs(e(r, k)) * (std::fabs(c[k]) + half[k]);
    }
    extent += (extent + std::fabs(centre - t.translation[r])) * 0x1p-20 + magnitude * 0x1p-49;
    // Each bound rounded outward: a step beyond the nearest double.
    box.min[r] = std::nextafter(centre - extent, -INFINITY), box.max[r] = std::nextafter(centre + extent, INFINITY);
    // The top level's float boxes and the rays' pads stay finite.
    if (!(std::fabs(box.min[r]) <= double(kMaxCoordinate) && std::fabs(box.max[r]) <= double(kMaxCoordinate)))
      throw UsageError(std::string(who) + ": the instance's world box on axis " + std::to_string(r) + " (" +
                       number_text(box.min[r]) + " to " + number_text(box.max[r]) + ") reaches beyond 2^100");
  }
}

}  // namespace

SceneMesh::SceneMesh(const BlobView& blob_view, std::shared_ptr<const void> keep, std::string mesh_name)
    : owner(std::move(keep)),
      bytes(blob_view.bytes()),
      name(std::move(mesh_name)),
      view(blob_view),
      walk(walker_for(uint32_t(view.layout().tree), uint32_t(view.layout().triangles))) {}

Scene::Scene() : edits_(std::make_unique<Edits>()) {}

Scene::Edits& Scene::edits(const char* who) const {
  if (!edits_) throw UsageError(std::string(who) + ": this scene was moved from");
  return *edits_;
}
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

// Every add_mesh's end: the view (validated) over bytes `owner` keeps
// alive, or the caller where it is null.
MeshId Scene::add_validated(const BlobView& view, std::shared_ptr<const void> owner, const std::string& name) {
  Edits& e = edits("Scene::add_mesh");
  // The world boxes come from the header's bounds (not every layout's
  // validation reads them): finite, min <= max.
  const layout::BlobHeader& h = layout::header_of(view.bytes().data());
  for (int a = 0; a < 3; ++a)
    if (!(h.bounds_min[a] <= h.bounds_max[a]) || !std::isfinite(h.bounds_min[a]) || !std::isfinite(h.bounds_max[a]))
      throw InputError(name + ": the blob's bounds on axis " + std::to_string(a) + " are not a finite box (" +
                       number_text(h.bounds_min[a]) + " to " + number_text(h.bounds_max[a]) + ")");
  e.meshes.push_back(std::make_shared<const SceneMesh>(view, std::move(owner), name));
  e.changed = true;
  e.note_added();
  return MeshId{uint32_t(e.meshes.size() - 1), e.number};
}

MeshId Scene::add_mesh(std::vector<uint8_t> blob, const std::string& name) {
  edits("Scene::add_mesh");  // a moved-from scene refuses before any validation
  // Moved into the shared copy: its bytes stay where the caller's vector had them.
  auto copy = std::make_shared<const std::vector<uint8_t>>(std::move(blob));
  const BlobView view(*copy, name);  // validates
  const MeshId id = add_validated(view, copy, name);
  edits_->owned_bytes += copy->capacity();
  return id;
}

MeshId Scene::add_mesh(std::shared_ptr<const MappedBlob> file, const std::string& name) {
  edits("Scene::add_mesh");
  if (!file) throw UsageError("Scene::add_mesh: " + name + ": the mapped blob is null");
  const BlobView view(file->bytes(), name);  // validates
  return add_validated(view, std::move(file), name);
}

MeshId Scene::add_mesh(const BlobView& blob, const std::string& name) { return add_validated(blob, nullptr, name); }

std::span<const uint8_t> Scene::mesh_blob(MeshId mesh) const {
  return edits("Scene::mesh_blob").mesh(mesh, "Scene::mesh_blob").bytes;
}

uint64_t Scene::number() const { return edits("Scene::number").number; }

size_t Scene::owned_blob_bytes() const { return edits("Scene::owned_blob_bytes").owned_bytes; }

InstanceId Scene::add_instance(MeshId mesh, const Transform& transform, uint8_t mask, bool flip_facing) {
  Edits& e = edits("Scene::add_instance");
  const SceneMesh& walked = e.mesh(mesh, "Scene::add_instance");
  // The top level's slots tell an instance by its high bit (kTopInstance).
  if (e.instances.size() >= layout::kTopInstance)
    throw UsageError("Scene::add_instance: a scene holds at most 2^31 instances, removed ones counted");
  Edits::Instance i;
  i.placed.id = uint32_t(e.instances.size());
  i.placed.mesh = mesh.index;
  i.placed.mask = mask;
  i.placed.flip_facing = flip_facing;
  WorldBox box;
  place(i.placed, box, transform, walked, "Scene::add_instance");
  e.instances.push_back(i);
  e.boxes.push_back(box);
  ++e.live;
  e.rebuild = e.changed = true;
  e.note_added();
  return InstanceId{i.placed.id, e.number};
}

void Scene::set_transform(InstanceId instance, const Transform& transform) {
  Edits& e = edits("Scene::set_transform");
  Edits::Instance& i = e.at(instance, "Scene::set_transform");
  layout::PlacedInstance moved = i.placed;  // unchanged should the transform be refused
  WorldBox box;
  place(moved, box, transform, *e.meshes[moved.mesh], "Scene::set_transform");
  i.placed = moved;
  e.boxes[instance.index] = box;
  e.changed = true;
}

void Scene::set_mask(InstanceId instance, uint8_t mask) {
  Edits& e = edits("Scene::set_mask");
  e.at(instance, "Scene::set_mask").placed.mask = mask;
  e.changed = true;
}

void Scene::set_flip_facing(InstanceId instance, bool flip_facing) {
  Edits& e = edits("Scene::set_flip_facing");
  e.at(instance, "Scene::set_flip_facing").placed.flip_facing = flip_facing;
  e.changed = true;
}

void Scene::set_enabled(InstanceId instance, bool enabled) {
  Edits& e = edits("Scene::set_enabled");
  Edits::Instance& i = e.at(instance, "Scene::set_enabled");
  e.rebuild |= i.enabled != enabled;
  e.changed |= i.enabled != enabled;
  i.enabled = enabled;
}

void Scene::remove_instance(InstanceId instance) {
  Edits& e = edits("Scene::remove_instance");
  e.at(instance, "Scene::remove_instance").removed = true;
  --e.live;
  e.rebuild = e.changed = true;
}

// A refit keeps the tree's splits while instances wander; after this many
// in a row the tree is built again, so a level in motion never walks a tree
// fitted to where it was long ago.
constexpr uint32_t kRefitsBeforeRebuild = 16;

void Scene::commit() {
  Edits& e = edits("Scene::commit");
  if (!e.changed) return;  // the committed snapshot is this frame's
  e.changed = false;
  if (!e.rebuild && e.refits < kRefitsBeforeRebuild && !e.built.wide.empty()) {
    // Moves and masks only: the same instances in the same places of the
    // tree, the boxes fitted again (the records are copied below).
    refit_top_level(e.boxes, e.order, e.built);
    ++e.refits;
  } else {
    std::vector<uint32_t> ids;
    ids.reserve(e.live);
    for (const Edits::Instance& i : e.instances)
      if (i.enabled && !i.removed) ids.push_back(i.placed.id);
    build_top_level(e.boxes, ids, e.built, e.order);
    e.rebuild = false, e.refits = 0;
  }
  // The snapshot: what a walk reads, copied (the last one may still be
  // walked by a batch in flight).
  std::shared_ptr<Edits::Frame> frame;
  if (e.previous && !e.previous->held.load(std::memory_order_acquire)) {
    // Nothing holds it: whoever walked it has let go, its last reads
    // ordered before the writes below by the acquire.
    frame = std::move(e.previous);
  } else {
    frame = std::make_shared<Edits::Frame>();
  }
  SceneSnapshot& next = frame->snapshot;
  next.meshes = e.meshes;
  next.top.placed.resize(e.order.size());
  for (size_t k = 0; k < e.order.size(); ++k) next.top.placed[k] = e.instances[e.order[k]].placed;
  next.top.wide.assign(e.built.wide.begin(), e.built.wide.end());
  for (int a = 0; a < 3; ++a)
    next.top.anchor[a] = e.built.anchor[a], next.top.min[a] = e.built.min[a], next.top.max[a] = e.built.max[a];
  // Handed out with a deleter of its own (one small control block a
  // commit; the arrays are the frame's): its last holder marks the frame
  // free. Marked held before the pointer exists, so no holder can clear
  // the mark before it is set.
  frame->held.store(true, std::memory_order_relaxed);
  std::shared_ptr<const SceneSnapshot> handed(
      &next, [keep = frame](const SceneSnapshot*) { keep->held.store(false, std::memory_order_release); });
  e.previous = std::move(e.current);
  e.current = std::move(frame);
  std::lock_guard<std::mutex> lock(e.committed_mutex);
  e.committed = std::move(handed);
  e.ever_committed = true;
}

std::shared_ptr<const SceneSnapshot> Scene::snapshot() const {
  Edits& e = edits("Scene::snapshot");
  std::lock_guard<std::mutex> lock(e.committed_mutex);
  if (e.added_before_commit && !e.ever_committed)
    throw UsageError("the scene was never committed: casts see its last commit, and its meshes and instances are not "
                     "in one yet; commit it first");
  return e.committed;
}

size_t Scene::instance_count() const { return edits("Scene::instance_count").live; }

size_t Scene::top_level_bytes() const {
  const Edits& e = edits("Scene::top_level_bytes");
  auto walked = [](const layout::TopLevel& t) {
    return t.placed.capacity() * sizeof(layout::PlacedInstance) + t.wide.capacity() * sizeof(layout::TopWideNode);
  };
  size_t bytes = e.instances.capacity() * sizeof(Edits::Instance) + e.boxes.capacity() * sizeof(WorldBox) +
                 walked(e.built) + e.order.capacity() * sizeof(uint32_t);
  for (const auto& f : {e.current, e.previous})
    if (f) bytes += walked(f->snapshot.top);
  return bytes;
}

uint64_t Scene::trace(std::span<const RayD> rays, std::span<SceneHit> hits, HitOutputs outputs, Query query, Cull cull,
                      uint8_t mask) const {
  return trace_snapshot(*snapshot(), rays, hits, outputs, query, cull, mask);
}

uint64_t Scene::trace_all_hits(std::span<const RayD> rays, SceneHitLists& lists, HitOutputs outputs, Cull cull,
                               uint8_t mask) const {
  return trace_all_hits_snapshot(*snapshot(), rays, lists, outputs, cull, mask);
}

uint64_t Scene::trace(std::span<const Ray> rays, std::span<SceneHit> hits, HitOutputs outputs, Query query, Cull cull,
                      uint8_t mask) const {
  check_scene_hits(rays.size(), hits.size());  // here, not a chunk at a time: it names the caller's sizes
  // Widened a chunk at a time on the stack: a game's per-frame call
  // allocates nothing.
  const std::shared_ptr<const SceneSnapshot> s = snapshot();
  constexpr size_t kChunk = 256;
  RayD wide[kChunk];
  uint64_t skipped = 0;
  size_t begin = 0;
  do {  // once at least: an empty batch still has its request checked
    const size_t n = std::min(kChunk, rays.size() - begin);
    std::transform(rays.begin() + begin, rays.begin() + begin + n, wide, widened);
    skipped += trace_snapshot(*s, std::span(wide, n), hits.subspan(begin, n), outputs, query, cull, mask);
    begin += n;
  } while (begin < rays.size());
  return skipped;
}

}  // namespace meshcast
