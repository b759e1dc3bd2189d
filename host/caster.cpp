#include "host/caster_impl.h"

#include <algorithm>
#include <atomic>
#include <thread>

#include "meshcast/errors.h"
#include "gpu/method.h"  // the methods the destructor lets go
#include "host/jobs.h"

namespace meshcast::host {

const char* backend_name(Backend b) {
  switch (b) {
    case Backend::Cpu: return "CPU";
    case Backend::Vulkan: return "Vulkan";
    case Backend::Automatic: return "automatic";
  }
  return "";
}

uint64_t Caster::Impl::new_identity() {
  // From 1: a default Ticket (caster 0) is nobody's. 2^64 casters never wrap.
  static std::atomic<uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
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
    s->work = [this, sp](uint32_t job) { walk_job(*sp, job); };
    slots_.push_back(std::move(s));
  }
  pending_.items.assign(slots_.size(), nullptr);

  if (options_.backend != Backend::Cpu) open_gpu(blob, name);
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
    t = {slot.id, slot.index, identity_};
  }
  start(slot, rays, backend);
  return collect(slot, t, hits, nullptr, false).latency_ms;
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

void Caster::Impl::trace_now(std::span<const Ray> rays, std::span<Hit> hits, BatchQuery query) const {
  blob("Caster::trace_now").trace(rays, hits, options_.hit_outputs, query.query, query.cull, query.packets);
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
OpenBatch Caster::open(uint32_t rays, BatchQuery query) { return impl_->open(rays, query); }
Ticket Caster::submit(const OpenBatch& batch) { return impl_->submit(batch); }
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
