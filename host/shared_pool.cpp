#include "host/shared_pool.h"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>

namespace meshcast::host {

uint32_t every_core() {
  cpu_set_t allowed;
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0 && CPU_COUNT(&allowed) > 0) return uint32_t(CPU_COUNT(&allowed));
  return std::max(1u, std::thread::hardware_concurrency());
}

// The process's one pool, as wide as the most threads a call has asked
// for: a call of fewer threads runs that many of its workers (below), so
// a sweep of thread counts keeps one pool, not one a count. A wider call
// replaces the pool; the narrower one is joined once the calls still on it
// return (each holds it). A child forked from the process
// (multiprocessing's default on Linux) has the pool but none of its
// threads: it makes its own and leaves the parent's alone (joining threads
// it does not have would wait for ever).
namespace {

// The pool's lock, held across a fork (pthread_atfork) so that a child
// never inherits it locked by a thread it does not have.
std::mutex& pool_mutex() {
  static std::mutex mutex;
  static const bool held_across_forks = [] {
    pthread_atfork([] { pool_mutex().lock(); }, [] { pool_mutex().unlock(); }, [] { pool_mutex().unlock(); });
    return true;
  }();
  (void)held_across_forks;
  return mutex;
}

}  // namespace

std::shared_ptr<WorkerPool> shared_pool(uint32_t threads) {
  static std::shared_ptr<WorkerPool> pool;
  static pid_t owner = getpid();
  std::lock_guard<std::mutex> lock(pool_mutex());
  if (owner != getpid()) {
    new std::shared_ptr<WorkerPool>(std::move(pool));  // the parent's, never destroyed here
    owner = getpid();
  }
  if (!pool || pool->threads() < threads) pool = std::make_shared<WorkerPool>(threads);
  return pool;
}

void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk) {
  if (threads <= 1 || plan.chunks <= 1) return for_each_chunk(plan, nullptr, chunk);
  const std::shared_ptr<WorkerPool> pool = shared_pool(threads);
  // `threads` runners on the pool, each taking the plan's chunks in turn:
  // at most that many run at once, however wide the pool is.
  Chunks runners;
  runners.chunks = runners.count = std::min<size_t>(threads, plan.chunks);
  std::atomic<size_t> next{0};
  for_each_chunk(runners, pool.get(), [&](size_t) {
    for (size_t c = next++; c < plan.chunks; c = next++) chunk(c);
  });
}

}  // namespace meshcast::host
