// The threads a cast of the package uses: the library's worker pools
// (host/jobs.h), one for each thread count asked for, and its batches cut
// into chunks of rays as host/chunks.h cuts them.
#pragma once
#include <cstdint>
#include <functional>

#include "host/chunks.h"

namespace meshcast::python {

using host::Chunks;
using host::plan_chunks;

// The threads a call may use: `requested`, or every core for 0;
// std::invalid_argument (Python's ValueError) outside 0..1024.
uint32_t thread_count(long long requested, const char* what = "nthreads");

// host::for_each_chunk on `threads` threads (1: the calling thread alone,
// no pool). Called without the GIL: chunk must not touch Python objects.
void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk);

}  // namespace meshcast::python
