#include "bench/peer.h"

namespace meshcast::bench {

std::unique_ptr<Peer> make_embree(const Mesh&) { return nullptr; }

}  // namespace meshcast::bench
