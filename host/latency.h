// The latency records of the batches a caster's game collected
// (Caster::records(), Caster::percentiles()): the last kRecords of them,
// a ring, so a long game does not grow it. Every call may come from
// several threads at once.
#pragma once
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "meshcast/caster.h"

namespace meshcast::host {

class LatencyRecords {
 public:
  static constexpr size_t kRecords = 1 << 16;

  LatencyRecords() { records_.reserve(kRecords); }  // add() allocates nothing
  void add(const BatchRecord& r);
  std::vector<BatchRecord> all() const;
  void clear();
  // Of one backend (all sizes together), or of one batch size.
  Percentiles percentiles(Backend b, uint32_t rays) const;

 private:
  mutable std::mutex mutex_;
  std::vector<BatchRecord> records_;
  uint64_t recorded_ = 0;  // ever added since the last clear(): the ring's next place
};

}  // namespace meshcast::host
