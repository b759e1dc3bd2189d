#include "host/chunks.h"

#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>

namespace meshcast::host {

Chunks plan_chunks(size_t count, uint32_t threads, size_t most) {
  Chunks plan;
  plan.count = count;
  const size_t wanted = size_t(std::max(1u, threads)) * 8;
  plan.rays = std::max<size_t>(64, std::min(most, (count + wanted - 1) / wanted));
  plan.chunks = (count + plan.rays - 1) / plan.rays;
  return plan;
}

void for_each_chunk(const Chunks& plan, JobSystem* jobs, const std::function<void(size_t)>& chunk) {
  if (plan.chunks == 0) return;
  if (jobs == nullptr || plan.chunks == 1) {
    for (size_t i = 0; i < plan.chunks; ++i) chunk(i);
    return;
  }
  // run() counts in 32 bits: 2^32 chunks of at least 64 rays would be 8 TB of rays.
  if (plan.chunks > UINT32_MAX) throw std::length_error("meshcast: a batch of more than 2^32 chunks of rays");
  std::mutex mutex;
  std::condition_variable done;
  size_t finished = 0;
  std::exception_ptr failure;
  const std::function<void(uint32_t)> work = [&](uint32_t index) {
    std::exception_ptr thrown;
    try {
      chunk(index);
    } catch (...) {
      thrown = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex);
    if (thrown && !failure) failure = thrown;
    if (++finished == plan.chunks) done.notify_one();
  };
  jobs->run(uint32_t(plan.chunks), work);
  std::unique_lock<std::mutex> lock(mutex);
  done.wait(lock, [&] { return finished == plan.chunks; });
  if (failure) std::rethrow_exception(failure);
}

}  // namespace meshcast::host
