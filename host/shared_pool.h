// One worker pool for the process, for the calls that cut a batch into
// chunks on the caller's behalf (the Python package, the C API): as wide
// as the most threads a call has asked for, its batches cut as
// host/chunks.h cuts them.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>

#include "host/chunks.h"
#include "host/jobs.h"

namespace meshcast::host {

// Every core this process may run on (a container's or taskset's share),
// not every core the machine has.
uint32_t every_core();

// The process's worker pool, at least `threads` wide (widened when a call
// asks for more: the narrower one lives on while someone holds it).
std::shared_ptr<WorkerPool> shared_pool(uint32_t threads);

// for_each_chunk on `threads` threads of the shared pool (1: the calling
// thread alone, no pool). meshcast::Error when the system refuses a thread.
void for_each_chunk(const Chunks& plan, uint32_t threads, const std::function<void(size_t)>& chunk);

}  // namespace meshcast::host
