// Where the CPU backend's work runs. An engine with its own job system
// implements JobSystem; without one, the caster makes a WorkerPool over the
// machine's cores.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace meshcast::host {

// run(count, work) arranges for work(i) to be called once for every i in
// [0, count), on any threads, and may return before they run. `work` stays
// alive until every call has returned (the caster keeps it per frame slot).
class JobSystem {
 public:
  virtual ~JobSystem() = default;
  virtual void run(uint32_t count, const std::function<void(uint32_t)>& work) = 0;
  virtual uint32_t threads() const = 0;  // how many run at once (for sizing the jobs)
};

// Worker threads taking job indices from a queue of posted runs. The queue
// keeps its capacity, so after warm-up posting allocates nothing.
class WorkerPool : public JobSystem {
 public:
  explicit WorkerPool(uint32_t threads);  // 0: std::thread::hardware_concurrency()
  ~WorkerPool() override;
  void run(uint32_t count, const std::function<void(uint32_t)>& work) override;
  uint32_t threads() const override { return uint32_t(workers_.size()); }

 private:
  struct Run {
    const std::function<void(uint32_t)>* work;
    uint32_t count, next;
  };
  void loop();
  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<Run> queue_;  // runs with indices left, oldest first
  bool stop_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace meshcast::host
