#include "builder/pairing.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "layout/formats.h"

namespace meshcast {

namespace {

// The surface area of the box of the edge p-q. Computed from the edge's
// canonical ends, so both half-edges of a twin get the same bits; in double,
// so edges of meshes near 1e-30 or 1e20 neither underflow to 0 nor overflow.
double edge_box_area(const Vec3& p, const Vec3& q) {
  const double ex = std::fabs(double(q.x) - p.x), ey = std::fabs(double(q.y) - p.y), ez = std::fabs(double(q.z) - p.z);
  return 2.0 * (ex * ey + ey * ez + ez * ex);
}

bool share_edge_by_index(const Triangle& a, const Triangle& b) {
  int shared = 0;
  for (uint32_t i : a)
    for (uint32_t j : b) shared += i == j;
  return shared >= 2;
}

bool same_point(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// Two corners in common, by position: what a compressed key's match must
// also be (two different edges may quantize to the same key).
bool share_edge_by_position(const Mesh& m, uint32_t a, uint32_t b) {
  int shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) shared += same_point(m.corner(a, i), m.corner(b, j));
  return shared >= 2;
}

uint32_t quantize24(double v, double lo, double extent) {
  if (!(extent > 0)) return 0;
  return uint32_t(std::clamp(std::round((v - lo) / extent * 16777215.0), 0.0, 16777215.0));
}

}  // namespace

std::vector<HalfEdge> half_edge_table(const Mesh& mesh) {
  std::vector<HalfEdge> table;
  table.reserve(mesh.triangles.size() * 3);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      if (a == b) continue;  // a degenerate triangle's collapsed edge pairs nothing
      if (a > b) std::swap(a, b);
      table.push_back({edge_box_area(mesh.vertices[a], mesh.vertices[b]), a, b, t});
    }
  return table;
}

std::vector<CompressedEdge> compressed_edge_table(const Mesh& mesh) {
  const Box3 box = mesh.bounds();
  double largest = 0;
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) largest = std::max(largest, edge_box_area(mesh.corner(t, k), mesh.corner(t, (k + 1) % 3)));
  std::vector<CompressedEdge> table;
  table.reserve(mesh.triangles.size() * 3);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = mesh.corner(t, k), q = mesh.corner(t, (k + 1) % 3);
      if (same_point(p, q)) continue;
      const uint32_t area = quantize24(edge_box_area(p, q), 0.0, largest);
      uint32_t mid[3];
      for (int a = 0; a < 3; ++a)
        mid[a] = quantize24(0.5 * (double(p[a]) + q[a]), box.min[a], double(box.max[a]) - box.min[a]);
      CompressedEdge e;
      e.key[0] = (16777215u - area) << 8 | mid[0] >> 16;
      e.key[1] = (mid[0] & 0xFFFFu) << 16 | mid[1] >> 8;
      e.key[2] = (mid[1] & 0xFFu) << 24 | mid[2];
      e.triangle = t;
      table.push_back(e);
    }
  return table;
}

std::vector<uint32_t> greedy_pairs(std::vector<HalfEdge> table, size_t triangles) {
  std::sort(table.begin(), table.end(), [](const HalfEdge& a, const HalfEdge& b) {
    if (a.area != b.area) return a.area > b.area;
    if (a.first != b.first) return a.first < b.first;
    if (a.second != b.second) return a.second < b.second;
    return a.triangle < b.triangle;
  });
  std::vector<uint32_t> partner(triangles, MC_NO_HIT);
  for (size_t i = 0; i + 1 < table.size(); ++i) {
    const HalfEdge &a = table[i], &b = table[i + 1];
    if (a.area != b.area || a.first != b.first || a.second != b.second || a.triangle == b.triangle) continue;
    if (partner[a.triangle] != MC_NO_HIT || partner[b.triangle] != MC_NO_HIT) continue;  // the seed's "reject"
    partner[a.triangle] = b.triangle, partner[b.triangle] = a.triangle;
  }
  return partner;
}

double input_order_paired_ratio(const Mesh& mesh, std::vector<uint32_t>* partner) {
  const size_t n = mesh.triangles.size();
  if (partner) partner->assign(n, MC_NO_HIT);
  size_t paired = 0;
  for (size_t i = 0; i + 1 < n;) {
    if (share_edge_by_index(mesh.triangles[i], mesh.triangles[i + 1])) {
      if (partner) (*partner)[i] = uint32_t(i + 1), (*partner)[i + 1] = uint32_t(i);
      paired += 2, i += 2;
    } else {
      i += 1;
    }
  }
  return n ? double(paired) / double(n) : 0.0;
}

Pairing pair_triangles(const Mesh& mesh, const PairingOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Pairing p;
  const size_t n = mesh.triangles.size();
  p.prescan_ratio = input_order_paired_ratio(mesh, &p.partner);
  if (p.prescan_ratio >= options.skip_above) {
    p.decision = "input order already pairs " + std::to_string(int(std::round(p.prescan_ratio * 100))) +
                 "% of the triangles (window N = 2, threshold " + std::to_string(int(std::round(options.skip_above * 100))) +
                 "%): pairing skipped, the input's pairs kept";
  } else {
    p.ran = true;
    if (!options.by_position) {
      p.partner = greedy_pairs(half_edge_table(mesh), n);
    } else {
      std::vector<CompressedEdge> table = compressed_edge_table(mesh);
      std::sort(table.begin(), table.end(), [](const CompressedEdge& a, const CompressedEdge& b) {
        for (int k = 0; k < 3; ++k)
          if (a.key[k] != b.key[k]) return a.key[k] < b.key[k];
        return a.triangle < b.triangle;
      });
      p.partner.assign(n, MC_NO_HIT);
      for (size_t i = 0; i + 1 < table.size(); ++i) {
        const CompressedEdge &a = table[i], &b = table[i + 1];
        if (a.key[0] != b.key[0] || a.key[1] != b.key[1] || a.key[2] != b.key[2] || a.triangle == b.triangle) continue;
        if (p.partner[a.triangle] != MC_NO_HIT || p.partner[b.triangle] != MC_NO_HIT) continue;
        if (!share_edge_by_position(mesh, a.triangle, b.triangle)) continue;  // two edges on one quantized key
        p.partner[a.triangle] = b.triangle, p.partner[b.triangle] = a.triangle;
      }
    }
    p.decision = "input order pairs " + std::to_string(int(std::round(p.prescan_ratio * 100))) +
                 "% (window N = 2, under the threshold " + std::to_string(int(std::round(options.skip_above * 100))) +
                 "%): paired by edge box area" + (options.by_position ? ", compressed position keys" : "");
  }
  for (uint32_t q : p.partner) p.pairs += q != MC_NO_HIT;
  p.pairs /= 2;
  p.paired_ratio = n ? 2.0 * p.pairs / double(n) : 0.0;
  p.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return p;
}

}  // namespace meshcast
