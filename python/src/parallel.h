// A batch of rays split over the library's worker threads (host/jobs.h),
// as the Caster's CPU backend splits one: chunks of consecutive rays, each
// walked whole by one thread, while the calling thread waits for the last.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>

namespace meshcast::python {

// The threads a call may use: `requested`, or every core for 0;
// std::invalid_argument (Python's ValueError) outside 0..1024.
uint32_t thread_count(long long requested, const char* what = "nthreads");

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

// Calls chunk(index) for every chunk of the plan on `threads` threads (1:
// the calling thread alone, no pool) and returns when every call has
// returned; the first exception a chunk threw is rethrown then. Called
// without the GIL: chunk must not touch Python objects.
void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk);

}  // namespace meshcast::python
