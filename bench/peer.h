// Peers measured side by side with meshcast (never dependencies of the
// library): built only when their Debian package is installed.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "meshcast/mesh.h"
#include "cpu/intersect.h"

namespace meshcast::bench {

class Peer {
 public:
  virtual ~Peer() = default;
  virtual std::string name() const = 0;
  virtual double build_ms() const = 0;
  virtual uint64_t bytes() const = 0;  // memory the peer reports for its scene
  // One thread, t in [0, t_max], hits in the caller's indices: the closest
  // hit, or with Query::Any the peer's occlusion query (Embree's
  // rtcOccluded1, which names no triangle: an occluded ray's hit is t 0,
  // triangle 0).
  virtual void trace(const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query = Query::Closest) const = 0;
};

// Embree 3 (libembree-dev) builds: Default (its fast mode, the default scene
// flags), Robust (RTC_SCENE_FLAG_ROBUST: no leaks at edges, slower) and
// Compact (RTC_SCENE_FLAG_COMPACT: triangle4i leaves that index the mesh),
// built with `threads` threads (0: all cores); tracing is one thread either
// way. bytes(): what Embree allocates for the scene plus the mesh it keeps
// and reads (12 bytes a vertex, 12 a triangle), shared with it, not copied.
// nullptr when meshcast was built without Embree.
enum class EmbreeMode { Default, Robust, Compact };
std::unique_ptr<Peer> make_embree(const Mesh& mesh, EmbreeMode mode = EmbreeMode::Default, uint32_t threads = 1);

}  // namespace meshcast::bench
