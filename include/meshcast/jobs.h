// Where the CPU backend's work runs. An engine with its own job system
// implements JobSystem and hands it to the Caster (CasterOptions::jobs);
// without one, the caster makes a pool of workers over the machine's cores.
#pragma once
#include <cstdint>
#include <functional>

namespace meshcast::host {

// run(count, work) arranges for work(i) to be called once for every i in
// [0, count), on any threads, and may return before they run. `work` stays
// alive until every call has returned (the caster keeps it per frame slot).
// The caster never calls run() from two threads at once (it serializes its
// own calls), so an implementation need not be thread-safe against itself;
// it is called from the game's thread and from the caster's own threads.
//
// run() may throw (an engine's queue that is full or shutting down): it
// must then have queued none of the calls. The caster passes the exception
// on as it was thrown: submit() throws it, wait() rethrows it for a batch
// the caster's GPU thread moved to the CPU, and the Automatic backend's
// measurement stops (why() says so). run() must call every work(i) it
// accepted: the caster waits for them all (wait(), its destructor).
// threads() must be at least 1 (the caster refuses 0).
class JobSystem {
 public:
  virtual ~JobSystem() = default;
  virtual void run(uint32_t count, const std::function<void(uint32_t)>& work) = 0;
  virtual uint32_t threads() const = 0;  // how many run at once (for sizing the jobs)
};

}  // namespace meshcast::host
