// AABBList (seed 000 §7): a flat list of batch boxes over BruteForce
// records (formats.h gives the bytes). The GPU tests every ray against
// every box and then only the batches a ray's box test let through; the
// CPU walker does the same one ray at a time.
#pragma once
#include <cstddef>
#include <cstdint>

#include "layout/blob_format.h"

namespace meshcast::layout {

struct ListEntry {
  float min[3], max[3];
  uint32_t count;    // triangles in the batch
  uint32_t records;  // tree-section offset of its first record
};
static_assert(sizeof(ListEntry) == MC_LIST_ENTRY_BYTES && offsetof(ListEntry, min) == MC_LIST_MIN_AT &&
              offsetof(ListEntry, max) == MC_LIST_MAX_AT && offsetof(ListEntry, count) == MC_LIST_COUNT_AT &&
              offsetof(ListEntry, records) == MC_LIST_RECORDS_AT);

inline ListEntry load_list_entry(const uint8_t* tree, uint32_t batch) {
  return load<ListEntry>(tree + uint64_t(batch) * MC_LIST_ENTRY_BYTES);
}

// Where batch b's records end: the next batch's first record, or the end of
// the tree section after the last batch (validation proves the tiling).
inline uint32_t list_records_end(const uint8_t* tree, const BlobHeader& h, uint32_t batch) {
  return batch + 1 < h.node_count ? load_list_entry(tree, batch + 1).records : h.tree_size;
}

}  // namespace meshcast::layout
