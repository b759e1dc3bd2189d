// Embree 3 as a peer: one triangle geometry holding the input mesh as is,
// rtcIntersect1 per ray, memory counted through the device's memory monitor.
#include <embree3/rtcore.h>

#include <atomic>
#include <chrono>

#include "bench/peer.h"

namespace meshcast::bench {

namespace {

class Embree final : public Peer {
 public:
  explicit Embree(const Mesh& mesh) {
    device_ = rtcNewDevice("threads=1");
    if (!device_) throw std::runtime_error("Embree: rtcNewDevice failed");
    rtcSetDeviceMemoryMonitorFunction(
        device_,
        [](void* user, ssize_t bytes, bool) {
          static_cast<std::atomic<int64_t>*>(user)->fetch_add(bytes);
          return true;
        },
        &bytes_);
    auto t0 = std::chrono::steady_clock::now();
    scene_ = rtcNewScene(device_);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.vertices.size()));
    for (size_t i = 0; i < mesh.vertices.size(); ++i)
      v[3 * i] = mesh.vertices[i].x, v[3 * i + 1] = mesh.vertices[i].y, v[3 * i + 2] = mesh.vertices[i].z;
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(unsigned), mesh.triangles.size()));
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      for (int c = 0; c < 3; ++c) idx[3 * t + c] = mesh.triangles[t][c];
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
  std::string name() const override { return "Embree " + std::to_string(RTC_VERSION_MAJOR) + "." +
                                             std::to_string(RTC_VERSION_MINOR) + "." +
                                             std::to_string(RTC_VERSION_PATCH); }
  double build_ms() const override { return build_ms_; }
  uint64_t bytes() const override { return uint64_t(bytes_.load()); }
  void trace(const std::vector<Ray>& rays, std::vector<Hit>& hits) const override {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (size_t i = 0; i < rays.size(); ++i) {
      const Ray& r = rays[i];
      RTCRayHit rh{};
      rh.ray.org_x = r.org[0], rh.ray.org_y = r.org[1], rh.ray.org_z = r.org[2];
      rh.ray.dir_x = r.dir[0], rh.ray.dir_y = r.dir[1], rh.ray.dir_z = r.dir[2];
      rh.ray.tnear = 0.0f, rh.ray.tfar = r.tmax, rh.ray.mask = ~0u;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      hits[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? Hit{} : Hit{rh.ray.tfar, rh.hit.primID, rh.hit.u, rh.hit.v};
    }
  }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  double build_ms_ = 0;
  std::atomic<int64_t> bytes_{0};
};

}  // namespace

std::unique_ptr<Peer> make_embree(const Mesh& mesh) { return std::make_unique<Embree>(mesh); }

}  // namespace meshcast::bench
