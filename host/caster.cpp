#include "host/caster_impl.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <sstream>
#include <stdexcept>

#include "meshcast/errors.h"
#include "meshcast/mesh.h"
#include "gpu/method.h"
#if MESHCAST_VULKAN
#include "gpu/scene.h"
#include "gpu/vulkan.h"
#endif
#include "host/jobs.h"
#include "layout/blob_format.h"
#include "layout/queries.h"
#include "cpu/scene.h"

namespace meshcast::host {

namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

const char* backend_name(Backend b) {
  switch (b) {
    case Backend::Cpu: return "CPU";
    case Backend::Vulkan: return "Vulkan";
    case Backend::Automatic: return "automatic";
  }
  return "";
}

Caster::Impl::Impl(std::span<const uint8_t> blob, const std::string& name, CasterOptions options)
    : view_(std::in_place, blob, name), options_(std::move(options)) {
  setup(blob, name);
}

Caster::Impl::Impl(CasterOptions options) : options_(std::move(options)) {
  // Scene batches alone: the GPU only when asked for by name (the
  // Automatic backend's crossover is a blob's).
  if (options_.backend == Backend::Automatic) options_.backend = Backend::Cpu;
  setup({}, "");
}

const BlobView& Caster::Impl::blob(const char* who) const {
  if (!view_) throw UsageError(std::string(who) + ": this caster was made without a blob (scene batches alone)");
  return *view_;
}

namespace {

// CasterOptions' ranges (caster.h), checked before anything is made: a
// value out of range is the caller's mistake, said so, never bent into
// range (0 frames would hold no batch, 2^32 - 1 would wrap the slot count,
// hit_outputs' other bits would reach the GPU's query flags).
void check_options(const CasterOptions& o) {
  auto refuse = [](const std::string& what) { throw UsageError("CasterOptions::" + what); };
  if (o.backend != Backend::Cpu && o.backend != Backend::Vulkan && o.backend != Backend::Automatic)
    refuse("backend " + std::to_string(int(o.backend)) + " is not Backend::Cpu, Backend::Vulkan or Backend::Automatic");
  if (o.frames < 1 || o.frames > kMaxCasterFrames)
    refuse("frames " + std::to_string(o.frames) + " is not in 1.." + std::to_string(kMaxCasterFrames) +
           " (the batches in flight at most)");
  if (o.threads > kMaxCasterThreads)
    refuse("threads " + std::to_string(o.threads) + " is not in 0.." + std::to_string(kMaxCasterThreads) +
           " (0: every core)");
  const uint32_t outputs = uint32_t(HitOutputs::Uv | HitOutputs::Point);
  if (uint32_t(o.hit_outputs) & ~outputs)
    refuse("hit_outputs " + std::to_string(uint32_t(o.hit_outputs)) +
           " has bits other than HitOutputs::Uv (1) and HitOutputs::Point (2)");
  if (o.jobs && o.jobs->threads() == 0)
    refuse("jobs: its threads() is 0; a job system runs at least one job at a time");
  // The engine made its instance (its layers are the ones that validate)
  // and chose its device: asking meshcast for either is a contradiction,
  // which would otherwise pass unnoticed.
  if (o.engine_vulkan.device && o.validation)
    refuse("validation is set together with engine_vulkan: the engine's instance has the layers it was created with; "
           "enable VK_LAYER_KHRONOS_validation on it instead");
  if (o.engine_vulkan.device && !o.device.empty())
    refuse("device '" + o.device + "' is set together with engine_vulkan, whose device is the one used");
}

}  // namespace

void Caster::Impl::setup(std::span<const uint8_t> blob, const std::string& name) {
  check_options(options_);
  if (options_.jobs) {
    jobs_ = options_.jobs;
  } else {
    pool_ = std::make_unique<WorkerPool>(options_.threads);
    jobs_ = pool_.get();
  }
  // One slot more than the game's frames: the Automatic backend's
  // measurement runs on it beside the game's batches.
  game_slots_ = options_.frames;
  for (uint32_t i = 0; i < game_slots_ + 1; ++i) {
    auto s = std::make_unique<Slot>();
    s->index = i;
    Slot* sp = s.get();
    s->work = [this, sp](uint32_t job) {
      calls_in_work_.fetch_add(1, std::memory_order_acquire);
      const auto t0 = std::chrono::steady_clock::now();
      const uint32_t first = job * sp->chunk, count = std::min(sp->chunk, sp->n - first);
      const std::span<const Ray> rays = sp->scene ? std::span<const Ray>() : std::span<const Ray>(sp->rays).subspan(first, count);
      const BatchQuery& q = sp->query;
      // What a walk throws (std::bad_alloc growing the rows of every hit)
      // is the batch's answer, rethrown by wait(): leaving a worker it
      // would end the process, or leave jobs_left short and wait() hung.
      try {
        if (sp->scene) {  // scene hits carry u, v at most
          const SceneBatchQuery& sq = sp->scene_query;
          const HitOutputs outputs = HitOutputs(uint32_t(options_.hit_outputs) & uint32_t(HitOutputs::Uv));
          const std::span<const RayD> world = std::span<const RayD>(sp->world).subspan(first, count);
          if (sq.query == Query::All) {
            SceneHitLists& rows = sp->job_scene_rows[job];
            rows.max_hits = sq.max_hits;
            trace_all_hits_snapshot(*sp->scene, world, rows, outputs, sq.cull, sq.mask);
          } else {
            trace_snapshot(*sp->scene, world, std::span<SceneHit>(sp->scene_hits).subspan(first, count), outputs, sq.query,
                           sq.cull, sq.mask);
          }
        } else if (q.query == Query::All) {
          HitLists& rows = sp->job_rows[job];
          rows.max_hits = q.max_hits;
          view_->trace_all_hits(rays, rows, options_.hit_outputs, q.cull);
        } else {
          view_->trace(rays, std::span<Hit>(sp->hits).subspan(first, count), options_.hit_outputs, q.query, q.cull);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!sp->error) sp->error = std::current_exception();
      }
      sp->cpu_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
      if (sp->jobs_left.fetch_sub(1) == 1) complete(*sp, Backend::Cpu);
      calls_in_work_.fetch_sub(1, std::memory_order_release);  // the last touch of the caster
    };
    slots_.push_back(std::move(s));
  }

  if (options_.backend != Backend::Cpu) {
#if !MESHCAST_VULKAN
    (void)blob, (void)name;
    gpu_error_ = "meshcast was built without its Vulkan backend (MESHCAST_VULKAN=OFF): the CPU answers";
#else
    bool refused_at_the_door = false;
    try {
      const VulkanObjects& engine = options_.engine_vulkan;
      if (engine.device) {
        gpu::ExternalDevice external;
        external.instance = static_cast<VkInstance>(engine.instance);
        external.physical_device = static_cast<VkPhysicalDevice>(engine.physical_device);
        external.device = static_cast<VkDevice>(engine.device);
        external.queue = static_cast<VkQueue>(engine.queue);
        external.queue_family = engine.queue_family;
        external.get_instance_proc_addr = reinterpret_cast<PFN_vkGetInstanceProcAddr>(engine.get_instance_proc_addr);
        external.instance_api_version = engine.instance_api_version;
        external.enabled_features = static_cast<const VkPhysicalDeviceFeatures2*>(engine.enabled_features);
        try {
          gpu_ = std::make_shared<gpu::Context>(external);
        } catch (const UsageError&) {  // the engine's objects lack what meshcast needs
          refused_at_the_door = true;
          throw;
        }
      } else {
        // Automatic takes no software device by itself: it would measure
        // for a moment only to find the CPU faster at every size.
        gpu_ = std::make_shared<gpu::Context>(
            gpu::DeviceChoice{options_.device, options_.validation, options_.backend == Backend::Automatic});
      }
      // The method that reads the blob's layout, or the one asked for:
      // trying each method in turn would let one that needs a feature the
      // device lacks (64-bit atomics) refuse the device for a blob that
      // only another method reads.
      const std::string m = options_.gpu_method.empty() && view_ ? gpu::method_reading(blob) : options_.gpu_method;
      if (view_ && m.empty())
        throw GpuError("no GPU method reads " + std::string(layout::tree_format_name(layout::header_of(blob.data()).tree_format)) +
                            "/" + std::string(layout::triangle_format_name(layout::header_of(blob.data()).triangle_format)));
      if (view_) {  // scene batches alone: the context is all they need
        method_ = gpu::make_method(*gpu_, m, blob, name, uint32_t(slots_.size()), uint32_t(options_.hit_outputs));
        method_name_ = m;
      }
      completion_ = std::thread([this] { gpu_completions(); });
    } catch (const std::exception& e) {  // GpuError, or InputError for a method that does not read the layout
      method_.reset();
      gpu_.reset();
      if (refused_at_the_door) throw;  // nothing was started: the caster is not made
      gpu_error_ = e.what();
    }
#endif
  }
  find_crossover();
}

void Caster::Impl::find_crossover() {
  if (options_.backend != Backend::Automatic || !gpu_available()) {
    crossover_.not_wanted();
    return;
  }
  if (crossover_.load(options_.profile, profile_key(device_name(), *view_))) return;
  crossover_.measure_in_background({
      &*view_, device_name(), options_.profile,
      [this](std::span<const Ray> rays, std::span<Hit> hits, Backend b) { return time_measurement_batch(rays, hits, b); },
      [this] { return gpu_available(); }, [this] { return cpu_threads(); },
      [this](const std::string& why) { gpu_failed(why); }});
}

double Caster::Impl::time_measurement_batch(std::span<const Ray> rays, std::span<Hit> hits, Backend backend) {
  Slot& slot = *slots_[game_slots_];
  Ticket t;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    slot.state = Slot::Running;
    slot.id = next_id_++;
    slot.query = {};  // the crossover is the closest hit's
    t = {slot.id, slot.index};
  }
  start(slot, rays, backend);
  return collect(slot, t, hits, nullptr, false).latency_ms;
}

