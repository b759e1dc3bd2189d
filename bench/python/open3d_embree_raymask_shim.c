/* Open3D 0.16.1 sets ray.mask = 0 on every ray it hands to Embree. Its bundled
 * Embree is built with EMBREE_RAY_MASK=OFF, which ignores the mask; Debian's
 * libembree3 (3.13.5) is built with EMBREE_RAY_MASK=ON, where a ray only meets
 * geometry with (ray.mask & geometry.mask) != 0, so every ray misses.
 * This shim interposes the two entry points Open3D calls with rays and sets
 * each ray's mask to all ones before handing on to the real Embree. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <embree3/rtcore.h>

typedef void (*fn1M)(RTCScene, struct RTCIntersectContext*, void*, unsigned int, size_t);

/* Look the real entry point up in libembree3 itself: Open3D's Python module loads
 * it with RTLD_LOCAL, where dlsym(RTLD_NEXT, ...) would not find it. */
static fn1M real_embree(const char* name) {
  void* lib = dlopen("libembree3.so.3", RTLD_NOW | RTLD_LOCAL);
  return lib ? (fn1M)dlsym(lib, name) : NULL;
}

static void open_masks(void* rays, unsigned int M, size_t stride) {
  char* p = (char*)rays;
  for (unsigned int i = 0; i < M; ++i) ((struct RTCRay*)(p + i * stride))->mask = 0xFFFFFFFFu;
}

void rtcIntersect1M(RTCScene scene, struct RTCIntersectContext* context, struct RTCRayHit* rayhit,
                    unsigned int M, size_t byteStride) {
  static fn1M real;
  if (!real) real = real_embree("rtcIntersect1M");
  open_masks(rayhit, M, byteStride);
  real(scene, context, rayhit, M, byteStride);
}

void rtcOccluded1M(RTCScene scene, struct RTCIntersectContext* context, struct RTCRay* ray,
                   unsigned int M, size_t byteStride) {
  static fn1M real;
  if (!real) real = real_embree("rtcOccluded1M");
  open_masks(ray, M, byteStride);
  real(scene, context, ray, M, byteStride);
}
