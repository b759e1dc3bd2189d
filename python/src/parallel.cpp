#include "python/src/parallel.h"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "host/jobs.h"

namespace meshcast::python {

uint32_t thread_count(long long requested, const char* what) {
  if (requested < 0 || requested > 1024)
    throw std::invalid_argument(std::string(what) + " " + std::to_string(requested) + ": from 0 (every core) to 1024");
  return requested ? uint32_t(requested) : std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// One pool for each thread count asked for, made on first use and kept for
// the process: a call's threads are its pool's, so calls of different
// counts from several Python threads do not share (or wait on) one queue
// of a wrong width. WorkerPool::run takes posts from any thread.
host::WorkerPool& pool_of(uint32_t threads) {
  static std::mutex mutex;
  static std::map<uint32_t, std::unique_ptr<host::WorkerPool>> pools;
  std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<host::WorkerPool>& pool = pools[threads];
  if (!pool) pool = std::make_unique<host::WorkerPool>(threads);
  return *pool;
}

}  // namespace

Chunks plan_chunks(size_t count, uint32_t threads, size_t most) {
  Chunks plan;
  plan.count = count;
  const size_t wanted = size_t(threads) * 8;
  plan.rays = std::max<size_t>(64, std::min(most, (count + wanted - 1) / wanted));
  plan.chunks = (count + plan.rays - 1) / plan.rays;
  return plan;
}

void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk) {
  if (plan.chunks == 0) return;
  if (threads <= 1 || plan.chunks == 1) {
    for (size_t i = 0; i < plan.chunks; ++i) chunk(i);
    return;
  }
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
  // run() counts in 32 bits: 2^32 chunks of at least 64 rays would be 8 TB of rays.
  if (plan.chunks > UINT32_MAX) throw std::length_error("meshcast: a batch of more than 2^32 chunks of rays");
  pool_of(threads).run(uint32_t(plan.chunks), work);
  std::unique_lock<std::mutex> lock(mutex);
  done.wait(lock, [&] { return finished == plan.chunks; });
  if (failure) std::rethrow_exception(failure);
}

}  // namespace meshcast::python
