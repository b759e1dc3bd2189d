#include "bench/peer.h"

namespace meshcast::bench {

std::unique_ptr<Peer> make_embree(const Mesh&, EmbreeMode, uint32_t) { return nullptr; }

}  // namespace meshcast::bench
