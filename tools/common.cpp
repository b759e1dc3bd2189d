#include "tools/common.h"

#include <algorithm>
#include <cstring>

#include "cpu/rays.h"
#include "cpu/trace.h"
#include "io/read_mesh.h"
#include "layout/blob.h"

namespace meshcast::tools {

Loaded load_mesh_or_blob(const std::string& path, const BuildOptions& options) {
  Loaded out;
  auto t0 = std::chrono::steady_clock::now();
  std::vector<uint8_t> head = read_file(path);
  uint32_t magic = 0;
  if (head.size() >= 4) std::memcpy(&magic, head.data(), 4);
  if (magic == MC_BLOB_MAGIC) {
    std::string why = layout::validate(head);
    if (!why.empty()) throw InputError(path + ": " + why);
    out.blob = std::move(head);
    out.load_ms = ms_since(t0);
    return out;
  }
  out.mesh = read_mesh(path);
  out.load_ms = ms_since(t0);
  auto t1 = std::chrono::steady_clock::now();
  out.blob = build_blob(*out.mesh, options, path, &out.report);
  out.build_ms = ms_since(t1);
  return out;
}

BuildOptions layout_options(const std::string& layout, uint32_t leaf, const std::string& splitter) {
  BuildOptions o = parse_layout(layout);
  o.leaf_size = leaf;
  if (!splitter.empty()) o.splitter = parse_splitter(splitter);  // else the layout's (Morton for StacklessLBVH)
  return o;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

SectionBytes section_bytes(const std::vector<uint8_t>& blob) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  SectionBytes s;
  s.header = sizeof(layout::BlobHeader);
  s.nodes = h.node_bytes;
  s.triangles = h.tree_size - h.node_bytes;
  s.vertices = h.vertex_size;
  s.remap = h.remap_size;
  s.total = blob.size();
  return s;
}

}  // namespace meshcast::tools
