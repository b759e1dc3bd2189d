// BruteForce (seed 000 §3.11): no tree; the "tree" from chunk_tree() is
// node 0 (the whole mesh) and one leaf a chunk, each written as a record
// [count][block] in input order.
#include "cpu/writer.h"

namespace meshcast {

namespace {

class BruteWriter : public TreeWriter {
 public:
  void plan(Writer& w) override { write_bruteforce(w); }
  void fill(Writer& w) override { fill_bruteforce(w); }
  uint32_t depth(const BuildTree&) const override { return 0; }

 private:
  static void write_bruteforce(Writer& w) {
    uint64_t size = 0;
    for (size_t n = 1; n < w.tree.nodes.size(); ++n)
      size += MC_BRUTE_RECORD_BYTES + w.leaf_bytes[n];
    if (size > 0x7FFFFFFFu) throw InputError("the BruteForce section of " + std::to_string(size) + " bytes exceeds 2 GiB");
    w.h.tree_size = uint32_t(size);
    w.h.node_count = uint32_t(w.tree.nodes.size() - 1);
    w.h.node_bytes = w.h.node_count * MC_BRUTE_RECORD_BYTES;  // the count words
    w.h.triangle_base = 0;
    w.h.root = 0;
  }

  static void fill_bruteforce(Writer& w) {
    uint32_t at = 0;
    Box3 all;
    for (size_t n = 1; n < w.tree.nodes.size(); ++n) {
      const BuildNode& leaf = w.tree.nodes[n];
      std::memcpy(w.bytes.data() + w.h.tree_offset + at, &leaf.count, 4);
      w.write_leaf(uint32_t(n), at + MC_BRUTE_RECORD_BYTES);
      all.grow(leaf.box);
      at += MC_BRUTE_RECORD_BYTES + w.leaf_bytes[n];
    }
    w.frame(all);
  }
};

}  // namespace

std::unique_ptr<TreeWriter> make_bruteforce_writer() { return std::make_unique<BruteWriter>(); }

}  // namespace meshcast
