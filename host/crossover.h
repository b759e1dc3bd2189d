// The Automatic backend's crossover (Caster::crossover()): the batch size
// from which on the GPU answers first. Read from the caster's profile
// (CasterOptions::profile; the file's format is host/profile.h's) when it
// holds one for this device and blob, else measured on a thread of its own
// while the game's batches go to the CPU, then saved to the profile.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <thread>

#include "meshcast/blob.h"
#include "meshcast/caster.h"

namespace meshcast::host {

// What a saved profile is known by: the device, the layout, the mesh.
std::string profile_key(const std::string& device, const BlobView& view);

class Crossover {
 public:
  // What the measurement needs of its caster.
  struct Measurement {
    const BlobView* blob = nullptr;
    std::string device;   // the device's name, which the note and the profile's key carry
    std::string profile;  // CasterOptions::profile ("": none)
    // Runs a closest-hit batch of `rays` on `backend` on the measurement's
    // own slot, its hits into `hits`; returns its latency (ms).
    std::function<double(std::span<const Ray> rays, std::span<Hit> hits, Backend backend)> time_batch;
    std::function<bool()> gpu_available;
    std::function<uint32_t()> cpu_threads;
    std::function<void(const std::string& why)> gpu_failed;  // the device failed while measured
  };

  // The caster's lock and condition: the note is read and written under
  // `mutex`, and known() turns true under it with `changed` notified, so a
  // thread waiting on `changed` for it (Caster::wait_for_crossover) never
  // misses it.
  Crossover(std::mutex& mutex, std::condition_variable& changed) : mutex_(mutex), changed_(changed) {}
  ~Crossover() { stop(); }
  Crossover(const Crossover&) = delete;
  Crossover& operator=(const Crossover&) = delete;

  uint32_t rays() const { return rays_.load(); }  // ~0u: never, or not known yet
  bool known() const { return known_.load(); }
  std::string note() const;  // why() says it: where the crossover came from, or why there is none

  // None is wanted (a backend other than Automatic, no GPU): known at once.
  // Before any thread of the caster's reads it.
  void not_wanted() { known_ = true; }
  // From `path` when it holds the crossover for `key` (known then); false
  // when it holds none, keeping why for the notes.
  bool load(const std::string& path, const std::string& key);
  // Measures on a thread of its own (the caster's constructor never
  // waits for it), then publishes the crossover, its note and known()
  // together, after saving it to the profile.
  void measure_in_background(Measurement m);
  // The measurement stops after its current batch; its thread is joined.
  void stop();

 private:
  void measure(const Measurement& m);  // the background thread's work
  std::string unused_profile() const;  // " (the profile was not used: ...)" for the notes, or ""

  std::mutex& mutex_;
  std::condition_variable& changed_;
  std::atomic<uint32_t> rays_{~0u};
  std::atomic<bool> known_{false};
  std::string note_;  // under mutex_ once the measurement has started
  // Why the profile was not used (host/profile.h), and whether a measured
  // crossover may be written over it; set by load().
  std::string profile_unused_;
  bool profile_replaceable_ = true;
  std::thread measuring_;  // the background measurement
  std::atomic<bool> stop_measuring_{false};
};

}  // namespace meshcast::host
