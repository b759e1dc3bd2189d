// The resident memory a piece of work adds at its peak: what a build needs
// besides the mesh it reads (its structure, kept, and whatever it frees
// before returning), measured by the kernel rather than counted by hand.
#pragma once
#include <functional>

namespace meshcast::bench {

// Bytes of resident memory `work` added at its peak: the process's
// high-water mark (VmHWM), reset just before (/proc/self/clear_refs, Linux
// 4.0 or later), less its resident size then, glibc's free heap pages
// handed back first (malloc_trim). Memory another allocator keeps pooled
// (Embree's, TBB's) and reuses is not counted again, so on a mesh of a few
// megabytes the figure may read low; 0 where the mark cannot be reset or
// read (no /proc).
double peak_added_bytes(const std::function<void()>& work);

}  // namespace meshcast::bench
