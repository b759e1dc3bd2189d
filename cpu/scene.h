// What one Scene::commit() makes (include/meshcast/scene.h): the meshes'
// blobs, shared by every snapshot that places them, and the top level.
// Immutable once made: a trace reads it while the next frame is edited.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "layout/top_level.h"
#include "meshcast/blob.h"
#include "meshcast/scene.h"

namespace meshcast {

// A scene's mesh: its blob's bytes, the view over them (validated once),
// and the walker the view chose, which the scene's walk calls with its own
// request (cpu/walk.h: its hits keep their slots, looked up afterwards).
struct SceneMesh {
  SceneMesh(std::vector<uint8_t> blob, std::string mesh_name);  // cpu/scene.cpp
  SceneMesh(const SceneMesh&) = delete;
  SceneMesh& operator=(const SceneMesh&) = delete;
  const std::vector<uint8_t> bytes;
  const std::string name;
  const BlobView view;  // reads `bytes`, declared before it
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
