// A batch on the CPU: cut into jobs for the caster's job system (its own
// pool or the engine's), each walking its rays on a worker.
#include "host/caster_impl.h"

#include <algorithm>
#include <chrono>
#include <exception>

#include "scene/snapshot.h"

namespace meshcast::host {

// One job of a CPU batch: its chunk of the slot's rays walked, its time
// added, and the batch completed by the last job to finish.
void Caster::Impl::walk_job(Slot& s, uint32_t job) {
  calls_in_work_.fetch_add(1, std::memory_order_acquire);
  const auto t0 = std::chrono::steady_clock::now();
  const uint32_t first = job * s.chunk, count = std::min(s.chunk, s.n - first);
  const std::span<const Ray> rays = s.scene ? std::span<const Ray>() : std::span<const Ray>(s.rays).subspan(first, count);
  const BatchQuery& q = s.query;
  // What a walk throws (std::bad_alloc growing the rows of every hit)
  // is the batch's answer, rethrown by wait(): leaving a worker it
  // would end the process, or leave jobs_left short and wait() hung.
  try {
    if (s.scene) {  // scene hits carry u, v at most
      const SceneBatchQuery& sq = s.scene_query;
      const HitOutputs outputs = HitOutputs(uint32_t(options_.hit_outputs) & uint32_t(HitOutputs::Uv));
      const std::span<const RayD> world = std::span<const RayD>(s.world).subspan(first, count);
      if (sq.query == Query::All) {
        SceneHitLists& rows = s.job_scene_rows[job];
        rows.max_hits = sq.max_hits;
        trace_all_hits_snapshot(*s.scene, world, rows, outputs, sq.cull, sq.mask);
      } else {
        trace_snapshot(*s.scene, world, std::span<SceneHit>(s.scene_hits).subspan(first, count), outputs, sq.query,
                       sq.cull, sq.mask);
      }
    } else if (q.query == Query::All) {
      HitLists& rows = s.job_rows[job];
      rows.max_hits = q.max_hits;
      view_->trace_all_hits(rays, rows, options_.hit_outputs, q.cull);
    } else {
      view_->trace(rays, std::span<Hit>(s.hits).subspan(first, count), options_.hit_outputs, q.query, q.cull, q.packets);
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!s.error) s.error = std::current_exception();
  }
  s.cpu_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
  if (s.jobs_left.fetch_sub(1) == 1) complete(s, Backend::Cpu);
  calls_in_work_.fetch_sub(1, std::memory_order_release);  // the last touch of the caster
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

void Caster::Impl::cpu_instead(Slot& s) {
  try {
    if (!s.scene) s.rays_to_own_array();
    start_cpu(s);
  } catch (...) {  // the job system's run() threw: the batch is answered with it, and this thread goes on
    s.error = std::current_exception();
    complete(s, Backend::Cpu);
  }
}

}  // namespace meshcast::host
