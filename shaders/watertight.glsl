// The watertight ray/triangle test of cpu/intersect.h (Woop, Benthin, Wald 2013),
// operation for operation: every product and difference is `precise`, so no
// compiler fuses them into an fma and both triangles of a shared edge get
// the same roundings; a lane float cannot settle (an edge function of 0, a
// det or T that overflowed or fell below kSettleTiny, a det of 2^126 or more,
// beyond the divisors Vulkan bounds a division's error for) is redone in double,
// as on the CPU, and every hit's t, u and v are worked out in double from
// the stored corners, as on the CPU. Two-sided unless the batch culls
// (kFlags' MC_CULL_*: det > 0 is the front face, as cpu/intersect.h's
// cull_sign); accepts t in [r.tmin, closest], both ends included, on the
// float t reported; a t past the largest float is no hit.
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

// cpu/watertight_double.cpp's watertight_inside_double: whether a triangle
// float could not settle lies inside, on a face the batch keeps. Corners in
// ray space (sheared x, y): each product of two floats is exact in double.
bool watertight_inside_double(float ax, float ay, float bx, float by, float cx, float cy) {
  precise double U = double(cx) * double(by) - double(cy) * double(bx);
  precise double V = double(ax) * double(cy) - double(ay) * double(cx);
  precise double W = double(bx) * double(ay) - double(by) * double(ax);
  if ((U < 0.0lf || V < 0.0lf || W < 0.0lf) && (U > 0.0lf || V > 0.0lf || W > 0.0lf)) return false;
  precise double det = U + V + W;
  return det != 0.0lf && !culled(det > 0.0lf);
}

// cpu/watertight_double.cpp's hit_in_double, operation for operation and in
// the ray's axis order: t, u and v in double from the stored corners, the
// float t reported compared with [r.tmin, limit].
bool hit_in_double(GpuRay r, vec3 a, vec3 b, vec3 c, float limit, out float t, out float u, out float v) {
  const uint k[3] = uint[3](r.kx, r.ky, r.kz);
  precise double e1[3], e2[3], s[3];
  double d[3];
  for (int j = 0; j < 3; ++j) {
    e1[j] = double(b[k[j]]) - double(a[k[j]]);
    e2[j] = double(c[k[j]]) - double(a[k[j]]);
    s[j] = double(a[k[j]]) - double(r.org[k[j]]);
    d[j] = double(r.dir[k[j]]);
  }
  precise double n[3] = double[3](e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]);
  precise double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
  if (nd == 0.0lf) return false;
  precise double num = n[0] * s[0] + n[1] * s[1] + n[2] * s[2];
  precise double size = abs(s[0]) * (abs(e1[1] * e2[2]) + abs(e1[2] * e2[1])) +
                        abs(s[1]) * (abs(e1[2] * e2[0]) + abs(e1[0] * e2[2])) +
                        abs(s[2]) * (abs(e1[0] * e2[1]) + abs(e1[1] * e2[0]));
  if (abs(num) <= ldexp(1.0lf, -49) * size) num = 0.0lf;
  precise double td = num / nd;
  if (!(td >= 0.0lf)) return false;
  t = float(abs(td));
  if (!(t >= r.tmin && t <= min(limit, kFloatMax))) return false;
  u = 0.0, v = 0.0;
  if ((kFlags & MC_HIT_UV) != 0u) {
    precise double p[3] = double[3](d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]);
    precise double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    precise double q[3] = double[3](-s[1] * e1[2] + s[2] * e1[1], -s[2] * e1[0] + s[0] * e1[2], -s[0] * e1[1] + s[1] * e1[0]);
    u = float(-(s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det);
    v = float((d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det);
  }
  return true;
}

// cpu/intersect.h's kFloatWindow: a triangle whose float t lies within
// 2^-10 of its corners' largest |sz z| of [r.tmin, closest] gets its t in
// double; one past that is no hit.
#define kFloatWindow uintBitsToFloat(0x3A800000u)  // 2^-10

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
  bool settled = !(U == 0.0 || V == 0.0 || W == 0.0);
  if (settled) {
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
    precise float det = U + V + W;
    precise float zs0 = r.sz * az, zs1 = r.sz * bz, zs2 = r.sz * cz;
    precise float T = U * zs0 + V * zs1 + W * zs2;
    const float dets = abs(det), Tabs = abs(T);
    settled = dets >= kSettleTiny && dets < kSettleHuge && Tabs >= kSettleTiny && Tabs < kInfinity;
    if (settled) {
      if (culled(det > 0.0)) return false;
      precise float tf = (det < 0.0 ? -T : T) / dets;
      precise float slack = max(max(abs(zs0), abs(zs1)), abs(zs2)) * kFloatWindow;
      precise float lo = tf + slack, hi = tf - slack;
      if (!(lo >= r.tmin && hi <= min(closest, kFloatMax))) return false;
    }
  }
  if (!settled && !watertight_inside_double(ax, ay, bx, by, cx, cy)) return false;
  return hit_in_double(r, a, b, c, closest, t, u, v);
}

#endif