template <class Ready>
bool Caster::Impl::block(std::unique_lock<std::mutex>& lock, Ready ready) {
  ++blocked_;
  changed_.wait(lock, [&] { return closing_ || ready(); });
  --blocked_;
  if (closing_) changed_.notify_all();  // the destructor waits for blocked_ to be 0 (and for the lock)
  return ready();
}

void Caster::Impl::wait_for_crossover() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!block(lock, [this] { return crossover_.known(); }))
    throw UsageError("Caster::wait_for_crossover: the caster was destroyed while waiting");
}

Caster::Impl::~Impl() {
  // No batch starts from now on, and a thread blocked in wait() or
  // wait_for_crossover() throws UsageError: its caster is going.
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
    changed_.notify_all();
  }
  // The measurement stops after its current batch.
  crossover_.stop();
  // Let what is still running finish, so no job or fence outlives the
  // caster, and every thread that was blocked in a call, or is still
  // copying a batch's hits out, leave it.
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] {
      return blocked_ == 0 && std::none_of(slots_.begin(), slots_.end(), [](const auto& s) {
               return s->state == Slot::Running || s->state == Slot::Collecting;
             });
    });
  }
  {
    std::lock_guard<std::mutex> lock(pending_mutex_);
    stopping_ = true;
  }
  pending_changed_.notify_all();
  if (completion_.joinable()) completion_.join();
  // A job that completed its slot may still be returning from the slot's
  // work: the slots (and the work they own) go only once every call is out,
  // and our own pool's workers are joined before the slots they call into.
  while (calls_in_work_.load(std::memory_order_acquire) != 0) std::this_thread::yield();
  pool_.reset();
  jobs_ = nullptr;
  query_methods_.clear();  // before the context they were made on (the scene methods: the GPU thread's, gone with it)
  method_.reset();
  gpu_.reset();
}

