// BruteForce (seed 000 §3.11): no tree; the "tree" from record_tree() is
// node 0 (the whole mesh) and one leaf a chunk, each written as a record
// [count][block] in input order.
#include <numeric>

#include "builder/writer.h"

namespace meshcast {

namespace {

class BruteWriter : public TreeWriter {
 public:
  // The input order.
  BuildTree build(const TreeInput& in, uint32_t) override {
    std::vector<uint32_t> input(in.boxes.size());
    std::iota(input.begin(), input.end(), 0u);
    return record_tree(in, std::move(input));
  }

  void plan(Writer& w) override {
    uint64_t size = 0;
    for (uint32_t n = 1; n < w.tree.nodes.size(); ++n) size += w.record_bytes(n);
    if (size > 0x7FFFFFFFu) throw InputError("the BruteForce section of " + std::to_string(size) + " bytes exceeds 2 GiB");
    w.h.tree_size = uint32_t(size);
    w.h.node_count = uint32_t(w.tree.nodes.size() - 1);
    w.h.node_bytes = w.h.node_count * MC_BRUTE_RECORD_BYTES;  // the count words
    w.h.triangle_base = 0;
    w.h.root = 0;
  }

  void fill(Writer& w) override {
    uint32_t at = 0;
    Box3 all;
    for (uint32_t n = 1; n < w.tree.nodes.size(); ++n) {
      at = w.write_record(n, at);
      all.grow(w.tree.nodes[n].box);
    }
    w.frame(all);
  }

  uint32_t depth(const BuildTree&) const override { return 0; }
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::BruteForce, const BuildOptions&) { return std::make_unique<BruteWriter>(); }

}  // namespace meshcast
