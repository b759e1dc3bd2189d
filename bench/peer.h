// Peers measured side by side with meshcast (never dependencies of the
// library): built only when their Debian package is installed.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "builder/tree_source.h"
#include "meshcast/mesh.h"
#include "cpu/intersect.h"
#include "meshcast/scene.h"

namespace meshcast::bench {

class Peer {
 public:
  virtual ~Peer() = default;
  virtual std::string name() const = 0;
  virtual double build_ms() const = 0;
  virtual uint64_t bytes() const = 0;  // memory the peer reports for its scene
  // One thread, t in [t_min, t_max], hits in the caller's indices: the closest
  // hit, or with Query::Any the peer's occlusion query (Embree's
  // rtcOccluded1, which names no triangle: an occluded ray's hit is t 0,
  // triangle 0).
  virtual void trace(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query = Query::Closest) const = 0;
  // The same answers on `threads` threads, the peer's own way of spreading
  // rays over cores.
  virtual void trace_on_cores(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query,
                              uint32_t threads) const = 0;
  // The same answers as trace(), the rays taken in their order 16 at a time
  // as packets (Embree: rtcIntersect16 / rtcOccluded16), one thread.
  virtual void trace_packets(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query) const = 0;
};

// Embree 3 (libembree-dev) builds: Default (its fast mode, the default scene
// flags), Robust (RTC_SCENE_FLAG_ROBUST: no leaks at edges, slower) and
// Compact (RTC_SCENE_FLAG_COMPACT: triangle4i leaves that index the mesh)
// and High (RTC_BUILD_QUALITY_HIGH: the SAH build with spatial splits, what
// a user with static meshes who builds once may pick), built with `threads` threads (0: all cores); tracing is one thread either
// way. bytes(): what Embree allocates for the scene plus the mesh it keeps
// and reads (12 bytes a vertex, 12 a triangle), shared with it, not copied.
// nullptr when meshcast was built without Embree.
enum class EmbreeMode { Default, Robust, Compact, High };
std::unique_ptr<Peer> make_embree(const Mesh& mesh, EmbreeMode mode = EmbreeMode::Default, uint32_t threads = 1);

// Embree's builder as the binary tree a blob is laid out over
// (bench/embree_tree.cpp): rtcBuildBVH's binned SAH (RTC_BUILD_QUALITY_MEDIUM,
// one thread) over the stored triangles' boxes, a node of at most the
// layout's leaf size a leaf, as meshcast's own splitter decides. An empty function when meshcast was built without Embree.
TreeSource embree_tree_source();

// A peer's instanced scene: each mesh its own scene, built once;
// the instances over them in a top scene rebuilt by commit().
struct PeerInstance {
  uint32_t mesh;
  Transform transform;
};
class ScenePeer {
 public:
  virtual ~ScenePeer() = default;
  virtual std::string name() const = 0;
  virtual uint64_t bytes() const = 0;  // every scene, top included, plus the meshes kept
  virtual void set_transform(uint32_t instance, const Transform& transform) = 0;
  virtual void commit() = 0;
  // One thread; the ray's origin rounded to float (Embree has no double
  // rays), hits naming the instance and the triangle.
  virtual void trace(const std::vector<RayD>& rays, std::vector<SceneHit>& hits) const = 0;
};
// Embree's instancing (RTC_GEOMETRY_TYPE_INSTANCE over one scene a mesh, its
// default build; the top scene RTC_SCENE_FLAG_DYNAMIC, one thread); its
// transforms are float. nullptr without Embree.
std::unique_ptr<ScenePeer> make_embree_scene(const std::vector<const Mesh*>& meshes,
                                             const std::vector<PeerInstance>& instances);

}  // namespace meshcast::bench
