// What the builder needs of each triangle codec, looked up by format id
// (builder/writer.h's CodecOps): the codec's constants, with the optional
// ones defaulted here once.
#include "builder/writer.h"
#include "layout/codecs.h"

namespace meshcast {

namespace {

template <class C>
constexpr bool nested_blocks() {
  if constexpr (requires { C::kNestedBlocks; }) return C::kNestedBlocks;
  return false;
}
template <class C>
constexpr uint32_t grid_bits() {
  if constexpr (requires { C::kGridBits; }) return C::kGridBits;
  return MC_BITPACK_BITS;
}
template <class C>
constexpr bool moves_floats() {
  if constexpr (requires { C::kMovesFloats; }) return C::kMovesFloats;
  return false;
}
template <class C>
uint32_t measure(TriCorners* tris, uint32_t count) {
  if constexpr (requires { C::measure(tris, count); }) return C::measure(tris, count);
  return C::block_bytes(count);
}

}  // namespace

CodecOps codec_ops(uint32_t format) {
#define MC_OPS(Codec, name)                                                                         \
  if (format == layout::Codec::kFormat)                                                            \
    return {layout::Codec::kFormat,        layout::Codec::kSlotDivisor,   layout::Codec::kGrid,        \
            grid_bits<layout::Codec>(),    nested_blocks<layout::Codec>(), moves_floats<layout::Codec>(), \
            layout::Codec::kLanes,         &measure<layout::Codec>,       &layout::Codec::encode};
  MC_FOR_EACH_TRIANGLE_CODEC(MC_OPS)
#undef MC_OPS
  throw InputError("unknown triangle format " + std::to_string(format));
}

}  // namespace meshcast