#if MESHCAST_VULKAN
VulkanInstances vulkan_instances() {
  const gpu::InstanceCount n = gpu::instances_made();
  return {n.created, n.alive};
}
#else
VulkanInstances vulkan_instances() { return {}; }
#endif

#if MESHCAST_VULKAN
std::string Caster::Impl::device_name() const { return gpu_ ? gpu_->device_name() : "none"; }
uint32_t Caster::Impl::validation_messages() const { return gpu_ ? gpu_->validation_messages() : 0; }
#else
std::string Caster::Impl::device_name() const { return "none"; }
uint32_t Caster::Impl::validation_messages() const { return 0; }
#endif

Backend Caster::Impl::choose(uint32_t rays) const {
  if (!gpu_available() || options_.backend == Backend::Cpu) return Backend::Cpu;
  if (options_.backend == Backend::Vulkan) return Backend::Vulkan;
  return rays >= crossover_.rays() ? Backend::Vulkan : Backend::Cpu;
}

std::string Caster::Impl::why(uint32_t rays) const {
  const std::string n = std::to_string(rays) + " rays: ";
  if (options_.backend == Backend::Cpu) return n + "CPU, as the caster was made";
  if (!gpu_available()) return n + "CPU, the GPU is unavailable (" + gpu_error() + ")";
  if (options_.backend == Backend::Vulkan) return n + "Vulkan on " + device_name() + ", as the caster was made";
  const std::string note = crossover_.note();
  const uint32_t crossover = crossover_.rays();
  if (!crossover_.known()) return n + "CPU, while the crossover is " + note;
  if (crossover == ~0u) return n + "CPU, the GPU finished no batch size first (" + note + ")";
  return n + (rays >= crossover ? "Vulkan on " + device_name() + ", at or above" : "CPU, below") +
         " the crossover of " + std::to_string(crossover) + " rays (" + note + ")";
}

