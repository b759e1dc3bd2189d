#include "gpu/method_table.h"

#include <algorithm>
#include <vector>

#include "layout/blob_format.h"
#include "layout/names.h"
#include "meshcast/errors.h"
#include "shaders/aabblist_bitpack.h"
#include "shaders/aabblist_float3.h"
#include "shaders/aabbtree_float3.h"
#include "shaders/aabbtree_strip.h"
#include "shaders/bruteforce_bitpack.h"
#include "shaders/bruteforce_float3.h"
#include "shaders/lbvh_float3.h"
#include "shaders/octtree_cluster.h"
#include "shaders/quadtree_i8.h"
#include "shaders/resolve_bitpack.h"
#include "shaders/resolve_float3.h"
#include "shaders/skdtree_float3.h"

namespace meshcast::gpu {

namespace {

#define MC_SPIRV(shader) Spirv{shader##_spv, sizeof shader##_spv}

using TF = TreeFormat;
using TRI = TriangleFormat;

// In the order of seed 000 §7's table: the tests, the stiff and extreme
// suite, bench gpu and bench error run the lines in this order. A method
// that reads several layouts lists first the one named when a blob fits none.
const MethodReading kTable[] = {
    {{"aabbtree", {TF::AABBTree, TRI::Float3}}, MC_SPIRV(aabbtree_float3), {}, make_walker},
    {{"aabbtree", {TF::AABBTree, TRI::UncompressedStrip}}, MC_SPIRV(aabbtree_strip), {}, make_walker},
    {{"quadtree", {TF::QuadTreeHalfFloat, TRI::Indexed8BitPackSOA4}}, MC_SPIRV(quadtree_i8), {}, make_walker},
    {{"octtree", {TF::OctTreeCompressed, TRI::ClusterBitPackSOA8}}, MC_SPIRV(octtree_cluster), {}, make_walker},
    {{"octtree", {TF::OctTreeCompressed, TRI::ClusterFloat3SOA8}}, MC_SPIRV(octtree_cluster), {}, make_walker},
    {{"aabblist", {TF::AABBList, TRI::Float3SOA128}}, MC_SPIRV(aabblist_float3), MC_SPIRV(resolve_float3),
     make_aabblist_method},
    {{"aabblist", {TF::AABBList, TRI::BitPackSOA128}}, MC_SPIRV(aabblist_bitpack), MC_SPIRV(resolve_bitpack),
     make_aabblist_method},
    {{"skdtree", {TF::SKDTree, TRI::Float3}}, MC_SPIRV(skdtree_float3), {}, make_walker},
    {{"lbvh", {TF::StacklessLBVH, TRI::Float3}}, MC_SPIRV(lbvh_float3), {}, make_walker},
    {{"bruteforce", {TF::BruteForce, TRI::BitPackSOA128}}, MC_SPIRV(bruteforce_bitpack), MC_SPIRV(resolve_bitpack),
     make_bruteforce},
    {{"bruteforce", {TF::BruteForce, TRI::Float3SOA128}}, MC_SPIRV(bruteforce_float3), MC_SPIRV(resolve_float3),
     make_bruteforce},
};

#undef MC_SPIRV

// The blob's layout as its header states it; nothing for a buffer too
// short to say (validation names what is wrong with it).
bool header_layout(std::span<const uint8_t> blob, uint32_t& tree, uint32_t& triangles) {
  if (blob.size() < sizeof(layout::BlobHeader)) return false;
  const layout::BlobHeader& h = layout::header_of(blob.data());
  tree = h.tree_format, triangles = h.triangle_format;
  return true;
}

bool reads(const MethodLayout& m, uint32_t tree, uint32_t triangles) {
  return uint32_t(m.layout.tree) == tree && uint32_t(m.layout.triangles) == triangles;
}

}  // namespace

std::span<const MethodReading> method_table() { return kTable; }

std::span<const MethodLayout> method_layouts() {
  static const std::vector<MethodLayout> kLayouts = [] {
    std::vector<MethodLayout> all;
    for (const MethodReading& line : kTable) all.push_back(line.what);
    return all;
  }();
  return kLayouts;
}

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const MethodReading& line : kTable)
    if (std::find(names.begin(), names.end(), line.what.method) == names.end()) names.push_back(line.what.method);
  return names;
}

std::string method_reading(std::span<const uint8_t> blob) {
  uint32_t tree = 0, triangles = 0;
  if (!header_layout(blob, tree, triangles)) return "";
  for (const MethodReading& line : kTable)
    if (reads(line.what, tree, triangles)) return line.what.method;
  return "";
}

std::string layouts_read_by(const std::string& method) {
  std::vector<std::string> names;
  for (const MethodReading& line : kTable)
    if (method == line.what.method) names.push_back(layout_name(line.what.layout));
  std::string text;
  for (size_t i = 0; i < names.size(); ++i) text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return text;
}

const MethodReading& method_line(const std::string& method, std::span<const uint8_t> blob) {
  uint32_t tree = 0, triangles = 0;
  const bool known = header_layout(blob, tree, triangles);
  const MethodReading* first = nullptr;
  for (const MethodReading& line : kTable) {
    if (method != line.what.method) continue;
    if (known && reads(line.what, tree, triangles)) return line;
    if (!first) first = &line;
  }
  if (first) return *first;
  std::string valid;
  for (const std::string& n : method_names()) valid += " " + n;
  throw InputError("unknown GPU method '" + method + "'; implemented:" + valid);
}

std::unique_ptr<Method> make_method(Context& ctx, const std::string& method, std::span<const uint8_t> blob,
                                    const std::string& name, uint32_t slots, uint32_t flags, uint32_t max_hits) {
  const MethodReading& line = method_line(method, blob);
  return line.make(ctx, blob, name, line, slots, flags, max_hits);
}

}  // namespace meshcast::gpu
