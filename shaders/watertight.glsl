// The watertight ray/triangle test of cpu/intersect.h (Woop, Benthin, Wald 2013),
// operation for operation: every product and difference is `precise`, so no
// compiler fuses them into an fma and both triangles of a shared edge get
// the same roundings; a lane float cannot settle (an edge function of 0, a
// det or T that overflowed or fell below kSettleTiny, a det of 2^126 or more,
// beyond the divisors Vulkan bounds a division's error for) is redone in double,
// as on the CPU. Two-sided unless the batch culls (kFlags' MC_CULL_*: det > 0
// is the front face, as cpu/intersect.h's cull_sign); accepts t in
// [r.tmin, closest], both ends included; a t past the largest float is no hit.
#ifndef MESHCAST_WATERTIGHT_GLSL
#define MESHCAST_WATERTIGHT_GLSL

#include "shaders/ray.glsl"

// Whether the batch's culling drops the face a determinant of this sign
// shows (positive: the front face, corners counter-clockwise seen from the
// origin).
#ifdef MC_SCENE
// The scene method walks a flip_facing instance with its faces turned: its
// front is the blob's back (cpu/scene_trace.cpp's turned()). A mirroring
// transform turns nothing: the walk is in the blob's frame.
bool instance_flip_facing = false;
bool culled(bool positive) { return (kFlags & (positive != instance_flip_facing ? MC_CULL_FRONT : MC_CULL_BACK)) != 0u; }
#else
bool culled(bool positive) { return (kFlags & (positive ? MC_CULL_FRONT : MC_CULL_BACK)) != 0u; }
#endif

#define kSettleTiny uintBitsToFloat(0x0D800000u)  // 2^-100, cpu/intersect.h kSettleTiny
#define kSettleHuge uintBitsToFloat(0x7E800000u)  // 2^126, cpu/intersect.h kSettleHuge

// Corners in ray space: sheared x, y, and z not yet scaled by sz.
bool watertight_double(float ax, float ay, float bx, float by, float cx, float cy, float az, float bz, float cz,
                       float sz, float tmin, float closest, out float t, out float u, out float v) {
  precise double U = double(cx) * double(by) - double(cy) * double(bx);
  precise double V = double(ax) * double(cy) - double(ay) * double(cx);
  precise double W = double(bx) * double(ay) - double(by) * double(ax);
  if ((U < 0.0lf || V < 0.0lf || W < 0.0lf) && (U > 0.0lf || V > 0.0lf || W > 0.0lf)) return false;
  precise double det = U + V + W;
  if (det == 0.0lf || culled(det > 0.0lf)) return false;
  precise double T = (U * double(az) + V * double(bz) + W * double(cz)) * double(sz);
  if (det < 0.0lf) T = -T, U = -U, V = -V, W = -W, det = -det;
  if (T < 0.0lf) return false;
  // The ends compared with the float t reported, as below and on the CPU.
  t = float(T / det);
  if (!(t >= tmin && t <= min(closest, kFloatMax))) return false;
  u = float(V / det), v = float(W / det);
  return true;
}

bool watertight(GpuRay r, vec3 a, vec3 b, vec3 c, float closest, out float t, out float u, out float v) {
  const float ox = r.org[r.kx], oy = r.org[r.ky], oz = r.org[r.kz];
  precise float ax = a[r.kx] - ox, ay = a[r.ky] - oy, az = a[r.kz] - oz;
  precise float bx = b[r.kx] - ox, by = b[r.ky] - oy, bz = b[r.kz] - oz;
  precise float cx = c[r.kx] - ox, cy = c[r.ky] - oy, cz = c[r.kz] - oz;
  ax = ax - r.sx * az, ay = ay - r.sy * az;
  bx = bx - r.sx * bz, by = by - r.sy * bz;
  cx = cx - r.sx * cz, cy = cy - r.sy * cz;
  precise float U = cx * by - cy * bx;
  precise float V = ax * cy - ay * cx;
  precise float W = bx * ay - by * ax;
  if (U == 0.0 || V == 0.0 || W == 0.0) return watertight_double(ax, ay, bx, by, cx, cy, az, bz, cz, r.sz, r.tmin, closest, t, u, v);
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  precise float det = U + V + W;
  precise float T = U * (r.sz * az) + V * (r.sz * bz) + W * (r.sz * cz);
  const float dets = abs(det), Tabs = abs(T);
  if (!(dets >= kSettleTiny && dets < kSettleHuge && Tabs >= kSettleTiny && Tabs < kInfinity))
    return watertight_double(ax, ay, bx, by, cx, cy, az, bz, cz, r.sz, r.tmin, closest, t, u, v);
  if (culled(det > 0.0)) return false;
  const float Ts = det < 0.0 ? -T : T;
  if (!(Ts >= 0.0)) return false;
  t = Ts / dets;
  if (!(t >= r.tmin && t <= min(closest, kFloatMax))) return false;
  u = V / det, v = W / det;
  return true;
}

#endif
