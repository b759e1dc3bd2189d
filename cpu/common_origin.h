// Batches whose rays share one origin, made ready for a packet walk
// (WalkRequest::packets): found, and ordered by direction so that the rays
// a packet takes together point nearly the same way. Baseline code (no
// instruction set of its own).
#pragma once
#include <cstdint>
#include <span>

#include "meshcast/ray.h"

namespace meshcast {

// Whether every ray starts at the first one's origin, bit for bit.
bool share_one_origin(std::span<const Ray> rays);

// order[k]: the index of the k-th ray by direction. The key is the
// direction's point on the octahedron |x| + |y| + |z| = 1 unfolded into a
// square (Meyer et al.'s octahedral map), 256 x 256 cells in Morton order,
// so neighbouring keys are neighbouring directions; rays of one cell keep
// their order. Two passes of a byte-wise counting sort. A direction that is
// not finite or is zero goes first (it is not walked anyway). `keys` and
// `scratch` (as many as the rays) are the caller's, so a caller that keeps
// them allocates nothing.
void order_by_direction(std::span<const Ray> rays, std::span<uint32_t> order, std::span<uint16_t> keys,
                        std::span<uint32_t> scratch);

}  // namespace meshcast
