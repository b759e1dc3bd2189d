// What the one-ray-a-thread tree walkers share: the closest hit so far, the
// conservative box test of cpu/intersect.h (Ize 2013) and the Float3 leaf test.
#ifndef MESHCAST_WALK_GLSL
#define MESHCAST_WALK_GLSL

// The sign bit, -0 included (std::signbit).
bool sign_bit(float x) { return (floatBitsToUint(x) >> 31) != 0u; }

// GLSL's min and max are undefined on NaN; these keep their second operand,
// as max_keep/min_keep do on the CPU (a slab the ray lies in constrains nothing).
float max_keep(float a, float b) { return a > b ? a : b; }
float min_keep(float a, float b) { return a < b ? a : b; }

// 1 + 2 gamma(3), gamma(n) = n u / (1 - n u), u = 2^-24 (cpu/intersect.h).
const float kFarScale = 1.0 + 2.0 * (3.0 * 5.9604644775390625e-8) / (1.0 - 3.0 * 5.9604644775390625e-8);

// The walk's answer so far: `t` is the cut every box and triangle test and
// stack pop compares against (the closest hit's t; below 0 once a
// Query::Any has its hit; t_max throughout a Query::All, whose hits go to
// the ray's row), `hit_t` the taken hit's t. As `Closest` in cpu/leaf.h.
struct Closest {
  float t;
  uint slot;
  float u, v;
  float hit_t;
  uint ray;
};

#ifndef MESHCAST_WALK_BOXES_ONLY
#include "shaders/hit_rows.glsl"

Closest closest_start(uint ray, GpuRay r) {
  if ((kFlags & MC_QUERY_ALL) != 0u) row_start(ray);
  return Closest(r.tmax, MC_NO_HIT, 0.0, 0.0, kInfinity, ray);
}
#endif

// The ray's interval [tn, tf] inside the box, each end one rounding of
// (plane - origin) * 1/d (the slabs of box_interval in cpu/intersect.h).
void box_interval(GpuRay r, vec3 mn, vec3 mx, out float tn, out float tf) {
  tn = 0.0, tf = kInfinity;
  for (int a = 0; a < 3; ++a) {
    const bool neg = sign_bit(r.dir[a]);
    precise float dn = ((neg ? mx[a] : mn[a]) - r.org[a]) * r.inv[a];
    precise float df = ((neg ? mn[a] : mx[a]) - r.org[a]) * r.inv[a];
    tn = max_keep(dn, tn);
    tf = min_keep(df, tf);
  }
}

// Whether [lo, hi] is open before the closest hit, the far end widened.
bool interval_open(float lo, float hi, float closest) {
  precise float limit = min_keep(hi, closest) * kFarScale;
  return lo <= limit;
}

// Entry distance of the box, or +inf for a miss (box_test of cpu/intersect.h).
float box_test(GpuRay r, vec3 mn, vec3 mx, float closest) {
  float tn, tf;
  box_interval(r, mn, mx, tn, tf);
  return interval_open(tn, tf, closest) ? tn : kInfinity;
}

#ifndef MESHCAST_WALK_BOXES_ONLY
// The triangle (a, b, d) of slot `slot`, if the ray hits it before the cut:
// the closest hit so far, any query's hit (the cut then below 0), or one
// more of all hits.
void consider(GpuRay r, vec3 a, vec3 b, vec3 d, uint slot, inout Closest c) {
  float t, u, v;
  if (!watertight(r, a, b, d, c.t, t, u, v) || !(t <= c.t)) return;
  if ((kFlags & MC_QUERY_ALL) != 0u) {
    row_add(c.ray, t, slot);
    return;
  }
  c.slot = slot, c.u = u, c.v = v, c.hit_t = t;
  c.t = (kFlags & MC_QUERY_ANY) != 0u ? -1.0 : t;
}

// `count` Float3 triangles (9 floats each) at blob offset `block`, slots
// from slot0.
void test_float3_leaf(GpuRay r, uint block, uint count, uint slot0, inout Closest c) {
  for (uint i = 0u; i < count; ++i) {
    const uint p = block + MC_FLOAT3_TRI_BYTES * i;
    const vec3 a = blob_vec3(p), b = blob_vec3(p + 12u), d = blob_vec3(p + 24u);  // the 3 corners
    consider(r, a, b, d, slot0 + i, c);
  }
}

uint slot_of(uint tree_block) { return (tree_block - header(MC_HDR_TRIANGLE_BASE)) / header(MC_HDR_SLOT_DIVISOR); }

// The ray's answer: its hit record, or for Query::All its finished row
// (and a miss record).
void write_closest(uint ray, Closest c) {
  if ((kFlags & MC_QUERY_ALL) != 0u) row_finish(ray);
  if (c.slot == MC_NO_HIT) write_miss(ray);
  else write_hit(ray, c.hit_t, remap_entry(c.slot), c.u, c.v);
}
#endif

#endif
