// The Vulkan scene method: shaders/scene_octtree.comp walks a
// snapshot's top level and then each instance's blob, reading the bytes
// Scene::commit() made (the placed records and wide nodes, copied
// unchanged) and the blobs the CPU walks. Every mesh must be in the
// recommended layout, OctTreeCompressed/ClusterBitPackSOA8, or its exact
// twin OctTreeCompressed/ClusterFloat3SOA8.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "meshcast/scene.h"

namespace meshcast {
struct SceneMesh;
}

namespace meshcast::gpu {

class Context;
class Buffer;
class Pipeline;

class SceneMethod {
 public:
  // `flags`: MC_HIT_UV, MC_QUERY_ANY and MC_CULL_*, the batches' outputs,
  // query and culling (the shader's specialization constant). UsageError
  // for every hit (MC_QUERY_ALL) or a point (MC_HIT_POINT): the CPU
  // answers those.
  SceneMethod(Context& ctx, uint32_t flags);
  ~SceneMethod();
  SceneMethod(const SceneMethod&) = delete;
  SceneMethod& operator=(const SceneMethod&) = delete;

  // trace_snapshot's answers on the GPU: each world ray's hit among the
  // instances whose mask shares a bit with `mask`, bit for bit the CPU's.
  // Returns the rays not walkable (trace_snapshot's count). InputError
  // naming a mesh in another layout; GpuError from Vulkan. The blobs are
  // uploaded once for as long as the snapshots bring the same meshes (the
  // method holds those meshes until then).
  uint64_t trace(const SceneSnapshot& snapshot, std::span<const RayD> rays, std::span<SceneHit> hits,
                 uint8_t mask = 0xFF);

  // trace() in two halves, one batch in flight: begin() uploads what it
  // needs and submits without waiting (the snapshot may go once it
  // returns); finish() waits for the batch and writes its answers (hits at
  // least the batch's size, else UsageError), returning trace()'s count.
  // The host layer's GPU thread runs scene batches so. Not thread-safe: one
  // caller at a time, and begin() only with no batch in flight
  // (std::logic_error otherwise).
  void begin(const SceneSnapshot& snapshot, std::span<const RayD> rays, uint8_t mask = 0xFF);
  uint64_t finish(std::span<SceneHit> hits);

  // "" when the method reads every mesh of the snapshot, else why not (a
  // mesh in another layout, naming it; blobs past what it addresses): what
  // begin() would refuse, found without copying anything.
  static std::string refusal(const SceneSnapshot& snapshot);

 private:
  void upload_blobs(const SceneSnapshot& snapshot);
  Context& ctx_;
  const uint32_t flags_;
  uint32_t n_ = 0;  // the rays of the batch begun last
  std::unique_ptr<Pipeline> pipeline_;
  std::unique_ptr<Buffer> blobs_, top_, rays_, hits_, unused_;
  // The meshes blobs_ holds, in the snapshot's order: held, so that a mesh
  // made later can never take the address of one uploaded here.
  std::vector<std::shared_ptr<const SceneMesh>> uploaded_;
  std::vector<uint32_t> mesh_base_;    // each one's first word in blobs_
  // The command buffer (re-recorded every batch: its sizes and buffers
  // vary), its fence and whether a batch is in flight (gpu/scene.cpp).
  // Declared last: destroyed first, it waits for a batch in flight before
  // the buffers that batch reads go.
  struct Flight;
  std::unique_ptr<Flight> flight_;
};

}  // namespace meshcast::gpu
