// What a Caster is made of (meshcast/caster.h): its frame slots, the CPU
// jobs that fill them, the GPU's methods and the thread that waits for
// their fences, the Automatic backend's crossover and the latency records.
// The public class forwards every call here.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/caster.h"
#include "meshcast/errors.h"
#include "host/crossover.h"
#include "host/latency.h"

namespace meshcast::gpu {
class Context;
class Method;
class SceneMethod;
}

namespace meshcast::host {

class WorkerPool;

struct Caster::Impl {
  Impl(std::span<const uint8_t> blob, const std::string& name, CasterOptions options);
  explicit Impl(CasterOptions options);
  // Caster::~Caster(): no thread outlives the members it uses.
  ~Impl();

  // One batch in flight: the game's (a ticket names it) or the crossover
  // measurement's. Its buffers are kept from batch to batch.
  struct Slot {
    enum State { Free, Open, Running, Ready, Collecting };  // Open: open() gave its room, not submitted
    uint32_t index = 0;
    State state = Free;
    uint64_t id = 0;
    uint32_t n = 0;
    std::vector<Ray> rays;  // a CPU batch's (the GPU's are in its method's mapped memory)
    // Where the batch's rays are: `rays`, or the GPU method's slot (a
    // batch begun there, or open() in place).
    std::span<Ray> placed;
    bool placed_on_gpu() const { return placed.data() != rays.data(); }
    // A batch the CPU takes over from the GPU: its rays into `rays`.
    void rays_to_own_array() {
      if (!placed_on_gpu()) return;
      rays.assign(placed.begin(), placed.end());
      placed = rays;
    }
    BatchQuery query;
    std::vector<Hit> hits;  // a hit a ray (closest or any)
    // Query::All on the CPU: each job's compact rows, which wait()
    // concatenates (kept from batch to batch, so they stop allocating once
    // warm; the GPU's rows are compacted when read back).
    std::vector<HitLists> job_rows;
    gpu::Method* method = nullptr;  // the GPU batch's
    // A scene batch: the snapshot it walks (held until collected), its world
    // rays, its hits or each job's rows.
    std::shared_ptr<const SceneSnapshot> scene;
    std::vector<RayD> world;
    std::vector<SceneHit> scene_hits;
    std::vector<SceneHitLists> job_scene_rows;
    SceneBatchQuery scene_query;
    Backend ran_on = Backend::Cpu;
    double submit_ms = 0, ready_ms = 0, cpu_ms = 0;
    // What the job system threw when the GPU thread moved the batch to the
    // CPU (no caller to throw it to then): wait() rethrows it.
    std::exception_ptr error;
    // CPU batches: jobs of `chunk` rays; the last to finish completes.
    uint32_t chunk = 0;
    std::atomic<uint32_t> jobs_left{0};
    std::atomic<int64_t> cpu_ns{0};
    std::function<void(uint32_t)> work;  // made once, handed to the job system every batch
  };

  // The public calls (meshcast/caster.h says what each does), each defined
  // in the file of its job.
  Ticket submit(std::span<const Ray> rays, BatchQuery query);
  OpenBatch open(uint32_t rays, BatchQuery query);
  Ticket submit(const OpenBatch& batch);
  Ticket submit(const Scene& scene, std::span<const RayD> rays, SceneBatchQuery query);
  bool poll(const Ticket& t);
  BatchRecord wait(const Ticket& t, std::span<Hit> hits);
  BatchRecord wait(const Ticket& t, HitLists& lists);
  BatchRecord wait(const Ticket& t, std::span<SceneHit> hits);
  BatchRecord wait(const Ticket& t, SceneHitLists& lists);
  void trace_now(std::span<const Ray> rays, std::span<Hit> hits, BatchQuery query) const;
  void trace_now(std::span<const Ray> rays, HitLists& lists, Cull cull) const;
  Backend choose(uint32_t rays) const;
  std::string why(uint32_t rays) const;
  void wait_for_crossover();
  bool gpu_available() const { return gpu_ != nullptr && !gpu_failed_.load(); }
  std::string gpu_error() const;
  std::string device_name() const;
  uint32_t validation_messages() const;
  uint32_t cpu_threads() const { return jobs_->threads(); }

