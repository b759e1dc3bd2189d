#include "tools/progress.h"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace meshcast::tools {

namespace {
// Often enough to look alive, rarely enough to cost nothing.
constexpr auto kTick = std::chrono::milliseconds(250);
std::atomic<bool> g_hidden{false};
std::unique_ptr<Progress> g_command;
}  // namespace

void hide_progress() { g_hidden = true; }
void begin_command_progress(const std::string& what) { g_command = std::make_unique<Progress>(what, true); }
void end_command_progress() { g_command.reset(); }

Progress::Progress(std::string what, bool shown) : what_(std::move(what)) {
  if (!shown || g_hidden || !isatty(STDERR_FILENO)) return;
  ticker_ = std::thread([this] {
    std::unique_lock<std::mutex> lock(mutex_);
    // Said at once, then every tick: work that asked for a line gets one
    // however fast the machine.
    do show();
    while (!wake_.wait_for(lock, kTick, [this] { return done_; }));
  });
}

Progress::~Progress() {
  if (!ticker_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  wake_.notify_one();
  ticker_.join();
  std::fputs("\r\033[K", stderr);  // the line cleared: what follows starts clean
}

void Progress::show() {
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double fraction = fraction_.load(std::memory_order_relaxed);
  // Carriage return first and last: output of the work's own that comes
  // meanwhile starts at the line's beginning, over this one.
  if (fraction >= 0)
    std::fprintf(stderr, "\r\033[K%s: %.0f%% (%.1f s)\r", what_.c_str(), 100 * fraction, seconds);
  else
    std::fprintf(stderr, "\r\033[K%s (%.1f s)\r", what_.c_str(), seconds);
  std::fflush(stderr);
}

}  // namespace meshcast::tools
