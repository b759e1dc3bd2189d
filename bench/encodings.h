// `meshcast bench encodings`: seed 000 §3.11 reproduced. Every triangle
// format brute force (tree format BruteForce) and inside a QuadTree of leaf
// size 8, timed over long random rays as the source timed them.
#pragma once
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast::bench {

struct EncodingRow {
  std::string encoding;
  double seed_ms = 0, seed_bytes = 0;      // seed 000 §3.11 (0: not in the table)
  double brute_min_ms = 0, brute_median_ms = 0, brute_bytes = 0;  // ms for the ray set
  double tree_min_ms = 0, tree_median_ms = 0, tree_bytes = 0;
  uint64_t disagreements = 0;              // against the oracle, both layouts
};

struct EncodingOptions {
  size_t rays = 1024;
  uint32_t repeat = 7;
  uint64_t seed = 1;
};

std::vector<EncodingRow> bench_encodings(const Mesh& mesh, const std::string& name, const EncodingOptions& o);

}  // namespace meshcast::bench
