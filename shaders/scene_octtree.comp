// A scene, one world ray a thread: cpu/scene_trace.cpp's walk on
// the bytes a Scene::commit() made. The top level's 8-wide nodes of float
// boxes near the anchor (layout/tree/top_level.h), each instance the ray reaches
// walked in its OctTreeCompressed/ClusterBitPackSOA8 blob
// (shaders/octtree_walk.glsl) on the ray brought into its frame: the
// translation subtracted in double, rounded to float, then the float
// inverse, every step the CPU's operation (precise: nothing fused; the
// divisions of the ray's set-up rounded once, div_exact).
//
// Bindings: 0 every mesh's blob, one after another (the top buffer's
// table gives each one's first word); 1 the world rays as RayD records
// (3 doubles, 3 floats, t_max, t_min, padding: 12 words); 5 the top level; 6 the answers,
// 6 words a ray: t, instance, triangle, u, v and whether some part of the
// ray could not be walked (the CPU's count of such rays). 2 to 4 are the
// blob methods' (unused here).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#define MC_SCENE 1
#include "shaders/blob.glsl"
#include "shaders/hits.glsl"
#include "shaders/octtree_walk.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, mask; } pc;

// The top level as gpu/scene.cpp lays it out: a header of words, then the
// snapshot's placed records and wide nodes byte for byte.
#define TOP_ANCHOR 0u       // 3 doubles
#define TOP_MIN 6u          // the root box, 3 doubles each
#define TOP_MAX 12u
#define TOP_NODES 18u       // wide nodes (0: nothing placed)
#define TOP_PLACED_AT 19u   // first word of the placed records
#define TOP_WIDE_AT 20u     // first word of the wide nodes
#define TOP_MESH_BASE 24u   // a word a mesh: its blob's first word in binding 0
layout(std430, set = 0, binding = 5) readonly buffer Top { uint top_words[]; };

#define SCENE_HIT_WORDS 6u
layout(std430, set = 0, binding = 6) writeonly buffer SceneHits { uint scene_hits[]; };


double top_f64(uint word) { return packDouble2x32(uvec2(top_words[word], top_words[word + 1u])); }

// See MC_TOP_MAX_DEPTH (layout/formats.h).
#define TOP_STACK_SIZE (7u * MC_TOP_MAX_DEPTH + 8u)

