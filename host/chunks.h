// A batch of rays split over a job system's threads: chunks of consecutive
// rays, each walked whole by one thread, the caller waiting for the last.
// The Python package and `meshcast trace --threads` cut their batches so.
#pragma once
#include <cstddef>
#include <functional>

#include "meshcast/jobs.h"

namespace meshcast::host {

// How a batch of `count` rays is cut for `threads` threads: enough chunks
// that the threads finish together (rays differ in cost by tens of times:
// an open sky against a level's interior), at most `most` rays a chunk and
// never so few that the pool's lock shows.
struct Chunks {
  size_t count = 0, rays = 1, chunks = 0;
  size_t begin(size_t chunk) const { return chunk * rays; }
  size_t end(size_t chunk) const { return begin(chunk) + rays < count ? begin(chunk) + rays : count; }
};
Chunks plan_chunks(size_t count, uint32_t threads, size_t most = 1024);

// Calls chunk(index) for every chunk of the plan on the job system's
// threads (null, or a single chunk: on the calling thread) and returns
// when every call has returned; the first exception a chunk threw is
// rethrown then.
void for_each_chunk(const Chunks& plan, JobSystem* jobs, const std::function<void(size_t)>& chunk);

}  // namespace meshcast::host
