#include "bench/encodings.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>

#include "cpu/agreement.h"
#include "cpu/encode.h"
#include "cpu/oracle.h"
#include "cpu/rays.h"
#include "cpu/trace.h"
#include "layout/blob.h"

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

struct Timing {
  double min_ms, median_ms, bytes;
  uint64_t disagreements;
};

Timing measure(const Mesh& mesh, const std::string& name, const std::string& layout, const std::vector<Ray>& rays,
               const std::vector<OracleHit>& oracle, uint32_t repeat) {
  std::vector<uint8_t> blob = build_blob(mesh, parse_layout(layout), name);
  BlobView view(blob, layout);
  std::vector<Hit> hits(rays.size());
  std::vector<double> ms;
  for (uint32_t r = 0; r < repeat; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    view.trace(rays, hits);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  const layout::BlobHeader& h = layout::header_of(blob.data());
  // Bytes of the triangle encoding: its blocks and its shared vertices.
  double bytes = double(h.tree_size - h.node_bytes + h.vertex_size) / h.triangle_count;
  // Formats that move vertices are judged on the triangles they store.
  double tolerance = 1e-5 * mesh.bounds().diagonal();
  Agreement a;
  if (moves_vertices(h.triangle_format)) {
    Mesh stored = stored_mesh(blob);
    OracleTree stored_tree(stored);
    std::vector<OracleHit> answers(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) answers[i] = stored_tree.closest(rays[i]);
    a = compare(stored, rays, hits, answers, tolerance);
  } else {
    a = compare(mesh, rays, hits, oracle, tolerance);
  }
  return {ms.front(), ms[ms.size() / 2], bytes, a.wrong + a.t_errors};
}

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
    Timing brute = measure(mesh, name, layout, rays, oracle, o.repeat);
    Timing in_tree = measure(mesh, name, "QuadTree/" + encoding, rays, oracle, o.repeat);
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
