// Triangle pairing (seed 003, Aman & Fenney, "Fast Triangle Pairing for Ray
// Tracing"): pair triangles across shared edges, the edges whose bounding
// box has the largest surface area first, so that pairs come out compact and
// large triangles are paired before small ones.
//
//   1. the half-edge table: per half-edge its box surface area (BBSA), the
//      smaller and the larger vertex index, and its triangle;
//   2. (optional) compressed keys for input without vertex indices: the
//      edge's midpoint and BBSA in 24 bits each, 16 bytes an entry;
//   3. a lexicographic sort, largest area first: twins end up side by side;
//   4. a greedy linear scan pairing the two triangles of twin half-edges
//      when neither is paired yet.
// A pre-scan first measures how well the input order pairs already (a
// window of N = 2: each triangle with the next) and skips the pass when that
// is good enough, as the seed's pairer does.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast {

struct HalfEdge {
  double area;              // surface area of the edge's axis-aligned box (double: see edge_box_area)
  uint32_t first, second;   // vertex indices, first < second
  uint32_t triangle;
};

// The compressed entry: 24-bit area (stored as 2^24 - 1 - area, so an
// ascending sort puts the largest first) and 24-bit midpoint coordinates
// over the mesh box, then the triangle.
struct CompressedEdge {
  uint32_t key[3];
  uint32_t triangle;
};
static_assert(sizeof(CompressedEdge) == 16, "seed 003: 16 bytes an entry");

struct PairingOptions {
  bool by_position = false;      // compressed keys from coordinates, not vertex indices
  double skip_above = 0.9;       // pre-scan ratio at or above which the pass is skipped
};

struct Pairing {
  std::vector<uint32_t> partner;  // per triangle: its pair's other triangle, or MC_NO_HIT
  uint32_t pairs = 0;
  double prescan_ratio = 0;       // paired share of triangles in input order, window N = 2
  double paired_ratio = 0;        // paired share after (prescan_ratio when skipped)
  bool ran = false;               // false: the pre-scan found the input well paired
  std::string decision;
  double ms = 0;
};

std::vector<HalfEdge> half_edge_table(const Mesh& mesh);
std::vector<CompressedEdge> compressed_edge_table(const Mesh& mesh);
// Step 3 and 4 on a table (sorted here); returns partner per triangle.
std::vector<uint32_t> greedy_pairs(std::vector<HalfEdge> table, size_t triangles);
// The pre-scan: input order, each unpaired triangle with the next one when
// they share an edge (two vertex indices).
double input_order_paired_ratio(const Mesh& mesh, std::vector<uint32_t>* partner = nullptr);

Pairing pair_triangles(const Mesh& mesh, const PairingOptions& options = {});

}  // namespace meshcast
