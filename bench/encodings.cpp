#include "bench/encodings.h"

#include "bench/measure.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>

#include "check/agreement.h"
#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "check/oracle.h"
#include "check/ray_files.h"
#include "meshcast/blob.h"
#include "layout/blob_format.h"

namespace meshcast::bench {

namespace {

// Seed 000 §3.11: time for 1024 long rays against the Stanford Bunny
// (69,451 triangles) brute force on an i7-7700HQ, and bytes per triangle.
const std::map<std::string, std::pair<double, double>> kSeed = {
    {"Float3SOA8", {91.4, 36.0}},          {"Float3SOA4", {169.4, 36.0}},
    {"BitPackSOA4", {240.1, 24.0}},        {"Indexed8BitPackSOA4", {362.3, 8.8}},
    {"Indexed16BitPackSOA4", {376.3, 10.0}}, {"Indexed32BitPackSOA4", {379.4, 16.0}},
    {"Indexed16SOA4", {400.2, 12.0}},      {"Indexed32SOA4", {401.9, 18.0}},
    {"Float3", {671.7, 36.0}},             {"Indexed16", {760.7, 12.0}},
    {"Indexed32", {765.6, 18.0}},          {"UncompressedStrip", {826.6, 13.1}},
    {"CompressedStrip", {891.9, 8.8}},     {"BitPack", {932.3, 24.0}},
};

}  // namespace

std::vector<EncodingRow> bench_encodings(const Mesh& mesh, const std::string& name, const EncodingOptions& o) {
  std::vector<Ray> rays = make_rays(mesh, RayKind::Long, o.rays, o.seed);
  OracleTree tree(mesh);
  std::vector<OracleHit> oracle(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) oracle[i] = tree.closest(rays[i]);

  std::vector<EncodingRow> rows;
  for (const std::string& layout : layout_names()) {
    if (layout.rfind("BruteForce/", 0) != 0) continue;
    std::string encoding = layout.substr(std::string("BruteForce/").size());
    EncodingRow row;
    row.encoding = encoding;
    if (auto it = kSeed.find(encoding); it != kSeed.end()) row.seed_ms = it->second.first, row.seed_bytes = it->second.second;
    Timing brute = measure(mesh, name, parse_layout(layout), rays, oracle, o.repeat);
    Timing in_tree = measure(mesh, name, parse_layout("QuadTree/" + encoding), rays, oracle, o.repeat);
    row.brute_min_ms = brute.min_ms, row.brute_median_ms = brute.median_ms, row.brute_bytes = brute.bytes;
    row.tree_min_ms = in_tree.min_ms, row.tree_median_ms = in_tree.median_ms, row.tree_bytes = in_tree.bytes;
    row.disagreements = brute.disagreements + in_tree.disagreements;
    rows.push_back(row);
    std::fprintf(stderr, "  %s: brute force %.1f ms, QuadTree %.3f ms\n", encoding.c_str(), brute.min_ms, in_tree.min_ms);
  }
  std::sort(rows.begin(), rows.end(), [](const EncodingRow& a, const EncodingRow& b) { return a.brute_min_ms < b.brute_min_ms; });
  return rows;
}

}  // namespace meshcast::bench
