#include "python/src/parallel.h"

#include <sched.h>
#include <unistd.h>

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
  if (requested) return uint32_t(requested);
  // Every core this process may run on (a container's or taskset's share),
  // not every core the machine has.
  cpu_set_t allowed;
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0 && CPU_COUNT(&allowed) > 0) return uint32_t(CPU_COUNT(&allowed));
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// One pool for each thread count asked for, made on first use and kept for
// the process: a call's threads are its pool's, so calls of different
// counts from several Python threads do not share one queue of a wrong
// width. WorkerPool::run takes posts from any thread. A child forked from
// the process (multiprocessing's default on Linux) has the pools but none
// of their threads: it makes its own, and leaves the parent's alone
// (joining threads it does not have would wait for ever).
host::WorkerPool& pool_of(uint32_t threads) {
  static std::mutex mutex;
  static std::map<uint32_t, std::unique_ptr<host::WorkerPool>> pools;
  static pid_t owner = getpid();
  std::lock_guard<std::mutex> lock(mutex);
  if (owner != getpid()) {
    for (auto& [count, pool] : pools) (void)pool.release();
    pools.clear();
    owner = getpid();
  }
  std::unique_ptr<host::WorkerPool>& pool = pools[threads];
  if (!pool) pool = std::make_unique<host::WorkerPool>(threads);
  return *pool;
}

}  // namespace

void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk) {
  host::for_each_chunk(plan, threads > 1 ? &pool_of(threads) : nullptr, chunk);
}

}  // namespace meshcast::python
