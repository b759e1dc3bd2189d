// The order point queries walk their points in: along a Morton curve over
// the points' box, so that consecutive points lie near each other. A walk
// starts each point from its predecessor's nearest triangle, whose
// distance is then already close to the point's own (cpu/closest_points.cpp),
// and the nodes it reads are the ones its predecessor just read. Points
// with a coordinate that is not finite go last, in their own order.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace meshcast {

// The 21 low bits of x spread to every third bit.
inline uint64_t spread_bits3(uint64_t x) {
  x &= 0x1FFFFF;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// The indices 0..n-1 in Morton order of the points; coordinate(i, k): axis
// k of point i, as a double.
template <class Coordinate>
std::vector<size_t> morton_order(size_t n, const Coordinate& coordinate) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  auto finite = [&](size_t i) {
    return std::isfinite(coordinate(i, 0)) && std::isfinite(coordinate(i, 1)) && std::isfinite(coordinate(i, 2));
  };
  for (size_t i = 0; i < n; ++i)
    if (finite(i))
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], coordinate(i, k)), hi[k] = std::max(hi[k], coordinate(i, k));
  std::vector<std::pair<uint64_t, size_t>> keyed(n);
  for (size_t i = 0; i < n; ++i) {
    uint64_t key = ~uint64_t(0);  // last
    if (finite(i)) {
      key = 0;
      for (int k = 0; k < 3; ++k) {
        // The cell on a grid of 2^21 over the box (the width's quotient may
        // overflow a double's range: then the middle).
        const double width = hi[k] - lo[k];
        const double at = width > 0 && std::isfinite(width) ? (coordinate(i, k) - lo[k]) / width : 0.5;
        key |= spread_bits3(uint64_t(std::clamp(at, 0.0, 1.0) * 0x1FFFFF)) << k;
      }
    }
    keyed[i] = {key, i};
  }
  // Points given in Morton order already (a chunk of an ordered batch,
  // whose own box gives the same order) are not sorted again.
  if (!std::is_sorted(keyed.begin(), keyed.end())) std::sort(keyed.begin(), keyed.end());
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace meshcast
