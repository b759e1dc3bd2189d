#include "python/src/parallel.h"

#include <algorithm>
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
// counts from several Python threads do not share one queue of a wrong
// width. WorkerPool::run takes posts from any thread.
host::WorkerPool& pool_of(uint32_t threads) {
  static std::mutex mutex;
  static std::map<uint32_t, std::unique_ptr<host::WorkerPool>> pools;
  std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<host::WorkerPool>& pool = pools[threads];
  if (!pool) pool = std::make_unique<host::WorkerPool>(threads);
  return *pool;
}

}  // namespace

Chunks plan_chunks(size_t count, uint32_t threads) { return host::plan_chunks(count, threads); }

void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk) {
  host::for_each_chunk(plan, threads > 1 ? &pool_of(threads) : nullptr, chunk);
}

}  // namespace meshcast::python
