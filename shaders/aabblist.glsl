// Method 2 of seed 000 §7, AABBList: what its passes share. Pass 1 appends
// a (ray, batch) pair for every batch box a ray enters; a one-thread pass
// turns the count into the indirect dispatch of pass 2, which tests the
// pairs' triangles (layout/formats.h: batch entries, then 128-lane records).
#ifndef MESHCAST_AABBLIST_GLSL
#define MESHCAST_AABBLIST_GLSL

#include "shaders/blob.glsl"

// Pairs the host sized for its chunk of rays, so the append never runs
// out; the bound check only guards against what cannot happen.
layout(std430, set = 0, binding = 4) buffer Pairs { uvec2 pairs[]; };

// counter: pass 1's appends; groups: pass 2's VkDispatchIndirectCommand
// (the host dispatches from byte 4); pair_count: what pass 2 consumes.
layout(std430, set = 0, binding = 5) buffer Control {
  uint counter;
  uint groups[3];
  uint pair_count;
} control;

// Workgroups of 128 lanes a batch needs (pass 2's y).
#define MC_LIST_GROUPS_Y ((MC_LIST_BATCH + 127u) / 128u)

uint list_entry(uint batch) { return header(MC_HDR_TREE_OFFSET) + batch * MC_LIST_ENTRY_BYTES; }
uint list_count(uint batch) { return blob_u32(list_entry(batch) + MC_LIST_COUNT_AT); }

#endif
