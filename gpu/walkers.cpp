// The one-ray-a-thread methods of seed 000 §7: a tree walked per thread
// (a stack of its own, or none for the StacklessLBVH), one dispatch a batch.
// Each is a shader and the layout it reads; the host side is the same.
#include <algorithm>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "meshcast/mesh.h"
#include "layout/blob_format.h"
#include "gpu/batch.h"
#include "shaders/aabbtree_float3.h"
#include "shaders/aabbtree_strip.h"
#include "shaders/lbvh_float3.h"
#include "shaders/octtree_cluster.h"
#include "shaders/quadtree_i8.h"
#include "shaders/skdtree_float3.h"

namespace meshcast::gpu {

namespace {

struct Walker {
  const char* method;
  uint32_t tree, triangles;
  const uint32_t* spirv;
  size_t spirv_bytes;
};

const Walker kWalkers[] = {
    {"aabbtree", MC_TREE_AABBTREE, MC_TRI_FLOAT3, aabbtree_float3_spv, sizeof aabbtree_float3_spv},
    {"aabbtree", MC_TREE_AABBTREE, MC_TRI_UNCOMPRESSEDSTRIP, aabbtree_strip_spv, sizeof aabbtree_strip_spv},
    {"skdtree", MC_TREE_SKDTREE, MC_TRI_FLOAT3, skdtree_float3_spv, sizeof skdtree_float3_spv},
    {"lbvh", MC_TREE_STACKLESSLBVH, MC_TRI_FLOAT3, lbvh_float3_spv, sizeof lbvh_float3_spv},
    {"quadtree", MC_TREE_QUADTREEHALFFLOAT, MC_TRI_INDEXED8BITPACKSOA4, quadtree_i8_spv, sizeof quadtree_i8_spv},
    {"octtree", MC_TREE_OCTTREECOMPRESSED, MC_TRI_CLUSTERBITPACKSOA8, octtree_cluster_spv, sizeof octtree_cluster_spv},
};

class WalkMethod : public BatchMethod {
 public:
  WalkMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const Walker& w, uint32_t slots,
             uint32_t flags, uint32_t max_hits)
      : BatchMethod(ctx, blob, name, w.method, w.tree, w.triangles, slots, flags, max_hits),
        walk_(ctx, w.spirv, w.spirv_bytes, 5, sizeof(Push), slots, flags, max_hits) {}

 protected:
  void bind_all(uint32_t slot) override { walk_.bind(buffers(slot), slot); }
  bool reads_keys() const override { return false; }
  void record(VkCommandBuffer cb, uint32_t slot, uint32_t n) override {
    Push push{0, n, records_};
    walk_.dispatch(cb, slot, &push, (n + 63) / 64, 1, 1);
  }

 private:
  Pipeline walk_;
};

}  // namespace

std::unique_ptr<Method> make_bruteforce(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                        uint32_t slots, uint32_t flags, uint32_t max_hits);

std::vector<std::string> method_names() {
  std::vector<std::string> names{"bruteforce", "aabblist"};
  for (const Walker& w : kWalkers)
    if (std::find(names.begin(), names.end(), w.method) == names.end()) names.push_back(w.method);
  return names;
}

std::span<const MethodLayout> method_layouts() {
  static const MethodLayout kAll[] = {{"aabbtree", "AABBTree/Float3"},
                                      {"aabbtree", "AABBTree/UncompressedStrip"},
                                      {"quadtree", "QuadTreeHalfFloat/Indexed8BitPackSOA4"},
                                      {"octtree", "OctTreeCompressed/ClusterBitPackSOA8"},
                                      {"aabblist", "AABBList/Float3SOA128"},
                                      {"aabblist", "AABBList/BitPackSOA128"},
                                      {"skdtree", "SKDTree/Float3"},
                                      {"lbvh", "StacklessLBVH/Float3"},
                                      {"bruteforce", "BruteForce/BitPackSOA128"},
                                      {"bruteforce", "BruteForce/Float3SOA128"}};
  return kAll;
}

std::string method_reading(std::span<const uint8_t> blob) {
  if (blob.size() < sizeof(layout::BlobHeader)) return "";
  const layout::BlobHeader& h = layout::header_of(blob.data());
  const std::string name = layout_name(h.tree_format, h.triangle_format);
  for (const MethodLayout& c : method_layouts())
    if (name == c.layout) return c.method;
  return "";
}

std::unique_ptr<Method> make_method(Context& ctx, const std::string& method, std::span<const uint8_t> blob,
                                    const std::string& name, uint32_t slots, uint32_t flags, uint32_t max_hits) {
  if (method == "bruteforce") return make_bruteforce(ctx, blob, name, slots, flags, max_hits);
  // 2^21 pairs (16 MiB a slot): far below every device's
  // maxStorageBufferRange, and still thousands of rays a chunk on large meshes.
  if (method == "aabblist") return make_aabblist(ctx, blob, name, uint64_t(1) << 21, slots, flags, max_hits);
  // A method that reads several triangle formats takes the blob's; the
  // first listed is the one named when the blob fits none.
  const Walker* pick = nullptr;
  const uint32_t format = blob_triangle_format(blob);
  for (const Walker& w : kWalkers) {
    if (method != w.method) continue;
    if (!pick) pick = &w;
    if (w.triangles == format) {
      pick = &w;
      break;
    }
  }
  if (pick) return std::make_unique<WalkMethod>(ctx, blob, name, *pick, slots, flags, max_hits);
  std::string valid;
  for (const std::string& n : method_names()) valid += " " + n;
  throw InputError("unknown GPU method '" + method + "'; implemented:" + valid);
}

}  // namespace meshcast::gpu
