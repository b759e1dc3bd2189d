// The batch's counters (binding 5; gpu/batch.cpp zeroes them on the device
// before the first dispatch and reads them after the fence): the rays
// answered as misses because the CPU would not walk them either (the
// count begin() once returned from a host pass over the rays).
#ifndef MESHCAST_BATCH_COUNTERS_GLSL
#define MESHCAST_BATCH_COUNTERS_GLSL

layout(std430, set = 0, binding = 5) buffer BatchCounters {
  uint unwalkable_rays;
};

// Called once a ray, by the pass that answers it.
void count_unwalkable(bool walkable) {
  if (!walkable) atomicAdd(unwalkable_rays, 1u);
}

#endif