// A batch's query, culling and row length, or UsageError naming the one out of range.
static void check_query(Query query, Cull cull, uint32_t max_hits) {
  layout::check_query("Caster::submit", query, cull);
  if (query == Query::All && (max_hits < 1 || max_hits > kMaxHitsLimit))
    throw UsageError("Caster::submit: max_hits " + std::to_string(max_hits) + " is not in 1.." +
                     std::to_string(kMaxHitsLimit));
}

Ticket Caster::Impl::submit(std::span<const Ray> rays, BatchQuery query) {
  check_query(query.query, query.cull, query.max_hits);
  blob("Caster::submit");
  Slot& s = take_slot();
  s.query = query;
  start(s, rays, choose(uint32_t(rays.size())));
  return {s.id, s.index};
}

Caster::Impl::Slot& Caster::Impl::take_slot() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (closing_) throw UsageError("Caster::submit: the caster is being destroyed");
  for (uint32_t i = 0; i < game_slots_; ++i)
    if (slots_[i]->state == Slot::Free) {
      Slot& s = *slots_[i];
      s.state = Slot::Running;
      s.id = next_id_++;
      return s;
    }
  throw UsageError("all " + std::to_string(game_slots_) +
                   " frames hold batches not yet collected; wait() for one before submitting more");
}

void Caster::Impl::size_slot(Slot& s, size_t n, bool scene) {
  if (n > UINT32_MAX)
    throw UsageError("Caster::submit: " + std::to_string(n) + " rays, more than a batch holds (2^32 - 1)");
  s.submit_ms = now_ms();
  s.n = uint32_t(n);
  // Query::All's rows are the jobs' own (start_cpu) or the GPU method's.
  const size_t answers = s.query.query == Query::All ? 0 : s.n;
  if (scene) s.scene_hits.resize(answers);
  else s.hits.resize(answers);
}

void Caster::Impl::free_slot(Slot& s) {
  std::lock_guard<std::mutex> lock(mutex_);
  free_locked(s);
}

void Caster::Impl::free_locked(Slot& s) {
  s.scene.reset();  // a scene batch lets its frame go (its arrays may serve a later commit)
  s.error = nullptr;
  s.state = Slot::Free;
  changed_.notify_all();  // under the lock: the caster may be destroyed once it is released
}

Ticket Caster::Impl::submit(const Scene& scene, std::span<const RayD> rays, SceneBatchQuery query) {
  check_query(query.query, query.cull, query.max_hits);
  std::shared_ptr<const SceneSnapshot> frame = scene.snapshot();  // UsageError for a moved-from scene
  Slot& s = take_slot();
  try {
    s.scene = std::move(frame);
    s.scene_query = query;
    s.query = {query.query, query.cull, query.max_hits};
    size_slot(s, rays.size(), true);
    s.world.assign(rays.begin(), rays.end());  // keeps its capacity: no allocation once warm
    if (s.n > 0 && scene_on_gpu(query, *s.scene)) {
      s.ran_on = Backend::Vulkan;
      {
        std::lock_guard<std::mutex> lock(pending_mutex_);
        pending_.push_back(&s);  // begun by the GPU thread, after the batches before it
      }
      pending_changed_.notify_one();
    } else {
      start_cpu(s);
    }
  } catch (...) {
    free_slot(s);
    throw;
  }
  return {s.id, s.index};
}

