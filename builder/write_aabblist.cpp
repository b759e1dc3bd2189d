// AABBList (seed 000 §7, the GPU's method 2): the leaves of the tree from
// record_tree() are records of at most brute_chunk() triangles, batch after
// batch in group_batches() order; each run of records that adds up to
// MC_LIST_BATCH triangles (the last: the rest) becomes one batch, written
// as an entry with the box of what its records decode to.
#include "builder/writer.h"
#include "layout/tree/aabblist.h"

namespace meshcast {

namespace {

class ListWriter : public TreeWriter {
 public:
  // Batch after batch in the options' grouping; the records tile each batch.
  BuildTree build(const TreeInput& in, uint32_t) override {
    static_assert(MC_LIST_BATCH % MC_BRUTE_CHUNK == 0 && MC_LIST_BATCH % 128 == 0, "records must tile a batch");
    return record_tree(in, group_batches(in.boxes, MC_LIST_BATCH, in.options.grouping));
  }

  void plan(Writer& w) override {
    const BuildTree& t = w.tree;
    first_.clear();
    uint64_t records = 0;
    uint32_t held = MC_LIST_BATCH;  // triangles in the open batch
    for (uint32_t n = 1; n < t.nodes.size(); ++n) {
      if (held == MC_LIST_BATCH) first_.push_back(n), held = 0;
      held += t.nodes[n].count;
      if (held > MC_LIST_BATCH) throw std::logic_error("AABBList: records straddle a batch boundary");
      records += w.record_bytes(n);
    }
    first_.push_back(uint32_t(t.nodes.size()));
    const uint64_t entries = uint64_t(first_.size() - 1) * MC_LIST_ENTRY_BYTES;
    if (entries + records > 0x7FFFFFFFu)
      throw InputError("the AABBList section of " + std::to_string(entries + records) + " bytes exceeds 2 GiB");
    w.h.node_count = uint32_t(first_.size() - 1);
    w.h.node_bytes = uint32_t(entries);
    w.h.triangle_base = uint32_t(entries);
    w.h.tree_size = uint32_t(entries + records);
    w.h.root = 0;
  }

  void fill(Writer& w) override {
    uint32_t at = w.h.triangle_base;
    Box3 all;
    for (uint32_t b = 0; b + 1 < first_.size(); ++b) {
      layout::ListEntry e{};
      e.records = at;
      Box3 box;
      for (uint32_t n = first_[b]; n < first_[b + 1]; ++n) {
        at = w.write_record(n, at);  // refits the record's box to what it decodes to
        box.grow(w.tree.nodes[n].box);
        e.count += w.tree.nodes[n].count;
      }
      for (int a = 0; a < 3; ++a) e.min[a] = box.min[a], e.max[a] = box.max[a];
      std::memcpy(w.bytes.data() + w.h.tree_offset + uint64_t(b) * MC_LIST_ENTRY_BYTES, &e, sizeof e);
      all.grow(box);
    }
    w.frame(all);
  }

  uint32_t depth(const BuildTree&) const override { return 1; }

 private:
  std::vector<uint32_t> first_;  // batch b's records: leaves first_[b] .. first_[b + 1] - 1
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::AABBList, const BuildOptions&) { return std::make_unique<ListWriter>(); }

}  // namespace meshcast