void main() {
  const uint ray = pc.ray_base + gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const uint w = ray * MC_RAYD_WORDS;
  dvec3 org;
  for (uint a = 0u; a < 3u; ++a)
    org[a] = packDouble2x32(uvec2(ray_words[w + MC_RAYD_ORG + 2u * a], ray_words[w + MC_RAYD_ORG + 2u * a + 1u]));
  const vec3 given_dir = ray_vec3(w, MC_RAYD_DIR);
  const vec3 dir = walked_direction(given_dir);  // as WorldRay of cpu/scene_trace.cpp
  const float tmax = ray_word(w, MC_RAYD_TMAX), tmin = ray_word(w, MC_RAYD_TMIN);
  float best_t = kInfinity, best_u = 0.0, best_v = 0.0;
  uint best_instance = MC_NO_HIT, best_triangle = MC_NO_HIT, incomplete = 0u;
  const double max_coordinate = 1267650600228229401496703205376.0lf;  // 2^100
  const bool walkable = all(lessThanEqual(abs(org), dvec3(max_coordinate))) && directions_walkable(dir, tmin, tmax);
  if (!walkable) incomplete = 1u;
  if (walkable && top_words[TOP_NODES] > 0u) {
    // The world ray as the top level's float boxes read it (TopRay of
    // cpu/walk_top.h: each plane less its shift, rel widened by the pad).
    vec3 rel, inv;
    double far_from_box = 0.0lf;
    for (uint a = 0u; a < 3u; ++a) {
      rel[a] = float(org[a] - top_f64(TOP_ANCHOR + 2u * a));
      inv[a] = div_exact(1.0, dir[a]);
      far_from_box = max(far_from_box, max(abs(org[a] - top_f64(TOP_MIN + 2u * a)), abs(org[a] - top_f64(TOP_MAX + 2u * a))));
    }
    const float pad = float(far_from_box * MC_TOP_BOX_SLACK);
    precise vec3 lo_shift = rel + vec3(pad), hi_shift = rel - vec3(pad);  // a box grows by the pad
    const float widen = 1.0 + float(MC_TOP_BOX_SLACK);
    const uint placed_at = top_words[TOP_PLACED_AT], wide_at = top_words[TOP_WIDE_AT];
    float cut = tmax;
    uint stack[TOP_STACK_SIZE];
    float entries[TOP_STACK_SIZE];
    int top = 0;
    stack[0] = 0u, entries[0] = 0.0;  // the root node
    top = 1;
    while (top > 0) {
      --top;
      precise float reach = cut * widen;
      if (entries[top] > reach) continue;
      const uint item = stack[top];
      if ((item & MC_TOP_INSTANCE) != 0u) {
        const uint at = placed_at + (item & ~MC_TOP_INSTANCE) * (MC_PLACED_BYTES / 4u);
        if ((top_words[at + MC_PLACED_MASK_AT / 4u] & pc.mask) == 0u) continue;
        // The ray in the instance's frame (to_local()).
        vec3 from;
        for (uint a = 0u; a < 3u; ++a) from[a] = float(org[a] - top_f64(at + MC_PLACED_TRANSLATION_AT / 4u + 2u * a));
        vec3 local_org, local_dir;
        for (uint i = 0u; i < 3u; ++i) {
          const uint row = at + MC_PLACED_TO_LOCAL_AT / 4u + 3u * i;
          const float m0 = uintBitsToFloat(top_words[row]), m1 = uintBitsToFloat(top_words[row + 1u]),
                      m2 = uintBitsToFloat(top_words[row + 2u]);
          precise float o = m0 * from[0] + m1 * from[1] + m2 * from[2];
          precise float d = m0 * dir[0] + m1 * dir[1] + m2 * dir[2];
          local_org[i] = o, local_dir[i] = d;
        }
        // The world ray's t_min: t is the same number in both frames, and
        // the cut (t_max or a hit's t) never falls below it.
        const GpuRay local = prepared(local_org, local_dir, tmin, cut);
        if (!local.walkable) {  // its direction scaled past the walkers' range: not walked, counted
          incomplete = 1u;
          continue;
        }
        blob_base = top_words[TOP_MESH_BASE + top_words[at + MC_PLACED_MESH_AT / 4u]];
        instance_flip_facing = top_words[at + MC_PLACED_FLIP_FACING_AT / 4u] != 0u;
        Closest c = Closest(cut, MC_NO_HIT, 0.0, 0.0, kInfinity, ray);
        walk_octtree(local, c);
        if (c.slot == MC_NO_HIT) continue;
        const uint id = top_words[at + MC_PLACED_ID_AT / 4u];
        // Equal t: the lower instance id, as the oracle breaks ties.
        if (c.hit_t < cut || best_instance == MC_NO_HIT || (c.hit_t == cut && id < best_instance)) {
          best_t = c.hit_t, best_instance = id, best_triangle = remap_entry(c.slot);
          best_u = c.u, best_v = c.v;
          if ((kFlags & MC_QUERY_ANY) != 0u) break;
          cut = c.hit_t;
        }
        continue;
      }
      // The node's 8 boxes (enter_node of cpu/walk_top.cpp); the entered
      // ones pushed farthest first, so the nearest is popped next.
      const uint node = wide_at + item * (MC_TOP_NODE_BYTES / 4u);
      const int base = top;
      for (uint k = 0u; k < MC_TOP_WIDTH; ++k) {
        const uint slot = top_words[node + MC_TOP_SLOT_AT / 4u + k];
        if (slot == MC_TOP_EMPTY) continue;
        float tn = 0.0, tf = reach;
        for (uint a = 0u; a < 3u; ++a) {
          const float lo = uintBitsToFloat(top_words[node + MC_TOP_LO_AT / 4u + MC_TOP_WIDTH * a + k]);
          const float hi = uintBitsToFloat(top_words[node + MC_TOP_HI_AT / 4u + MC_TOP_WIDTH * a + k]);
          precise float t0 = (lo - lo_shift[a]) * inv[a];
          precise float t1 = (hi - hi_shift[a]) * inv[a];
          const bool negative = sign_bit(dir[a]);
          tn = max_keep(negative ? t1 : t0, tn);
          tf = min_keep(negative ? t0 : t1, tf);
        }
        if (!(tn <= tf)) continue;
        int j = top++;
        while (j > base && entries[j - 1] < tn) entries[j] = entries[j - 1], stack[j] = stack[j - 1], --j;
        entries[j] = tn, stack[j] = slot;
      }
    }
  }
  const uint o = ray * SCENE_HIT_WORDS;
  scene_hits[o] = floatBitsToUint(best_t);
  scene_hits[o + 1u] = best_instance;
  scene_hits[o + 2u] = best_triangle;
  scene_hits[o + 3u] = floatBitsToUint((kFlags & MC_HIT_UV) != 0u ? best_u : 0.0);
  scene_hits[o + 4u] = floatBitsToUint((kFlags & MC_HIT_UV) != 0u ? best_v : 0.0);
  scene_hits[o + 5u] = incomplete;
}
