// The threads one build may use (BuildOptions::threads): at most that many
// run at once, the caller's among them. Work handed out here never changes
// the blob: every part writes its own range and the parts are put together
// in the order a one-thread build makes them, so a build is byte-identical
// on any number of threads.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace meshcast {

// The most BuildOptions::threads may ask for.
constexpr uint32_t kMaxBuildThreads = 1024;

class BuildThreads {
 public:
  // 0: every hardware thread.
  explicit BuildThreads(uint32_t threads)
      : total_(threads ? threads : std::max(1u, std::thread::hardware_concurrency())), spare_(int(total_) - 1) {}
  uint32_t total() const { return total_; }

  // Runs main() on the caller's thread and side() beside it, on a thread
  // of its own when one is spare (else after main(), on the caller's);
  // returns when both are done. main()'s exception is rethrown first, as
  // a one-thread build, which builds main()'s part first, would raise it.
  template <class Side, class Main>
  void fork(Side&& side, Main&& main) {
    std::thread worker;
    std::exception_ptr side_error;
    if (take_spare()) {
      try {
        worker = std::thread([&] {
          try {
            side();
          } catch (...) {
            side_error = std::current_exception();
          }
          spare_.fetch_add(1);
        });
      } catch (...) {  // no thread to be had: the caller does both
        spare_.fetch_add(1);
      }
    }
    if (!worker.joinable()) {
      main();
      side();
      return;
    }
    std::exception_ptr main_error;
    try {
      main();
    } catch (...) {
      main_error = std::current_exception();
    }
    // While it waits this thread runs nothing: its slot is spare meanwhile
    // (the side's own splits may fork into it).
    spare_.fetch_add(1);
    worker.join();
    spare_.fetch_sub(1);
    if (main_error) std::rethrow_exception(main_error);
    if (side_error) std::rethrow_exception(side_error);
  }

  // fn(i) for every i in [0, count), in chunks of `grain` handed out in
  // turn to the caller and up to total() - 1 more threads. fn must only
  // write what belongs to its i.
  template <class Fn>
  void for_each(uint64_t count, uint64_t grain, Fn&& fn) {
    grain = std::max<uint64_t>(grain, 1);
    const uint64_t chunks = (count + grain - 1) / grain;
    const uint32_t helpers = uint32_t(std::min<uint64_t>(total_ - 1, chunks > 0 ? chunks - 1 : 0));
    std::atomic<uint64_t> next{0};
    std::exception_ptr error;
    std::mutex error_lock;
    auto run = [&] {
      try {
        for (uint64_t c; (c = next.fetch_add(1)) < chunks;)
          for (uint64_t i = c * grain, end = std::min(count, i + grain); i < end; ++i) fn(i);
      } catch (...) {
        next.store(chunks);  // the others stop at their next chunk
        std::lock_guard<std::mutex> hold(error_lock);
        if (!error) error = std::current_exception();
      }
    };
    std::vector<std::thread> workers;
    workers.reserve(helpers);
    try {
      for (uint32_t k = 0; k < helpers; ++k) workers.emplace_back(run);
    } catch (...) {  // fewer threads than asked: those started share the work
    }
    run();
    for (std::thread& w : workers) w.join();
    if (error) std::rethrow_exception(error);
  }

 private:
  bool take_spare() {
    int n = spare_.load();
    while (n > 0)
      if (spare_.compare_exchange_weak(n, n - 1)) return true;
    return false;
  }

  uint32_t total_;
  std::atomic<int> spare_;
};

// fn(i) for every i in [0, count): on `threads` (BuildThreads::for_each),
// or on the caller's thread alone when there are none.
template <class Fn>
void for_each_on(BuildThreads* threads, uint64_t count, uint64_t grain, Fn&& fn) {
  if (threads) threads->for_each(count, grain, fn);
  else
    for (uint64_t i = 0; i < count; ++i) fn(i);
}

}  // namespace meshcast
