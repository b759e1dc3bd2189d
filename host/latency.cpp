#include "host/latency.h"

#include <algorithm>
#include <cmath>

namespace meshcast::host {

void LatencyRecords::add(const BatchRecord& r) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (records_.size() < kRecords) records_.push_back(r);
  else records_[recorded_ % kRecords] = r;
  ++recorded_;
}

std::vector<BatchRecord> LatencyRecords::all() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return records_;
}

void LatencyRecords::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  records_.clear();
  recorded_ = 0;
}

Percentiles LatencyRecords::percentiles(Backend b, uint32_t rays) const {
  std::vector<double> latency;
  double total_ms = 0, total_rays = 0;
  for (const BatchRecord& r : all()) {
    if (r.ran_on != b || (rays && r.rays != rays)) continue;
    latency.push_back(r.latency_ms);
    total_ms += r.latency_ms, total_rays += r.rays;
  }
  Percentiles p;
  p.batches = latency.size();
  if (latency.empty()) return p;
  std::sort(latency.begin(), latency.end());
  p.p50_ms = latency[(latency.size() - 1) / 2];
  p.p99_ms = latency[std::min(latency.size() - 1, size_t(std::ceil(0.99 * double(latency.size()))) - 1)];
  p.rays_per_second = total_ms > 0 ? total_rays / (total_ms * 1e-3) : 0;
  return p;
}

}  // namespace meshcast::host