void Caster::Impl::start(Slot& s, std::span<const Ray> rays, Backend backend) {
  try {
    size_slot(s, rays.size(), false);
    s.rays.assign(rays.begin(), rays.end());  // keeps its capacity: no allocation once warm
    const bool all = s.query.query == Query::All;
    // The GPU's rows of every hit carry no u, v (gpu::BatchMethod): such a batch is the CPU's.
    const bool gpu_answers = !(all && has(options_.hit_outputs, HitOutputs::Uv));
    if (backend == Backend::Vulkan && gpu_available() && s.n > 0 && gpu_answers) {
      try {
        start_gpu(s);
        return;
      } catch (const GpuError& e) {
        // A lost device is given up; any other refusal (a batch beyond a
        // buffer limit, memory) sends just this batch to the CPU.
        if (e.lost) gpu_failed(e.what());
      }
    }
    start_cpu(s);
  } catch (...) {
    free_slot(s);
    throw;
  }
}

void Caster::Impl::start_cpu(Slot& s) {
  s.ran_on = Backend::Cpu;
  s.cpu_ns = 0;
  // About four jobs a thread, so uneven rays even out; at least 64 rays a
  // job. In 64 bits: an engine's threads() may be anything (a count that
  // dropped to 0 since the constructor checked it sizes as 1).
  const uint64_t slices = 4ull * std::max(jobs_->threads(), 1u);
  const uint32_t per = uint32_t(std::max<uint64_t>(64, (s.n + slices - 1) / slices));
  const uint32_t jobs = (s.n + per - 1) / per;
  if (s.query.query == Query::All) {  // a job's rows each, in order (none for no rays)
    if (s.scene) s.job_scene_rows.resize(jobs);
    else s.job_rows.resize(jobs);
  }
  if (s.n == 0) return complete(s, Backend::Cpu);
  s.chunk = per;
  s.jobs_left = jobs;
  // The game's thread, the measurement and the GPU completions may all start
  // CPU batches; a JobSystem need not take two run() calls at once.
  std::lock_guard<std::mutex> lock(jobs_mutex_);
  jobs_->run(jobs, s.work);
}

void Caster::Impl::start_gpu(Slot& s) {
  const auto t0 = std::chrono::steady_clock::now();
  {
    std::lock_guard<std::mutex> lock(gpu_mutex_);
    if (options_.before_gpu_submit) options_.before_gpu_submit();
    s.method = method_for(s.query);
    s.method->begin(s.index, s.rays);
  }
  s.ran_on = Backend::Vulkan;
  s.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  {
    std::lock_guard<std::mutex> lock(pending_mutex_);
    pending_.push_back(&s);
  }
  pending_changed_.notify_one();
}

// The one thread that waits for GPU batches, in submission order, so each
// batch's ready time is taken when its fence signals, not when the game
// happens to ask. A failed wait (a lost device) moves the batch, and every
// later one, to the CPU.
void Caster::Impl::gpu_completions() {
  for (;;) {
    Slot* s = nullptr;
    {
      std::unique_lock<std::mutex> lock(pending_mutex_);
      pending_changed_.wait(lock, [this] { return stopping_ || !pending_.empty(); });
      if (pending_.empty()) {
        scene_methods_.clear();  // made and used by this thread alone: let go here too
        return;
      }
      s = pending_.front();
      pending_.pop_front();
    }
    try {
      if (gpu_failed_) throw GpuError(gpu_error());
      if (s->scene) run_scene_on_gpu(*s);
      else s->method->wait(s->index);
      complete(*s, Backend::Vulkan);
    } catch (const GpuError& e) {  // the device is lost, or (a scene batch, before it began) refused it
      if (e.lost || !s->scene) gpu_failed(e.what());
      cpu_instead(*s);
    } catch (...) {  // a scene the GPU method does not read (a layout, a limit), or the test hook's own: the CPU's
      cpu_instead(*s);
    }
  }
}

