// `meshcast bench splitters` and `meshcast bench leafsize`: seed 000 §4.1 and
// §4.2 on this machine.
#pragma once
#include <string>
#include <vector>

#include "bench/measure.h"

namespace meshcast::bench {

struct TreeRow {
  std::string label, layout;
  double seed_ms = 0;  // the source's figure, 0 where it has none
  Timing timing;
  double seed_tree_bytes = 0;
};

// §4.1: every splitter, AABBTree/Float3 and AABBTree/Float3SOA4, leaf 8.
std::vector<TreeRow> bench_splitters(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);
// §4.2: leaf sizes 4, 8, 16, AABBTree/Float3, Binning.
std::vector<TreeRow> bench_leafsize(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);
// §6, first table: every tree format with Float3, Binning, leaf 8.
std::vector<TreeRow> bench_trees(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);

}  // namespace meshcast::bench
