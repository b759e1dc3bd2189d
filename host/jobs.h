// The caster's own workers, when the engine gives it no job system
// (meshcast/jobs.h): a pool over the machine's cores.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "meshcast/jobs.h"

namespace meshcast::host {

// Worker threads taking job indices from a queue of posted runs. The queue
// keeps its capacity, so after warm-up posting allocates nothing.
class WorkerPool : public JobSystem {
 public:
  // 0: std::thread::hardware_concurrency(). meshcast::Error, saying which
  // thread, when the system refuses to start one.
  explicit WorkerPool(uint32_t threads);
  ~WorkerPool() override;
  void run(uint32_t count, const std::function<void(uint32_t)>& work) override;
  uint32_t threads() const override { return uint32_t(workers_.size()); }

 private:
  struct Run {
    const std::function<void(uint32_t)>* work;
    uint32_t count, next;
  };
  void loop();
  void stop();  // the workers finish the queue and are joined
  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<Run> queue_;  // runs with indices left, oldest first
  bool stop_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace meshcast::host