void Caster::Impl::cpu_instead(Slot& s) {
  try {
    start_cpu(s);
  } catch (...) {  // the job system's run() threw: the batch is answered with it, and this thread goes on
    s.error = std::current_exception();
    complete(s, Backend::Cpu);
  }
}

bool Caster::Impl::scene_on_gpu(const SceneBatchQuery& q, const SceneSnapshot& frame) const {
#if !MESHCAST_VULKAN
  (void)q, (void)frame;
  return false;
#else
  return options_.backend == Backend::Vulkan && gpu_available() && q.query != Query::All &&
         gpu::SceneMethod::refusal(frame).empty();  // a mesh it does not read: the CPU's at once, not after the queue
#endif
}

void Caster::Impl::run_scene_on_gpu(Slot& s) {
#if !MESHCAST_VULKAN
  (void)s;  // not reached: without the Vulkan backend there is no device
#else
  const SceneBatchQuery& q = s.scene_query;
  const uint32_t flags = (uint32_t(options_.hit_outputs) & MC_HIT_UV) | layout::query_bits(q.query, q.cull);
  gpu::SceneMethod* method = nullptr;
  {
    const auto t0 = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(gpu_mutex_);  // the queue and the command pool are shared
    if (options_.before_gpu_submit) options_.before_gpu_submit();
    std::shared_ptr<gpu::SceneMethod>& m = scene_methods_[flags];
    if (!m) m = std::make_shared<gpu::SceneMethod>(*gpu_, flags);
    method = m.get();
    method->begin(*s.scene, s.world, q.mask);
    s.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  try {
    method->finish(s.scene_hits);  // waits for the fence alone: blob batches may begin meanwhile
  } catch (const GpuError& e) {
    // A batch begun but not finished (its fence never signalled) leaves
    // the device unusable, whatever the error says: lost.
    throw GpuError(e.what(), true);
  }
#endif
}

void Caster::Impl::gpu_failed(const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!gpu_failed_.exchange(true)) gpu_error_ = why;
}

void Caster::Impl::complete(Slot& s, Backend ran_on) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s.ready_ms = now_ms();
    s.ran_on = ran_on;
    if (ran_on == Backend::Cpu) s.cpu_ms = double(s.cpu_ns.load()) * 1e-6;
    s.state = Slot::Ready;
    changed_.notify_all();  // under the lock: the waiter may destroy the caster once it is released
  }
}

Caster::Impl::Slot& Caster::Impl::slot_of(const Ticket& t) const {
  if (t.slot >= game_slots_)
    throw UsageError("ticket " + std::to_string(t.id) + " names frame slot " + std::to_string(t.slot) + " of " +
                     std::to_string(game_slots_) + ": not a ticket of this caster");
  return *slots_[t.slot];
}

bool Caster::Impl::poll(const Ticket& t) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Slot& s = slot_of(t);
  if (s.id != t.id || s.state == Slot::Free || s.state == Slot::Collecting)
    throw UsageError("ticket " + std::to_string(t.id) + " is unknown or already collected");
  return s.state == Slot::Ready;
}

gpu::Method* Caster::Impl::method_for(const BatchQuery& q) {
#if !MESHCAST_VULKAN
  (void)q;
  return method_.get();  // not reached: without the Vulkan backend no batch goes to a GPU
#else
  const uint32_t flags = uint32_t(options_.hit_outputs) | layout::query_bits(q.query, q.cull);
  if (flags == uint32_t(options_.hit_outputs)) return method_.get();
  const uint32_t max_hits = q.query == Query::All ? q.max_hits : 1;
  std::unique_ptr<gpu::Method>& m = query_methods_[{flags, max_hits}];
  if (!m) m = gpu::make_method(*gpu_, method_name_, view_->bytes(), "the caster's blob", uint32_t(slots_.size()), flags, max_hits);
  return m.get();
#endif
}

BatchRecord Caster::Impl::wait(const Ticket& t, std::span<Hit> hits) { return collect(slot_of(t), t, hits, nullptr, true); }

