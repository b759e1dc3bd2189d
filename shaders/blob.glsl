// The blob as the CPU wrote it, bound as one read-only uint array, and the
// readers every method shares: header fields, and the remap from a triangle
// slot to the caller's triangle index (layout/blob_format.h describes the section).
#ifndef MESHCAST_BLOB_GLSL
#define MESHCAST_BLOB_GLSL

#include "layout/formats.h"

layout(std430, set = 0, binding = 0) readonly buffer Blob { uint blob_words[]; };

// The scene method (MC_SCENE) binds every mesh's blob in one buffer, each
// at a word offset: the blob an instance walks starts at blob_base. Offsets
// everywhere else are the blob's own, as the CPU reads them.
#ifdef MC_SCENE
uint blob_base = 0u;
#define MC_BLOB_WORD(w) (blob_base + (w))
#else
#define MC_BLOB_WORD(w) (w)
#endif

uint blob_u32(uint byte_offset) { return blob_words[MC_BLOB_WORD(byte_offset >> 2)]; }
float blob_f32(uint byte_offset) { return uintBitsToFloat(blob_u32(byte_offset)); }
// Three floats in a row (a box corner, a vertex).
vec3 blob_vec3(uint byte_offset) {
  return vec3(blob_f32(byte_offset), blob_f32(byte_offset + 4u), blob_f32(byte_offset + 8u));
}
uint header(uint word) { return blob_words[MC_BLOB_WORD(word)]; }

// remap_entry of layout/blob_format.h: the used-slot bitmap (64-bit words), the
// rank of each word, then the bit-packed entries; or in input order (no
// entries), or no remap at all.
uint remap_entry(uint slot) {
  if (header(MC_HDR_REMAP_SIZE) == 0u) return slot;  // no remap section: hits name slots
  const uint base = header(MC_HDR_REMAP_OFFSET);
  const uint words = (header(MC_HDR_REMAP_SLOTS) + 63u) / 64u;
  const uint w = slot >> 6, bit = slot & 63u;
  const uint lo = blob_u32(base + 8u * w), hi = blob_u32(base + 8u * w + 4u);
  const uint below = bit < 32u ? bitCount(lo & ((1u << bit) - 1u))
                               : uint(bitCount(lo)) + bitCount(hi & ((1u << (bit - 32u)) - 1u));
  const uint index = blob_u32(base + 8u * words + 4u * w) + below;
  const uint bits = header(MC_HDR_REMAP_BITS);
  if (bits == 0u) return index;  // in input order: the n-th used slot is triangle n
  // Entry `index` starts `index * bits` bits into the entries (8-aligned);
  // it spans at most two 32-bit words.
  const uint64_t at = uint64_t(base + 12u * words) * 8ul + uint64_t(index) * uint64_t(bits);
  const uint word = uint(at >> 5), shift = uint(at & 31ul);
  const uint64_t pair = uint64_t(blob_words[MC_BLOB_WORD(word)]) | (uint64_t(blob_words[MC_BLOB_WORD(word + 1u)]) << 32);
  return uint((pair >> shift) & ((1ul << bits) - 1ul));
}

#endif
