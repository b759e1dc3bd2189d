// What one Scene::commit() makes (include/meshcast/scene.h): the meshes'
// blobs, shared by every snapshot that places them, and the top level.
// Immutable once made: a trace reads it while the next frame is edited.
#pragma once
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "layout/tree/top_level.h"
#include "meshcast/blob.h"
#include "meshcast/scene.h"

namespace meshcast {

// A scene's mesh: its blob's bytes and what keeps them alive, the view
// over them (validated once), and the walker the view chose, which the
// scene's walk calls with its own request (cpu/walk.h: its hits keep their
// slots, looked up afterwards).
struct SceneMesh {
  // `view` validated over bytes that `owner` keeps alive: the scene's copy,
  // a MappedBlob shared with the caller, or null for bytes the caller
  // guarantees (Scene::add_mesh of a BlobView). scene/scene.cpp.
  SceneMesh(const BlobView& view, std::shared_ptr<const void> owner, std::string mesh_name);
  SceneMesh(const SceneMesh&) = delete;
  SceneMesh& operator=(const SceneMesh&) = delete;
  const std::shared_ptr<const void> owner;
  const std::span<const uint8_t> bytes;  // the view's
  const std::string name;
  const BlobView view;
  void (*const walk)(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped,
                     const WalkRequest& request);
};

class SceneSnapshot {
 public:
  std::vector<std::shared_ptr<const SceneMesh>> meshes;
  layout::TopLevel top;
};

// UsageError unless the hits span holds one hit a ray (trace_snapshot's
// check, which Scene's float-ray trace makes before its chunks).
void check_scene_hits(size_t rays, size_t hits);

}  // namespace meshcast
