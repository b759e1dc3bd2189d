// Method 3 of seed 000 §7: AABBTree (§5.1), one ray a thread with its own
// stack: the walk of cpu/walk_aabbtree.cpp (both children tested, the nearer
// walked, the farther pushed with its entry distance and dropped once the
// closest hit is nearer). The including file defines test_leaf() for its
// triangle format.
#include "shaders/batch_counters.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

vec3 node_min(uint at) { return blob_vec3(at + MC_AABB_MIN_AT); }
vec3 node_max(uint at) { return blob_vec3(at + MC_AABB_MAX_AT); }

void main() {
  const uint ray = pc.ray_base + gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const GpuRay r = load_ray(ray);
  count_unwalkable(r.walkable);
  Closest c = closest_start(ray, r);
  const uint tree = header(MC_HDR_TREE_OFFSET);
  if (r.walkable && box_test(r, node_min(tree), node_max(tree), c.t) != kInfinity) {
    uint stack_node[MC_MAX_DEPTH + 2u];
    float stack_t[MC_MAX_DEPTH + 2u];
    int top = -1;
    uint at = 0u;
    for (;;) {
      const uint props = blob_u32(tree + at + MC_AABB_PROPERTIES_AT);
      if ((props & MC_AABB_LEAF_BIT) == 0u) {
        const uint left = at + MC_AABB_NODE_BYTES, right = props & MC_AABB_VALUE_MASK;
        const float lt = box_test(r, node_min(tree + left), node_max(tree + left), c.t);
        const float rt = box_test(r, node_min(tree + right), node_max(tree + right), c.t);
        const bool lhit = lt != kInfinity, rhit = rt != kInfinity;
        if (lhit && rhit) {
          ++top;
          if (lt <= rt) stack_node[top] = right, stack_t[top] = rt, at = left;
          else stack_node[top] = left, stack_t[top] = lt, at = right;
          continue;
        }
        if (lhit || rhit) {
          at = lhit ? left : right;
          continue;
        }
      } else {
        const uint block = at + MC_AABB_NODE_BYTES;
        test_leaf(r, tree + block, props & MC_AABB_VALUE_MASK, slot_of(block), c);
      }
      while (top >= 0 && stack_t[top] > c.t * kFarScale) --top;
      if (top < 0) break;
      at = stack_node[top--];
    }
  }
  write_closest(ray, c);
}
