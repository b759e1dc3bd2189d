// What a triangle codec is given to encode one leaf's block, and what it
// decodes one triangle back to. Each codec lives in its own header
// (float3.h, soa.h, indexed.h, ...) as a struct of static members whose
// contract is the TriangleCodec concept below; the optional traits are
// defaulted here, once.
#pragma once
#include <concepts>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "layout/blob_format.h"

namespace meshcast::layout {

// One triangle as the codec stores it. The writer passes the leaf's
// triangles with their corners (bit-packed formats already quantized against
// the mesh box); encode() leaves them in the order it stored them, with the
// corners the walker will decode, so the writer can build the remap and fit
// the leaf's bounds to exactly what is stored.
struct TriCorners {
  float v[3][3];       // corner, axis
  uint64_t packed[3];  // BitPack word of each corner (bit-packed formats only)
  uint32_t vertex[3];  // the input mesh's vertex of each corner
  uint32_t input;      // the input mesh's triangle
};

// How a triangle format places vertices before encoding:
//   kGridNone      stored as given (floats)
//   kGridMeshBox   BitPack grid of seed 000 §3.4 over the mesh box:
//                  scale = extent / (2^21 - 1), offset = box minimum
//   kGridPowerOfTwo the same 21-bit range with a power-of-two step and an
//                  offset on that step, so block-relative codes decode exactly
enum GridKind : uint32_t { kGridNone = 0, kGridMeshBox = 1, kGridPowerOfTwo = 2 };

// State shared by the blocks of one blob while it is written.
struct BlockContext {
  uint32_t block_address = 0;   // blob offset of the block being written
  uint32_t vertex_section = 0;  // blob offset of the vertex section
  // Shared vertex pool of the indexed formats, as the vertex section's bytes,
  // and the pool index a key (packed word or input vertex) last received.
  std::vector<uint8_t>* pool = nullptr;
  std::unordered_map<uint64_t, uint32_t>* last_index = nullptr;
  const float* grid_step = nullptr;   // the mesh grid (header quant_scale), kGridPowerOfTwo formats
  uint32_t* max_block_shift = nullptr;  // largest m of a BitPackSOA block (soa.h)
  const BlobHeader* header = nullptr;   // the blob's header as far as it is known (grids)
};

// The contract every triangle codec meets (checked for each in codecs.h):
//   kFormat        its MC_TRI_* id        kLanes   triangles a test takes
//   kSlotDivisor   block bytes a slot     kGrid    where its vertices lie
//   block_bytes(count)            bytes of a block of `count` (the most, for
//                                 formats whose blocks vary)
//   encode(tris, count, ctx, out) writes one leaf's block
//   decode(blob, block, i, out)   the corners of triangle i of a block
//   check(blob, block, count, why) what validation must prove of a block
// Optional: kNestedBlocks, kGridBits, kMovesFloats, measure(), stored_bytes().
template <class C>
concept TriangleCodec = requires(TriCorners* tris, uint32_t count, BlockContext& ctx, uint8_t* out,
                                 const uint8_t* blob, uint32_t block, float (&corners)[3][3], std::string* why) {
  { C::kFormat } -> std::convertible_to<uint32_t>;
  { C::kSlotDivisor } -> std::convertible_to<uint32_t>;
  { C::kLanes } -> std::convertible_to<uint32_t>;
  { C::kGrid } -> std::convertible_to<GridKind>;
  { C::block_bytes(count) } -> std::convertible_to<uint64_t>;
  C::encode(tris, count, ctx, out);
  C::decode(blob, block, count, corners);
  { C::check(blob, block, count, why) } -> std::convertible_to<bool>;
};

// The optional traits' defaults:
//   nested_blocks  blocks on nested lattices of the mesh grid (BitPackSOA)
//   grid_bits      bits a grid coordinate takes (the BitPack 21 otherwise)
//   moves_floats   a float format that still moves vertices (cleared bits)
//   independent_blocks  encode() writes nothing but its own block (no
//                  shared vertex pool, no shared maximum), so the leaves
//                  may be encoded on several threads at once; otherwise
//                  they are encoded one after another, in order
//   measure        bytes a leaf's block will take (block_bytes otherwise)
template <class C>
constexpr bool nested_blocks() {
  if constexpr (requires { C::kNestedBlocks; }) return C::kNestedBlocks;
  else return false;
}
template <class C>
constexpr uint32_t grid_bits() {
  if constexpr (requires { C::kGridBits; }) return C::kGridBits;
  else return MC_BITPACK_BITS;
}
template <class C>
constexpr bool moves_floats() {
  if constexpr (requires { C::kMovesFloats; }) return C::kMovesFloats;
  else return false;
}
template <class C>
constexpr bool independent_blocks() {
  if constexpr (requires { C::kIndependentBlocks; }) return C::kIndependentBlocks;
  else return false;
}
template <class C>
uint32_t measure(TriCorners* tris, uint32_t count) {
  if constexpr (requires { C::measure(tris, count); }) return C::measure(tris, count);
  else return C::block_bytes(count);
}

// Bytes a block of `count` triangles takes in a blob: block_bytes(count) for
// fixed-size formats; formats whose blocks vary (strips) read their own,
// returning 0 when the block does not end within `limit` bytes or is broken.
template <class C>
uint64_t stored_bytes(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit) {
  if constexpr (requires { C::stored_bytes(blob, block, count, limit); }) return C::stored_bytes(blob, block, count, limit);
  else return C::block_bytes(count);
}

// Formats whose blocks are read front to back (strips, pair blocks): their
// size and any one triangle come from the format's read(blob, block,
// count, limit, emit), which also checks the block's grammar.
template <class C>
struct ReadBack {
  static uint64_t stored_bytes(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit) {
    return C::read(blob, block, count, limit, [](uint32_t, const float(*)[3]) {});
  }
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    C::read(blob, block, i + 1, ~0ull, [&](uint32_t k, const float(*p)[3]) {
      if (k == i) std::memcpy(out, p, 36);
    });
  }
  static bool check(const uint8_t*, uint32_t, uint32_t, std::string*) { return true; }  // read() checks
};

// Appends a vertex record to the pool; returns its index (record number).
inline uint32_t pool_append(std::vector<uint8_t>& pool, const void* record, size_t bytes) {
  uint32_t index = uint32_t(pool.size() / bytes);
  const uint8_t* p = static_cast<const uint8_t*>(record);
  pool.insert(pool.end(), p, p + bytes);
  return index;
}

// The bit-packed vertex of seed 000 §3.4: 21 bits per component in a uint64,
// x in the low bits. Decoding is one fused multiply-add per component, done
// the same way (and so to the same bits) by every walker and shader.
inline uint32_t bitpack_component(uint64_t w, int axis) {
  return uint32_t(w >> (MC_BITPACK_BITS * axis)) & MC_BITPACK_MAX;
}
void bitpack_decode(uint64_t w, const float offset[3], const float scale[3], float out[3]);
// The grid point q in [0, max] whose decode fma(q, scale, offset) lies
// nearest v (0 when scale is 0).
uint32_t quantize(float v, float offset, float scale, uint32_t max);
uint64_t bitpack_encode(const float v[3], const float offset[3], const float scale[3]);

}  // namespace meshcast::layout
