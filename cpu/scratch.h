// A thread's scratch rows for Query::All: the walkers write a ray's row of
// max_hits records there, and the trace copies the kept hits out into the
// caller's compact rows (meshcast/ray.h HitRows). Made once a thread and
// grown to the largest asked for, so a caster's workers stop allocating
// once warm. Included by the baseline code alone (cpu/blob_view.cpp,
// cpu/scene_trace.cpp), never by a walker's instruction-set file: an
// instantiation there could carry that set's instructions to every caller.
#pragma once
#include <cstddef>
#include <span>
#include <vector>

namespace meshcast {

// `records` of a thread's scratch of Record, valid until the thread's next
// call for the same Record (callers do not nest).
template <class Record>
std::span<Record> thread_scratch(size_t records) {
  thread_local std::vector<Record> scratch;
  if (scratch.size() < records) scratch.resize(records);
  return std::span<Record>(scratch).first(records);
}

}  // namespace meshcast
