// Embree 3 as a peer: one triangle geometry over the input mesh, shared
// (Embree reads our arrays), rtcIntersect1 per ray, Embree's own memory
// counted through the device's memory monitor.
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <map>
#include <memory>
#include <chrono>

#include "bench/peer.h"

namespace meshcast::bench {

namespace {

// A device of `threads` build threads (0: every core) whose allocations
// are summed into *bytes (Embree's memory monitor).
RTCDevice new_device(uint32_t threads, std::atomic<int64_t>* bytes) {
  RTCDevice device = rtcNewDevice(("threads=" + std::to_string(threads)).c_str());
  if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
  rtcSetDeviceMemoryMonitorFunction(
      device,
      [](void* user, ssize_t delta, bool) {
        static_cast<std::atomic<int64_t>*>(user)->fetch_add(delta);
        return true;
      },
      bytes);
  return device;
}

class Embree final : public Peer {
 public:
  Embree(const Mesh& mesh, EmbreeMode mode, uint32_t threads) : mode_(mode) {
    device_ = new_device(threads, &bytes_);
    auto t0 = std::chrono::steady_clock::now();
    scene_ = rtcNewScene(device_);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree reads a vertex buffer with 16-byte loads: 4 bytes of padding.
    vertices_.resize(3 * mesh.vertices.size() + 1, 0.0f);
    for (size_t i = 0; i < mesh.vertices.size(); ++i)
      for (int a = 0; a < 3; ++a) vertices_[3 * i + size_t(a)] = mesh.vertices[i][a];
    indices_.resize(3 * mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      for (int c = 0; c < 3; ++c) indices_[3 * t + size_t(c)] = mesh.triangles[t][size_t(c)];
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices_.data(), 0,
                               3 * sizeof(float), mesh.vertices.size());
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices_.data(), 0,
                               3 * sizeof(unsigned), mesh.triangles.size());
    mesh_bytes_ = 12ull * mesh.vertices.size() + 12ull * mesh.triangles.size();
    if (mode == EmbreeMode::Robust) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    if (mode == EmbreeMode::Compact) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_COMPACT);
    if (mode == EmbreeMode::High) {  // the scene's quality and the geometry's both: spatial splits need the latter
      rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
      rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_HIGH);
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene_);
    build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  ~Embree() override {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }
  std::string name() const override {
    const char* mode = mode_ == EmbreeMode::Robust    ? " robust"
                       : mode_ == EmbreeMode::Compact ? " compact"
                       : mode_ == EmbreeMode::High    ? " high quality"
                                                      : " default";
    return "Embree " + std::to_string(RTC_VERSION_MAJOR) + "." + std::to_string(RTC_VERSION_MINOR) + "." +
           std::to_string(RTC_VERSION_PATCH) + mode;
  }
  double build_ms() const override { return build_ms_; }
  uint64_t bytes() const override { return uint64_t(bytes_.load()) + mesh_bytes_; }
  void trace(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query) const override {
    trace_range(rays, hits, query, 0, rays.size());
  }
  void trace_on_cores(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query, uint32_t threads) const override {
    // Embree's own way: its rays spread by a TBB loop, in an arena of
    // `threads` (TBB's workers, as Embree's build uses), kept from call to
    // call as a game would keep it.
    std::unique_ptr<tbb::task_arena>& arena = arenas_[threads];
    if (!arena) arena = std::make_unique<tbb::task_arena>(static_cast<int>(threads));
    arena->execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        trace_range(rays, hits, query, r.begin(), r.end());
      });
    });
  }
  void trace_packets(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query) const override {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // the caller's rays come sorted by direction
    for (size_t begin = 0; begin < rays.size(); begin += 16) {
      const size_t n = std::min<size_t>(16, rays.size() - begin);
      alignas(64) int valid[16];
      alignas(64) RTCRayHit16 rh{};
      for (size_t k = 0; k < 16; ++k) {
        valid[k] = k < n ? -1 : 0;
        const Ray& r = rays[begin + std::min(k, n - 1)];
        rh.ray.org_x[k] = r.org[0], rh.ray.org_y[k] = r.org[1], rh.ray.org_z[k] = r.org[2];
        rh.ray.dir_x[k] = r.dir[0], rh.ray.dir_y[k] = r.dir[1], rh.ray.dir_z[k] = r.dir[2];
        rh.ray.tnear[k] = r.tmin, rh.ray.tfar[k] = r.tmax, rh.ray.mask[k] = ~0u;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      }
      if (query == Query::Any) {
        rtcOccluded16(valid, scene_, &context, &rh.ray);
        for (size_t k = 0; k < n; ++k) hits[begin + k] = rh.ray.tfar[k] < 0 ? Hit{0.0f, 0} : Hit{};
      } else {
        rtcIntersect16(valid, scene_, &context, &rh);
        for (size_t k = 0; k < n; ++k)
          hits[begin + k] = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID
                                ? Hit{}
                                : Hit{rh.ray.tfar[k], rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k]};
      }
    }
  }

 private:
  void trace_range(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query, size_t begin, size_t end) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    if (query == Query::Any) {
      for (size_t i = begin; i < end; ++i) {
        const Ray& r = rays[i];
        RTCRay ray{};
        ray.org_x = r.org[0], ray.org_y = r.org[1], ray.org_z = r.org[2];
        ray.dir_x = r.dir[0], ray.dir_y = r.dir[1], ray.dir_z = r.dir[2];
        ray.tnear = r.tmin, ray.tfar = r.tmax, ray.mask = ~0u;
        rtcOccluded1(scene_, &context, &ray);
        hits[i] = ray.tfar < 0 ? Hit{0.0f, 0} : Hit{};  // occluded: tfar is set to -inf
      }
      return;
    }
    for (size_t i = begin; i < end; ++i) {
      const Ray& r = rays[i];
      RTCRayHit rh{};
      rh.ray.org_x = r.org[0], rh.ray.org_y = r.org[1], rh.ray.org_z = r.org[2];
      rh.ray.dir_x = r.dir[0], rh.ray.dir_y = r.dir[1], rh.ray.dir_z = r.dir[2];
      rh.ray.tnear = r.tmin, rh.ray.tfar = r.tmax, rh.ray.mask = ~0u;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      hits[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? Hit{} : Hit{rh.ray.tfar, rh.hit.primID, rh.hit.u, rh.hit.v};
    }
  }

  EmbreeMode mode_;
  mutable std::map<uint32_t, std::unique_ptr<tbb::task_arena>> arenas_;  // by thread count
  std::vector<float> vertices_;
  std::vector<unsigned> indices_;
  uint64_t mesh_bytes_ = 0;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  double build_ms_ = 0;
  std::atomic<int64_t> bytes_{0};
};

