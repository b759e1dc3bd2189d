// The rays as the GPU reads them, one header for the host that writes them
// (gpu/batch.cpp, gpu/scene.cpp), the shaders that load them
// (shaders/ray.glsl, shaders/scene_octtree.comp) and the CPU walkers whose
// per-ray constants the shaders compute again (cpu/intersect.h's RayPre).
// Word offsets are plain #defines in the common subset of C++ and GLSL; the
// constants' arithmetic below is the CPU's, in correctly rounded float,
// which shaders/ray.glsl repeats with every division rounded once.
#ifndef MESHCAST_LAYOUT_RAY_RECORD_H
#define MESHCAST_LAYOUT_RAY_RECORD_H

// A float ray: meshcast::Ray as the caller writes it, 8 words (the
// shaders prepare its constants: no host pass over the rays).
#define MC_RAY_WORDS 8u
#define MC_RAY_ORG 0u   // x, y, z
#define MC_RAY_DIR 3u   // x, y, z as given (walked_direction applied on the device)
#define MC_RAY_TMAX 6u
#define MC_RAY_TMIN 7u

// A scene's double-precision ray (meshcast::RayD as the caller gives it): 12 words.
#define MC_RAYD_WORDS 12u
#define MC_RAYD_ORG 0u   // x, y, z as doubles, low word first
#define MC_RAYD_DIR 6u   // x, y, z as floats
#define MC_RAYD_TMAX 9u
#define MC_RAYD_TMIN 10u

#ifdef __cplusplus
#include <cmath>
#include <utility>

namespace meshcast::layout {

// The per-ray constants of the box and watertight triangle tests (Woop,
// Benthin, Wald 2013): the dominant axis kz, kx and ky the others (swapped
// for a negative dir[kz] to keep the winding), the shear sx, sy, sz, and
// the reciprocal direction. `dir` is already walked_direction's.
struct RayConstants {
  float inv[3];
  int axis[3];  // {kx, ky, kz}
  float sx, sy, sz;
};

// Always inlined: the walkers are compiled once an instruction set
// (cpu/isa.h), and an out-of-line copy shared between sets could carry
// one set's instructions into another's code.
[[gnu::always_inline]] inline RayConstants ray_constants(const float dir[3]) {
  RayConstants c;
  for (int a = 0; a < 3; ++a) c.inv[a] = 1.0f / dir[a];
  const float ax = std::fabs(dir[0]), ay = std::fabs(dir[1]), az = std::fabs(dir[2]);
  const int kz = (ax > ay) ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (dir[kz] < 0) std::swap(kx, ky);
  c.sx = dir[kx] / dir[kz];
  c.sy = dir[ky] / dir[kz];
  c.sz = 1.0f / dir[kz];
  c.axis[0] = kx, c.axis[1] = ky, c.axis[2] = kz;
  return c;
}

}  // namespace meshcast::layout
#endif

#endif
