// The box cache of seed 004: a zero-byte node's box costs up to 18 vertex
// fetches, so boxes once computed are kept in a small direct-mapped table
// (the seed's 4K entries), one per thread and shared by every mesh that
// thread walks, never between threads. An entry is known by the blob's
// address, its checksum and the node's position, so a blob freed and
// another built at the same address cannot return a stale box unless it
// has the same bytes (and then the same boxes).
#pragma once
#include <cstdint>
#include <cstring>
#include <memory>

#include "cpu/isa.h"

namespace meshcast {
MC_ISA_BEGIN

class BoxCache {
 public:
  static constexpr uint32_t kEntries = 4096;

  bool find(const uint8_t* blob, uint32_t checksum, uint32_t node, float mn[3], float mx[3]) const {
    const Entry& e = entries_[slot(checksum, node)];
    if (e.blob != blob || e.node != node || e.checksum != checksum) return false;
    std::memcpy(mn, e.box, 12), std::memcpy(mx, e.box + 3, 12);
    return true;
  }
  void put(const uint8_t* blob, uint32_t checksum, uint32_t node, const float mn[3], const float mx[3]) {
    Entry& e = entries_[slot(checksum, node)];
    e.blob = blob, e.checksum = checksum, e.node = node;
    std::memcpy(e.box, mn, 12), std::memcpy(e.box + 3, mx, 12);
  }
  static constexpr size_t bytes() { return sizeof(Entry) * kEntries; }

  // The calling thread's cache, made on its first use.
  static BoxCache& for_this_thread() {
    thread_local std::unique_ptr<BoxCache> cache = std::make_unique<BoxCache>();
    return *cache;
  }

 private:
  struct Entry {
    const uint8_t* blob = nullptr;
    uint32_t checksum = 0, node = 0;
    float box[6] = {};
  };
  static uint32_t slot(uint32_t checksum, uint32_t node) { return ((node * 0x9E3779B1u) ^ checksum) >> 20; }
  Entry entries_[kEntries];
};

MC_ISA_END
}  // namespace meshcast
