#include "bench/peer.h"

namespace meshcast::bench {

std::unique_ptr<Peer> make_embree(const Mesh&, EmbreeMode, uint32_t) { return nullptr; }

TreeSource embree_tree_source() { return {}; }

std::unique_ptr<ScenePeer> make_embree_scene(const std::vector<const Mesh*>&, const std::vector<PeerInstance>&) {
  return nullptr;
}

}  // namespace meshcast::bench
