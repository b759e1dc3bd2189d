// AABBList's readings: validation and the leaf descent over the batch
// entries of layout/tree/aabblist.h and their records.
#include "layout/tree/tree_walks.h"

#include "layout/tree/aabblist.h"
#include "layout/triangles/codecs.h"

namespace meshcast::layout {

namespace {

// AABBList: each batch's box above its records.
void descend_aabblist(Descent& d) {
  for (uint32_t b = 0; b < d.h.node_count; ++b) {
    ListEntry e = load_list_entry(d.tree, b);
    d.path.push_back(box_of(e.min, e.max));
    d.records(e.records, list_records_end(d.tree, d.h, b));
    d.path.pop_back();
  }
}

}  // namespace

// AABBList: the entries, then the batches' records tiling the rest of the
// section in batch order, each batch's records holding its count, and every
// batch but the last full (the shaders find records by arithmetic).
std::string validate_tree(tree::AABBList, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  const uint8_t* tree = blob + h.tree_offset;
  if (h.node_count == 0 || h.triangle_base != uint64_t(h.node_count) * MC_LIST_ENTRY_BYTES)
    return "AABBList of " + num(h.node_count) + " batches does not start its records at tree offset " +
           num(uint64_t(h.node_count) * MC_LIST_ENTRY_BYTES);
  uint64_t at = h.triangle_base, records = 0;
  for (uint32_t b = 0; b < h.node_count; ++b) {
    const ListEntry e = load_list_entry(tree, b);
    const std::string batch = "AABBList batch " + num(b);
    if (e.records != at) return batch + " starts at tree offset " + num(e.records) + ", not " + num(at);
    if (e.count == 0 || e.count > MC_LIST_BATCH || (b + 1 < h.node_count && e.count != MC_LIST_BATCH))
      return batch + " holds " + num(e.count) + " triangles (" + num(MC_LIST_BATCH) + " each, the last 1.." +
             num(MC_LIST_BATCH) + ")";
    const uint32_t end = list_records_end(tree, h, b);
    if (end < at || end > h.tree_size) return batch + "'s records end at " + num(end) + ", outside the tree section";
    uint64_t held = 0;
    if (std::string why = check_records(codec, blob, h, &at, end, &held, &records); !why.empty()) return why;
    if (held != e.count) return batch + "'s records hold " + num(held) + " triangles, its entry says " + num(e.count);
    *triangles += held;
  }
  return "";
}

void from_root(Descent& d, tree::AABBList) { descend_aabblist(d); }

}  // namespace meshcast::layout