// Embree's instancing: a scene a mesh (its geometry shares our arrays), a
// top scene of instance geometries whose ids are the instances' indices.
class EmbreeScene final : public ScenePeer {
 public:
  EmbreeScene(const std::vector<const Mesh*>& meshes, const std::vector<PeerInstance>& instances) {
    device_ = new_device(1, &bytes_);
    shapes_.reserve(meshes.size());  // Embree keeps pointers into each shape's arrays
    for (const Mesh* mesh : meshes) {
      Shape& s = shapes_.emplace_back();
      s.vertices.resize(3 * mesh->vertices.size() + 1, 0.0f);  // 16-byte loads: 4 bytes of padding
      for (size_t i = 0; i < mesh->vertices.size(); ++i)
        for (int a = 0; a < 3; ++a) s.vertices[3 * i + size_t(a)] = mesh->vertices[i][a];
      s.indices.resize(3 * mesh->triangles.size());
      for (size_t t = 0; t < mesh->triangles.size(); ++t)
        for (int c = 0; c < 3; ++c) s.indices[3 * t + size_t(c)] = mesh->triangles[t][size_t(c)];
      mesh_bytes_ += 12ull * mesh->vertices.size() + 12ull * mesh->triangles.size();
      s.scene = rtcNewScene(device_);
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, s.vertices.data(), 0, 12,
                                 mesh->vertices.size());
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, s.indices.data(), 0, 12,
                                 mesh->triangles.size());
      rtcCommitGeometry(g);
      rtcAttachGeometry(s.scene, g);
      rtcReleaseGeometry(g);
      rtcCommitScene(s.scene);
    }
    top_ = rtcNewScene(device_);
    rtcSetSceneFlags(top_, RTC_SCENE_FLAG_DYNAMIC);
    for (size_t i = 0; i < instances.size(); ++i) {
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, shapes_[instances[i].mesh].scene);
      rtcAttachGeometryByID(top_, g, unsigned(i));
      instances_.push_back(g);
      set_transform(uint32_t(i), instances[i].transform);
    }
    rtcCommitScene(top_);
  }
  ~EmbreeScene() override {
    for (RTCGeometry g : instances_) rtcReleaseGeometry(g);
    rtcReleaseScene(top_);
    for (Shape& s : shapes_) rtcReleaseScene(s.scene);
    rtcReleaseDevice(device_);
  }
  std::string name() const override {
    return "Embree " + std::to_string(RTC_VERSION_MAJOR) + "." + std::to_string(RTC_VERSION_MINOR) + "." +
           std::to_string(RTC_VERSION_PATCH) + " instances";
  }
  uint64_t bytes() const override { return uint64_t(bytes_.load()) + mesh_bytes_; }
  void set_transform(uint32_t instance, const Transform& t) override {
    float xfm[12];  // 3x4 row-major: rotation_scale, then the translation (rounded to float)
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) xfm[4 * r + c] = t.rotation_scale[3 * r + c];
      xfm[4 * r + 3] = float(t.translation[r]);
    }
    rtcSetGeometryTransform(instances_[instance], 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
    rtcCommitGeometry(instances_[instance]);
  }
  void commit() override { rtcCommitScene(top_); }
  void trace(const std::vector<RayD>& rays, std::vector<SceneHit>& hits) const override {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (size_t i = 0; i < rays.size(); ++i) {
      const RayD& r = rays[i];
      RTCRayHit rh{};
      rh.ray.org_x = float(r.org[0]), rh.ray.org_y = float(r.org[1]), rh.ray.org_z = float(r.org[2]);
      rh.ray.dir_x = r.dir[0], rh.ray.dir_y = r.dir[1], rh.ray.dir_z = r.dir[2];
      rh.ray.tnear = r.tmin, rh.ray.tfar = r.tmax, rh.ray.mask = ~0u;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(top_, &context, &rh);
      hits[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? SceneHit{}
                                                         : SceneHit{rh.ray.tfar, rh.hit.instID[0], rh.hit.primID};
    }
  }

 private:
  struct Shape {
    std::vector<float> vertices;
    std::vector<unsigned> indices;
    RTCScene scene = nullptr;
  };
  RTCDevice device_ = nullptr;
  std::vector<Shape> shapes_;
  std::vector<RTCGeometry> instances_;
  RTCScene top_ = nullptr;
  uint64_t mesh_bytes_ = 0;
  std::atomic<int64_t> bytes_{0};
};

}  // namespace

std::unique_ptr<ScenePeer> make_embree_scene(const std::vector<const Mesh*>& meshes,
                                             const std::vector<PeerInstance>& instances) {
  return std::make_unique<EmbreeScene>(meshes, instances);
}

std::unique_ptr<Peer> make_embree(const Mesh& mesh, EmbreeMode mode, uint32_t threads) {
  return std::make_unique<Embree>(mesh, mode, threads);
}

}  // namespace meshcast::bench