  // host/caster.cpp: made, and destroyed.
  void setup(std::span<const uint8_t> blob, const std::string& name);  // both constructors' rest
  // The caller's blob, which must outlive the caster (none for a caster of
  // scene batches alone); blob() throws UsageError naming `who` then.
  std::optional<BlobView> view_;
  const BlobView& blob(const char* who) const;
  // The crossover's: loaded from options.profile, else measured.
  void find_crossover();
  // One batch of the crossover's measurement on the slot after the game's
  // (its batches are not the game's records): its latency.
  double time_measurement_batch(std::span<const Ray> rays, std::span<Hit> hits, Backend backend);

  // host/frame_slots.cpp: a batch from its slot taken to its slot freed.
  Slot& slot_of(const Ticket& t) const;  // UsageError for a slot out of range
  Slot& take_slot();  // a free game slot, Running; UsageError when none, or while the caster closes
  // A taken slot's batch of n rays under s.query: the clock started, room
  // for its answers (scene hits or hits); UsageError naming `who` beyond
  // 2^32 - 1 rays, or when the machine's memory cannot hold the batch's
  // rays and answers (allocating() below).
  void size_slot(Slot& s, size_t n, bool scene, const char* who);
  static uint64_t batch_bytes(const Slot& s, bool scene);  // the slot's rays and answers (size_slot's count)
  // Runs `allocate`, which grows a slot's arrays for a batch of n rays
  // (`bytes` in all), turning std::bad_alloc into UsageError naming `who`,
  // the rays and the bytes: everything the caster throws is a
  // meshcast::Error, and a bad_alloc says nothing of which call or size.
  template <class Allocate>
  static void allocating(const char* who, size_t n, uint64_t bytes, Allocate allocate);
  // Fills the slot with the rays and starts the batch on `backend` (the
  // CPU too when the GPU refuses it); collect() waits for it, copies its
  // hits and frees the slot, keeping its record if `record`.
  void start(Slot& s, std::span<const Ray> rays, Backend backend);
  // Whether a blob batch of the slot's query and size may go to the GPU.
  bool gpu_takes(const Slot& s, Backend backend) const;
  void complete(Slot& s, Backend ran_on);  // Ready, its time taken; waiters woken
  // Waits on changed_ under `lock` (mutex_) until ready() or the caster
  // closes; counted in blocked_, which the destructor waits to be 0.
  // Returns ready(): false when the caster closed first.
  template <class Ready>
  bool block(std::unique_lock<std::mutex>& lock, Ready ready);
  // The first half of collecting: checks that the caller collects the
  // batch into what it asked for (scene hits or not, rows or not, `room`
  // hits), waits for it and marks it Collecting; release() frees the slot.
  BatchRecord claim(Slot& s, const Ticket& t, bool scene_wait, bool lists, size_t room);
  // `lists`: where a Query::All batch's rows go (null for the others).
  BatchRecord collect(Slot& s, const Ticket& t, std::span<Hit> hits, HitLists* lists, bool record);
  // collect()'s copy of a claimed batch's answers into the caller's
  // (the GPU's read back, or the CPU's rows or hits).
  void copy_out(Slot& s, BatchRecord& r, std::span<Hit> hits, HitLists* lists);
  void release(Slot& s, const BatchRecord& r, bool record);
  void free_slot(Slot& s);  // what started the batch threw: nothing runs
  void free_locked(Slot& s);  // free_slot() under mutex_

  // host/cpu_batches.cpp: a batch cut into jobs on the job system.
  void start_cpu(Slot& s);
  void walk_job(Slot& s, uint32_t job);  // the slot's work: one job's rays
  // start_cpu() for a batch the GPU thread moves to the CPU: what the job
  // system throws is kept in the slot for wait(), as no caller is there.
  void cpu_instead(Slot& s);

  // host/gpu_batches.cpp: the device, its methods and its thread.
  void open_gpu(std::span<const uint8_t> blob, const std::string& name);
  // The GPU method for a batch's query, made on first use (under gpu_mutex_).
  gpu::Method* method_for(const BatchQuery& q);
  // The slot's GPU method, and room for its rays there (s.placed); GpuError
  // when the device refuses the batch.
  void place_on_gpu(Slot& s);
  // Submits the slot's placed rays; the GPU thread waits for them.
  void start_gpu(Slot& s);
  // A batch the GPU refused at submission: its rays into the slot's own
  // array, then the CPU's jobs.
  void gpu_refused(Slot& s, const GpuError& e);
  void gpu_completions();  // the GPU thread
  // Whether a scene batch of this query on this frame goes to the GPU
  // (Backend::Vulkan, a device that has not failed, one hit a ray, every
  // mesh in the layout the GPU scene method reads).
  bool scene_on_gpu(const SceneBatchQuery& q, const SceneSnapshot& frame) const;
  // A scene batch on the GPU thread: begun, waited for, its answers in the
  // slot (GpuError, `lost` once the batch was begun; InputError or
  // UsageError for a batch the GPU scene method refuses).
  void run_scene_on_gpu(Slot& s);
  void gpu_failed(const std::string& why);  // every batch the CPU's from now on; gpu_error_ says why

