// Rays and the hits they get: the records every walker, shader and file
// (RAYS, HITS) shares. A ray is o + t d for t in [0, tmax]; d need not be
// normalized and t is in units of d. Triangles are two-sided and the test is
// watertight: a ray through a shared edge or vertex hits one of its triangles.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "meshcast/mesh.h"

namespace meshcast {

struct Ray {
  float org[3];
  float dir[3];
  float tmax;
};
static_assert(sizeof(Ray) == 28, "Ray is the 7 floats of a rays-file record");

// A miss's triangle number.
constexpr uint32_t kNoHit = 0xFFFFFFFFu;

struct Hit {
  float t = INFINITY;        // INFINITY on a miss
  uint32_t triangle = kNoHit;  // the index in the caller's mesh (the input order)
  // Only when asked for (HitOutputs::Uv): barycentrics of corners 1 and 2
  // (strips: of a rotation of the triangle's corners, the winding kept).
  float u = 0, v = 0;
  float point[3] = {0, 0, 0};  // only when asked for (HitOutputs::Point): org + t * dir
};
static_assert(sizeof(Hit) == 28, "the Vulkan methods' hit record (shaders/hits.glsl) is the same 7 words");

// What a hit carries besides t and the triangle, computed only when asked
// for (on either backend): flags, combined with |.
enum class HitOutputs : uint32_t { None = 0, Uv = 1, Point = 2 };
constexpr HitOutputs operator|(HitOutputs a, HitOutputs b) { return HitOutputs(uint32_t(a) | uint32_t(b)); }
constexpr bool has(HitOutputs set, HitOutputs flag) { return (uint32_t(set) & uint32_t(flag)) != 0; }

// The question a trace answers: the closest hit along [0, tmax] (the
// default), or any hit there ("is anything in the way?": line of sight,
// shadow and audio probes), where the walk ends at the first triangle it
// takes and the hit names that triangle and its t, not the nearest.
enum class Query : uint32_t { Closest = 0, Any = 1 };

// The largest direction component a ray may have.
constexpr float kMaxDirection = 0x1p126f;

// A ray the walkers walk: an origin within +-2^100 (kMaxCoordinate, the
// range of meshes), direction components within +-2^126 (so every
// reciprocal the tests use is a normal float: a GPU may flush denormals to
// 0) and not all below FLT_MIN (such a direction counts as zero), tmax not
// NaN and not negative (infinity allowed). Any other ray is answered as a
// miss and counted.
bool ray_is_walkable(const Ray& r);  // defined once in the library (cpu/trace.cpp)

}  // namespace meshcast