BatchRecord Caster::Impl::wait(const Ticket& t, HitLists& lists) { return collect(slot_of(t), t, {}, &lists, true); }

// What a ticket is collected into must be what its batch asked for.
static void check_collected(uint64_t id, bool scene_batch, bool scene_wait, bool all, bool lists, size_t room, size_t n) {
  if (scene_batch != scene_wait)
    throw UsageError("ticket " + std::to_string(id) + (scene_batch ? " is a scene batch: wait(ticket, SceneHit hits or SceneHitLists&) collects it"
                                                                   : " is a blob batch: wait(ticket, Hit hits or HitLists&) collects it"));
  if (all != lists)
    throw UsageError(all ? "ticket " + std::to_string(id) + " asked for every hit: wait(ticket, lists) collects it"
                         : "ticket " + std::to_string(id) + " asked for one hit a ray: wait(ticket, hits) collects it");
  if (!all && room < n) throw UsageError("wait() needs room for " + std::to_string(n) + " hits, got " + std::to_string(room));
}

BatchRecord Caster::Impl::claim(Slot& s, const Ticket& t, bool scene_wait, bool lists, size_t room) {
  std::unique_lock<std::mutex> lock(mutex_);
  auto gone = [&] { return s.id != t.id || s.state == Slot::Free || s.state == Slot::Collecting; };
  if (gone()) throw UsageError("ticket " + std::to_string(t.id) + " is unknown or already collected");
  check_collected(t.id, s.scene != nullptr, scene_wait, s.query.query == Query::All, lists, room, s.n);
  // Another thread may collect the same ticket first: then this one throws.
  // The measurement's own batches are waited for while the caster closes.
  auto ready = [&] { return gone() || s.state == Slot::Ready; };
  if (s.index >= game_slots_) changed_.wait(lock, ready);
  else if (!block(lock, ready))
    throw UsageError("ticket " + std::to_string(t.id) + " was not collected: the caster was destroyed while waiting");
  if (gone()) throw UsageError("ticket " + std::to_string(t.id) + " was collected by another thread");
  if (s.error) {  // the batch never ran: collected, and answered with why
    const std::exception_ptr error = s.error;
    free_locked(s);
    std::rethrow_exception(error);
  }
  s.state = Slot::Collecting;
  return {s.ran_on, s.n, s.ready_ms - s.submit_ms, 0, s.cpu_ms};
}

void Caster::Impl::release(Slot& s, const BatchRecord& r, bool record) {
  if (record) records_.add(r);
  free_slot(s);
}

BatchRecord Caster::Impl::wait(const Ticket& t, std::span<SceneHit> hits) {
  Slot& s = slot_of(t);
  const BatchRecord r = claim(s, t, true, false, hits.size());
  std::copy(s.scene_hits.begin(), s.scene_hits.begin() + s.n, hits.begin());
  release(s, r, true);
  return r;
}

// A CPU batch's rows: its jobs' rows one after the other, in ray order.
template <class Record>
static void concatenate(HitRows<Record>& lists, uint32_t max_hits, const std::vector<HitRows<Record>>& jobs) {
  lists.max_hits = max_hits;
  lists.clear();
  for (const HitRows<Record>& rows : jobs) lists.append(rows);
}

BatchRecord Caster::Impl::wait(const Ticket& t, SceneHitLists& lists) {
  Slot& s = slot_of(t);
  const BatchRecord r = claim(s, t, true, true, 0);
  try {
    concatenate(lists, s.scene_query.max_hits, s.job_scene_rows);
  } catch (...) {  // std::bad_alloc: the slot is let go, not left Collecting (the destructor waits on it)
    free_slot(s);
    throw;
  }
  release(s, r, true);
  return r;
}

BatchRecord Caster::Impl::collect(Slot& s, const Ticket& t, std::span<Hit> hits, HitLists* lists, bool record) {
  BatchRecord r = claim(s, t, false, lists != nullptr, hits.size());
  try {
    copy_out(s, r, hits, lists);
  } catch (...) {  // std::bad_alloc: the slot is let go, not left Collecting (the destructor waits on it)
    free_slot(s);
    throw;
  }
  release(s, r, record);
  return r;
}

