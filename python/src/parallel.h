// The threads a cast of the package uses: one worker pool for the process
// (host/jobs.h), as wide as the most threads a call has asked for, and its
// batches cut into chunks of rays as host/chunks.h cuts them.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>

#include "host/chunks.h"
#include "host/jobs.h"

namespace meshcast::python {

using host::Chunks;
using host::plan_chunks;

// The threads a call may use: `requested`, or every core for 0;
// std::invalid_argument (Python's ValueError) outside 0..1024.
uint32_t thread_count(long long requested, const char* what = "nthreads");

// The process's worker pool, at least `threads` wide (widened when a call
// asks for more: the narrower one lives on while someone holds it).
std::shared_ptr<host::WorkerPool> shared_pool(uint32_t threads);

// host::for_each_chunk on `threads` threads (1: the calling thread alone,
// no pool). Called without the GIL: chunk must not touch Python objects.
// meshcast::Error (RuntimeError) when the system refuses a thread.
void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk);

}  // namespace meshcast::python
