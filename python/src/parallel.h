// The threads a cast of the package uses: the process's one worker pool
// (host/shared_pool.h), its batches cut into chunks of rays as
// host/chunks.h cuts them.
#pragma once
#include <cstdint>

#include "host/chunks.h"
#include "host/shared_pool.h"

namespace meshcast::python {

using host::Chunks;
using host::for_each_chunk;
using host::plan_chunks;
using host::shared_pool;

// The threads a call may use: `requested`, or every core for 0;
// std::invalid_argument (Python's ValueError) outside 0..1024.
uint32_t thread_count(long long requested, const char* what = "nthreads");

}  // namespace meshcast::python