void Caster::Impl::copy_out(Slot& s, BatchRecord& r, std::span<Hit> hits, HitLists* lists) {
  bool copied = false;
  if (r.ran_on == Backend::Vulkan) {
    try {
      std::lock_guard<std::mutex> lock(gpu_mutex_);
      gpu::GpuTiming timing;
      if (lists) s.method->finish_lists(s.index, *lists, &timing);
      else s.method->finish(s.index, hits.first(s.n), &timing);  // straight from the mapped buffer
      r.device_ms = timing.device_ms;
      copied = true;
    } catch (const GpuError& e) {  // the device went while reading back: the CPU answers
      gpu_failed(e.what());
      if (lists) {
        lists->max_hits = s.query.max_hits;  // the batch's rows, not what the caller's lists held
        trace_now(s.rays, *lists, s.query.cull);
      }
      else trace_now(s.rays, hits.first(s.n), s.query);
      r.ran_on = Backend::Cpu;
      copied = true;
    }
  }
  if (!copied && lists) {
    concatenate(*lists, s.query.max_hits, s.job_rows);
  } else if (!copied && s.n) {
    std::memcpy(hits.data(), s.hits.data(), s.n * sizeof(Hit));
  }
}

void Caster::Impl::trace_now(std::span<const Ray> rays, std::span<Hit> hits, BatchQuery query) const {
  blob("Caster::trace_now").trace(rays, hits, options_.hit_outputs, query.query, query.cull);
}

void Caster::Impl::trace_now(std::span<const Ray> rays, HitLists& lists, Cull cull) const {
  blob("Caster::trace_now").trace_all_hits(rays, lists, options_.hit_outputs, cull);
}

std::string Caster::Impl::gpu_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return gpu_error_;
}

// The public class: every call is the implementation's.
Caster::Caster(std::span<const uint8_t> blob, const std::string& name, CasterOptions options)
    : impl_(std::make_unique<Impl>(blob, name, std::move(options))) {}
Caster::Caster(CasterOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
Caster::~Caster() = default;  // ~Impl() stops the threads before any member goes

Ticket Caster::submit(std::span<const Ray> rays, BatchQuery query) { return impl_->submit(rays, query); }
Ticket Caster::submit(const Scene& scene, std::span<const RayD> rays, SceneBatchQuery query) {
  return impl_->submit(scene, rays, query);
}
BatchRecord Caster::wait(const Ticket& t, std::span<SceneHit> hits) { return impl_->wait(t, hits); }
BatchRecord Caster::wait(const Ticket& t, SceneHitLists& lists) { return impl_->wait(t, lists); }
bool Caster::poll(const Ticket& t) { return impl_->poll(t); }
BatchRecord Caster::wait(const Ticket& t, std::span<Hit> hits) { return impl_->wait(t, hits); }
BatchRecord Caster::wait(const Ticket& t, HitLists& lists) { return impl_->wait(t, lists); }
void Caster::trace_now(std::span<const Ray> rays, std::span<Hit> hits, BatchQuery query) const {
  impl_->trace_now(rays, hits, query);
}
void Caster::trace_now(std::span<const Ray> rays, HitLists& lists, Cull cull) const { impl_->trace_now(rays, lists, cull); }
Backend Caster::choose(uint32_t rays) const { return impl_->choose(rays); }
std::string Caster::why(uint32_t rays) const { return impl_->why(rays); }
uint32_t Caster::crossover() const { return impl_->crossover_.rays(); }
bool Caster::crossover_known() const { return impl_->crossover_.known(); }
void Caster::wait_for_crossover() { impl_->wait_for_crossover(); }
bool Caster::gpu_available() const { return impl_->gpu_available(); }
std::string Caster::gpu_error() const { return impl_->gpu_error(); }
std::string Caster::device_name() const { return impl_->device_name(); }
uint32_t Caster::validation_messages() const { return impl_->validation_messages(); }
uint32_t Caster::cpu_threads() const { return impl_->cpu_threads(); }
Percentiles Caster::percentiles(Backend b, uint32_t rays) const { return impl_->records_.percentiles(b, rays); }
std::vector<BatchRecord> Caster::records() const { return impl_->records_.all(); }
void Caster::clear_records() { impl_->records_.clear(); }

}  // namespace meshcast::host
