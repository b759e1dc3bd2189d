// AABBList grouping (seed 000 §7). The seed's greedy grouping takes the
// unused triangle whose centre has the lowest x and puts it in a batch with
// the unused triangles whose centres lie nearest to it. Here the sweep runs
// along the longest axis of the centres' box instead of always x: on a mesh
// flat in x (a wall) every x is equal and the sweep below could never stop
// early. Finding the nearest is exact: centres sorted along the sweep axis,
// scanned from the seed outward until the sweep distance alone exceeds the
// worst of the batch - 1 nearest so far; used triangles are skipped through
// a path-halving "next unused" table, so each is stepped over about once.
#include <algorithm>
#include <numeric>

#include "builder/build_topdown.h"

namespace meshcast {

namespace {

std::vector<uint32_t> closest_centroid(const std::vector<Vec3>& centres, uint32_t batch) {
  const uint32_t n = uint32_t(centres.size());
  Box3 box;
  for (const Vec3& c : centres) box.grow(c);
  const Vec3 e = box.extent();
  const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
  std::vector<uint32_t> sweep(n);
  std::iota(sweep.begin(), sweep.end(), 0u);
  std::stable_sort(sweep.begin(), sweep.end(), [&](uint32_t a, uint32_t b) { return centres[a][axis] < centres[b][axis]; });

  std::vector<uint32_t> next(n + 1);  // next[i] == i: position i is unused
  std::iota(next.begin(), next.end(), 0u);
  auto unused_from = [&](uint32_t i) {
    while (next[i] != i) i = next[i] = next[next[i]];
    return i;
  };
  std::vector<uint32_t> order;
  order.reserve(n);
  std::vector<std::pair<double, uint32_t>> nearest;  // max-heap of (squared distance, sweep position)
  for (uint32_t first = unused_from(0); first < n; first = unused_from(first)) {
    const Vec3 s = centres[sweep[first]];
    next[first] = first + 1;
    order.push_back(sweep[first]);
    nearest.clear();
    for (uint32_t i = unused_from(first + 1); i < n && batch > 1; i = unused_from(i + 1)) {
      const Vec3 c = centres[sweep[i]];
      const double along = double(c[axis]) - s[axis];
      const bool full = nearest.size() == batch - 1;
      if (full && along * along > nearest.front().first) break;  // every later centre lies farther
      const double dx = double(c.x) - s.x, dy = double(c.y) - s.y, dz = double(c.z) - s.z;
      const std::pair<double, uint32_t> candidate{dx * dx + dy * dy + dz * dz, i};
      if (full) {
        if (!(candidate < nearest.front())) continue;
        std::pop_heap(nearest.begin(), nearest.end());
        nearest.back() = candidate;
      } else {
        nearest.push_back(candidate);
      }
      std::push_heap(nearest.begin(), nearest.end());
    }
    // The batch keeps sweep order: deterministic, and near triangles stay near.
    std::sort(nearest.begin(), nearest.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    for (const auto& [distance, i] : nearest) next[i] = i + 1, order.push_back(sweep[i]);
  }
  return order;
}

}  // namespace

std::vector<uint32_t> group_batches(const std::vector<Box3>& boxes, uint32_t batch, Grouping grouping) {
  std::vector<Vec3> centres = box_centres(boxes);
  return grouping == Grouping::Morton ? morton_sorted(centres) : closest_centroid(centres, batch);
}

std::vector<Grouping> all_groupings() { return {Grouping::ClosestCentroid, Grouping::Morton}; }

const char* grouping_name(Grouping g) { return g == Grouping::Morton ? "Morton" : "ClosestCentroid"; }

Grouping parse_grouping(const std::string& name) { return parse_named(name, all_groupings(), grouping_name, "grouping"); }

}  // namespace meshcast
