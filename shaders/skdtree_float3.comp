// Method 4 of seed 000 §7: SKDTree (§5.5) with Float3 triangles, one ray a
// thread: the walk of cpu/walk_skdtree.cpp, the ray's [near, far] interval
// clipped by each node's two planes, the far end widened as in the box test.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"
#include "shaders/walk.glsl"

#include "shaders/batch_counters.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint ray = pc.ray_base + gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const GpuRay r = load_ray(ray);
  count_unwalkable(r.walkable);
  Closest c = closest_start(ray, r);
  const uint tree = header(MC_HDR_TREE_OFFSET);
  float tn, tf;
  box_interval(r, vec3(uintBitsToFloat(header(MC_HDR_BOUNDS_MIN)), uintBitsToFloat(header(MC_HDR_BOUNDS_MIN + 1u)),
                       uintBitsToFloat(header(MC_HDR_BOUNDS_MIN + 2u))),
               vec3(uintBitsToFloat(header(MC_HDR_BOUNDS_MAX)), uintBitsToFloat(header(MC_HDR_BOUNDS_MAX + 1u)),
                    uintBitsToFloat(header(MC_HDR_BOUNDS_MAX + 2u))),
               tn, tf);
  if (r.walkable && interval_open(tn, tf, c.t)) {
    uint stack_node[MC_MAX_DEPTH + 2u];
    float stack_near[MC_MAX_DEPTH + 2u], stack_far[MC_MAX_DEPTH + 2u];
    int top = -1;
    uint at = 0u;
    for (;;) {
      const uint props = blob_u32(tree + at + MC_SKD_PROPERTIES_AT);
      const uint axis = props >> MC_SKD_AXIS_SHIFT;
      if (axis != MC_SKD_LEAF_AXIS) {
        precise float tl = (blob_f32(tree + at + MC_SKD_LEFT_PLANE_AT) - r.org[axis]) * r.inv[axis];
        precise float tr = (blob_f32(tree + at + MC_SKD_RIGHT_PLANE_AT) - r.org[axis]) * r.inv[axis];
        const uint left = at + MC_SKD_INTERIOR_BYTES, right = props & MC_SKD_VALUE_MASK;
        float ln = tn, lf = tf, rn = tn, rf = tf;
        if (sign_bit(r.dir[axis])) ln = max_keep(tl, tn), rf = min_keep(tr, tf);
        else lf = min_keep(tl, tf), rn = max_keep(tr, tn);
        const bool lhit = interval_open(ln, lf, c.t), rhit = interval_open(rn, rf, c.t);
        if (lhit || rhit) {
          const bool left_first = lhit && (!rhit || ln < rn);
          if (lhit && rhit) {
            ++top;
            stack_node[top] = left_first ? right : left;
            stack_near[top] = left_first ? rn : ln;
            stack_far[top] = left_first ? rf : lf;
          }
          at = left_first ? left : right, tn = left_first ? ln : rn, tf = left_first ? lf : rf;
          continue;
        }
      } else {
        const uint block = at + MC_SKD_LEAF_BYTES;
        test_float3_leaf(r, tree + block, props & MC_SKD_VALUE_MASK, slot_of(block), c);
      }
      while (top >= 0 && !interval_open(stack_near[top], stack_far[top], c.t)) --top;
      if (top < 0) break;
      at = stack_node[top], tn = stack_near[top], tf = stack_far[top];
      --top;
    }
  }
  write_closest(ray, c);
}
