// The caster's frame slots: a batch submitted into a free one, started on
// the CPU or the GPU, polled, collected into the caller's hits or rows,
// and the slot freed for the next frame's batch.
#include "host/caster_impl.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <exception>

#include <unistd.h>

#include "meshcast/errors.h"
#include "gpu/method.h"
#include "layout/queries.h"

namespace meshcast::host {

namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The machine's memory in bytes (0: not known).
uint64_t machine_memory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

}  // namespace

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
  return {s.id, s.index, identity_};
}

Ticket Caster::Impl::submit(const Scene& scene, std::span<const RayD> rays, SceneBatchQuery query) {
  check_query(query.query, query.cull, query.max_hits);
  std::shared_ptr<const SceneSnapshot> frame = scene.snapshot();  // UsageError for a moved-from scene
  Slot& s = take_slot();
  try {
    s.scene = std::move(frame);
    s.scene_query = query;
    s.query = {query.query, query.cull, query.max_hits};
    size_slot(s, rays.size(), true, "Caster::submit");
    // Keeps its capacity: no allocation once warm.
    allocating("Caster::submit", s.n, batch_bytes(s, true), [&] { s.world.assign(rays.begin(), rays.end()); });
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
  return {s.id, s.index, identity_};
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

// What a slot's arrays take for its batch: the rays' copy and a hit a ray
// (Query::All's rows are the jobs' own, start_cpu, or the GPU method's, and
// grow with the hits found).
static uint64_t batch_bytes(uint64_t n, bool scene, bool all) {
  const uint64_t answers = all ? 0 : n;
  return scene ? n * sizeof(RayD) + answers * sizeof(SceneHit) : n * sizeof(Ray) + answers * sizeof(Hit);
}

uint64_t Caster::Impl::batch_bytes(const Slot& s, bool scene) {
  return host::batch_bytes(s.n, scene, s.query.query == Query::All);
}

void Caster::Impl::size_slot(Slot& s, size_t n, bool scene, const char* who) {
  if (n > UINT32_MAX)
    throw UsageError(std::string(who) + ": " + std::to_string(n) + " rays, more than a batch holds (2^32 - 1)");
  // Refused in words before anything is allocated when the machine could
  // not hold it at all: an allocator may grant more than the memory and
  // fail only as the pages are written, and a sanitizer's ends the process
  // rather than throw. What is refused later still is allocating()'s.
  const uint64_t bytes = host::batch_bytes(n, scene, s.query.query == Query::All);
  static const uint64_t memory = machine_memory();
  if (memory != 0 && bytes > memory)
    throw UsageError(std::string(who) + ": a batch of " + std::to_string(n) + " rays needs " + std::to_string(bytes) +
                     " bytes for its rays and answers, more than this machine's memory (" + std::to_string(memory) +
                     " bytes); submit it in parts");
  s.submit_ms = now_ms();
  s.n = uint32_t(n);
  const size_t answers = s.query.query == Query::All ? 0 : s.n;
  allocating(who, n, bytes, [&] {
    if (scene) s.scene_hits.resize(answers);
    else s.hits.resize(answers);
  });
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

bool Caster::Impl::gpu_takes(const Slot& s, Backend backend) const {
  // The GPU's rows of every hit carry no u, v (gpu::BatchMethod): such a batch is the CPU's.
  const bool gpu_answers = !(s.query.query == Query::All && has(options_.hit_outputs, HitOutputs::Uv));
  return backend == Backend::Vulkan && gpu_available() && s.n > 0 && gpu_answers;
}

void Caster::Impl::start(Slot& s, std::span<const Ray> rays, Backend backend) {
  try {
    size_slot(s, rays.size(), false, "Caster::submit");
    if (gpu_takes(s, backend)) {
      try {
        place_on_gpu(s);  // the rays go straight into the device's mapped memory
        std::copy(rays.begin(), rays.end(), s.placed.begin());
        start_gpu(s);
        return;
      } catch (const GpuError& e) {
        // A lost device is given up; any other refusal (memory) sends just
        // this batch to the CPU.
        if (e.lost) gpu_failed(e.what());
      }
    }
    // Keeps its capacity: no allocation once warm.
    allocating("Caster::submit", s.n, batch_bytes(s, false), [&] { s.rays.assign(rays.begin(), rays.end()); });
    s.placed = s.rays;
    start_cpu(s);
  } catch (...) {
    free_slot(s);
    throw;
  }
}

OpenBatch Caster::Impl::open(uint32_t rays, BatchQuery query) {
  check_query(query.query, query.cull, query.max_hits);
  blob("Caster::open");
  Slot& s = take_slot();
  try {
    s.query = query;
    size_slot(s, rays, false, "Caster::open");
    bool on_gpu = false;
    if (gpu_takes(s, choose(rays))) {
      try {
        place_on_gpu(s);
        on_gpu = true;
      } catch (const GpuError& e) {
        if (e.lost) gpu_failed(e.what());
      }
    }
    if (!on_gpu) {
      // Keeps its capacity (no allocation once warm) and the rays it held.
      allocating("Caster::open", rays, batch_bytes(s, false), [&] { s.rays.resize(rays); });
      s.placed = s.rays;
    }
  } catch (...) {
    free_slot(s);
    throw;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s.state = Slot::Open;
  }
  return {{s.id, s.index, identity_}, s.placed};
}

Ticket Caster::Impl::submit(const OpenBatch& batch) {
  const Ticket& t = batch.ticket;
  Slot& s = slot_of(t);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (s.id != t.id || s.state != Slot::Open)
      throw UsageError("Caster::submit: ticket " + std::to_string(t.id) + " is not an open batch of this caster");
    if (closing_) throw UsageError("Caster::submit: the caster is being destroyed");
    // The rays are the span's: the room open() gave, or the first part of
    // it the caller narrowed the span to. Any other span would start rays
    // the caller never wrote here (the room holds an earlier batch's).
    if (batch.rays.data() != s.placed.data())
      throw UsageError("Caster::submit: the rays of open batch " + std::to_string(t.id) +
                       " do not start where open() put them; narrow the span with rays.first(k) to submit the first "
                       "k rays written");
    if (batch.rays.size() > s.n)
      throw UsageError("Caster::submit: the rays of open batch " + std::to_string(t.id) + " are " +
                       std::to_string(batch.rays.size()) + " rays, more than the " + std::to_string(s.n) + " opened");
    s.state = Slot::Running;
  }
  try {
    if (batch.rays.size() < s.n) {
      // Fewer rays written than opened: the batch, its hits and the
      // device's batch cut to them (smaller: nothing is allocated).
      s.n = uint32_t(batch.rays.size());
      if (s.query.query != Query::All) s.hits.resize(s.n);
      if (s.placed_on_gpu() && s.n > 0) {
        std::lock_guard<std::mutex> lock(gpu_mutex_);
        s.placed = s.method->rays(s.index, s.n);  // the same mapped memory, now s.n rays
      } else {
        s.rays.resize(s.placed_on_gpu() ? 0 : s.n);  // none written: the CPU answers the empty batch at once
        s.placed = s.rays;
      }
    }
    if (s.placed_on_gpu()) {
      try {
        start_gpu(s);
        return t;
      } catch (const GpuError& e) {
        gpu_refused(s, e);
        return t;
      }
    }
    start_cpu(s);
  } catch (...) {
    free_slot(s);
    throw;
  }
  return t;
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
  // Every caster numbers its batches from 1: a ticket's id and slot alone
  // would match another caster's batch.
  if (t.caster != identity_)
    throw UsageError("ticket " + std::to_string(t.id) +
                     (t.caster ? " was issued by another caster" : " was issued by no caster (made up, or default)") +
                     ": not a ticket of this caster");
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
  if (s.state == Slot::Open) throw UsageError("ticket " + std::to_string(t.id) + " is open: submit(batch) starts it");
  return s.state == Slot::Ready;
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
  if (s.state == Slot::Open) throw UsageError("ticket " + std::to_string(t.id) + " is open: submit(batch) starts it");
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
        trace_now(s.placed, *lists, s.query.cull);
      }
      else trace_now(s.placed, hits.first(s.n), s.query);
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

}  // namespace meshcast::host
