#include "host/jobs.h"

#include <algorithm>
#include <string>
#include <system_error>

#include "meshcast/errors.h"

namespace meshcast::host {

WorkerPool::WorkerPool(uint32_t threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  queue_.reserve(64);
  try {
    for (uint32_t i = 0; i < threads; ++i) workers_.emplace_back([this] { loop(); });
  } catch (const std::system_error& e) {
    // The system refused a thread (its limit of threads or of address
    // space): those started are joined, not destroyed joinable
    // (std::terminate), and the caller hears why in words.
    const size_t started = workers_.size();
    stop();
    throw Error("meshcast: the system refused to start worker thread " + std::to_string(started + 1) + " of " +
                std::to_string(threads) + " (" + e.what() +
                "): ask for fewer threads, or raise the process's limits on threads and address space");
  } catch (...) {  // std::bad_alloc (a thread's own state, the vector growing): the same joining first
    stop();
    throw;
  }
}

WorkerPool::~WorkerPool() { stop(); }

void WorkerPool::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void WorkerPool::run(uint32_t count, const std::function<void(uint32_t)>& work) {
  if (count == 0) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back({&work, count, 0});
  }
  wake_.notify_all();
}

// One index at a time under the lock: jobs are whole chunks of rays, so the
// lock is taken a few times a batch and a thread, not a ray.
void WorkerPool::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, nothing left
    Run& r = queue_.front();
    const std::function<void(uint32_t)>* work = r.work;
    const uint32_t index = r.next++;
    if (r.next == r.count) queue_.erase(queue_.begin());
    lock.unlock();
    (*work)(index);
    lock.lock();
  }
}

}  // namespace meshcast::host
