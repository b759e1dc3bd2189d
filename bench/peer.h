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
  // One thread, closest hit, t in [0, t_max], hits in the caller's indices.
  virtual void trace(const std::vector<Ray>& rays, std::vector<Hit>& hits) const = 0;
};

// Embree 3 (libembree-dev), default scene flags: its fast mode. nullptr when
// meshcast was built without Embree.
std::unique_ptr<Peer> make_embree(const Mesh& mesh);

}  // namespace meshcast::bench
