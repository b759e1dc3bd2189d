// What the builder needs of each triangle codec, looked up by format id
// (builder/writer.h's CodecOps): the codec's constants and its optional
// traits (layout/triangles/block.h defaults them).
#include "builder/writer.h"
#include "layout/triangles/codecs.h"

namespace meshcast {

using layout::grid_bits;
using layout::independent_blocks;
using layout::measure;
using layout::moves_floats;
using layout::nested_blocks;

CodecOps codec_ops(uint32_t format) {
#define MC_OPS(Codec, name)                                                                         \
  if (format == layout::Codec::kFormat)                                                            \
    return {layout::Codec::kFormat,        layout::Codec::kSlotDivisor,   layout::Codec::kGrid,        \
            grid_bits<layout::Codec>(),    nested_blocks<layout::Codec>(), moves_floats<layout::Codec>(), \
            independent_blocks<layout::Codec>(),                                                   \
            layout::Codec::kLanes,         &measure<layout::Codec>,       &layout::Codec::encode};
  MC_FOR_EACH_TRIANGLE_CODEC(MC_OPS)
#undef MC_OPS
  throw InputError("unknown triangle format " + std::to_string(format));
}

}  // namespace meshcast
