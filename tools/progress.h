// A line on stderr saying what long work is doing while it does it, for a
// person at a terminal: shown only when stderr is a terminal (never into a
// file or a pipe), never with --json, and cleared when the work ends.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace meshcast::tools {

class Progress {
 public:
  // `shown`: the caller's own condition (the work is long enough, no
  // --json); stderr must also be a terminal.
  Progress(std::string what, bool shown);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  // The share done, 0 to 1; before the first call only the time is shown.
  void set(double fraction) { fraction_.store(fraction, std::memory_order_relaxed); }

 private:
  void show();
  std::string what_;
  std::atomic<double> fraction_{-1};
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread ticker_;
};

// The sizes past which work shows its progress.
constexpr size_t kProgressTriangles = 1000000, kProgressRays = 1000000;

// A command whose output is --json shows none: called before its work.
void hide_progress();
// The line of a whole command (the benches): begun before its work, ended
// before anything else is said (main's error messages too).
void begin_command_progress(const std::string& what);
void end_command_progress();

}  // namespace meshcast::tools