  CasterOptions options_;
  std::unique_ptr<WorkerPool> pool_;
  JobSystem* jobs_ = nullptr;
  std::shared_ptr<gpu::Context> gpu_;  // shared_ptr: deleted where Vulkan is known (none without it)
  std::unique_ptr<gpu::Method> method_;  // the closest hit's, two-sided (and the crossover's)
  std::string method_name_;
  std::map<std::pair<uint32_t, uint32_t>, std::unique_ptr<gpu::Method>> query_methods_;  // (flags, max_hits)
  // By flags; the GPU thread's alone. shared_ptr: its deleter is made where
  // the method is (a build without Vulkan makes none and needs none).
  std::map<uint32_t, std::shared_ptr<gpu::SceneMethod>> scene_methods_;
  std::string gpu_error_;
  std::atomic<bool> gpu_failed_{false};

  mutable std::mutex mutex_;            // slots and the crossover's note
  std::mutex gpu_mutex_;                // the GPU method's begin and finish
  std::mutex jobs_mutex_;               // one JobSystem::run at a time (game thread, measurement, completions)
  std::atomic<uint32_t> calls_in_work_{0};  // jobs still inside a slot's work, even after it completed
  std::condition_variable changed_;     // a slot became ready or free, the crossover known, the caster closing
  bool closing_ = false;                // under mutex_: the destructor has begun
  uint32_t blocked_ = 0;                // under mutex_: threads in block()
  std::vector<std::unique_ptr<Slot>> slots_;  // options.frames for the game, then the measurement's
  uint32_t game_slots_ = 0;
  uint64_t next_id_ = 1;
  // This caster's number, which its tickets carry (Ticket::caster): one a
  // caster, never given twice in the process, so a ticket of a caster
  // destroyed and another made in its memory is still refused.
  static uint64_t new_identity();  // host/caster.cpp
  const uint64_t identity_ = new_identity();
  // Under mutex_, changed_ notified when it is known; its measurement's
  // thread is stopped first thing in the destructor.
  Crossover crossover_{mutex_, changed_};
  LatencyRecords records_;

  std::mutex pending_mutex_;            // GPU batches waiting for their fence (scene batches: to begin), in order
  std::condition_variable pending_changed_;
  // A ring of one entry a slot (a slot is pending at most once), so
  // queueing a batch allocates nothing: a std::deque allocated a block
  // every 64 batches.
  struct PendingRing {
    std::vector<Slot*> items;
    size_t head = 0, count = 0;
    bool empty() const { return count == 0; }
    void push_back(Slot* s) {
      if (count == items.size()) throw std::logic_error("more GPU batches pending than the caster has slots");
      items[(head + count++) % items.size()] = s;
    }
    Slot* front() const { return items[head]; }
    void pop_front() { head = (head + 1) % items.size(), --count; }
  };
  PendingRing pending_;
  bool stopping_ = false;
  std::thread completion_;
};

template <class Allocate>
void Caster::Impl::allocating(const char* who, size_t n, uint64_t bytes, Allocate allocate) {
  try {
    allocate();
  } catch (const std::bad_alloc&) {
    throw UsageError(std::string(who) + ": a batch of " + std::to_string(n) + " rays needs " + std::to_string(bytes) +
                     " bytes for its rays and answers, which could not be allocated; submit it in parts");
  }
}

template <class Ready>
bool Caster::Impl::block(std::unique_lock<std::mutex>& lock, Ready ready) {
  ++blocked_;
  changed_.wait(lock, [&] { return closing_ || ready(); });
  --blocked_;
  if (closing_) changed_.notify_all();  // the destructor waits for blocked_ to be 0 (and for the lock)
  return ready();
}

}  // namespace meshcast::host
