// The one list of triangle formats: validation, the writer, the walkers'
// dispatch table and the layout names are all generated from it.
#pragma once
#include "layout/triangles/bitpack.h"
#include "layout/triangles/cluster.h"
#include "layout/triangles/float3.h"
#include "layout/triangles/soa.h"
#include "layout/triangles/strip.h"
#include "layout/triangles/indexed.h"
#include "layout/triangles/indexed8bitpacksoa4.h"
#include "layout/triangles/pairsoa.h"

// X(codec type in meshcast::layout, its name as the seed writes it)
#define MC_FOR_EACH_TRIANGLE_CODEC(X)                  \
  X(Float3, "Float3")                                  \
  X(Float3SOA4, "Float3SOA4")                          \
  X(Indexed8BitPackSOA4, "Indexed8BitPackSOA4")        \
  X(Indexed16, "Indexed16")                            \
  X(Indexed32, "Indexed32")                            \
  X(Indexed16SOA4, "Indexed16SOA4")                    \
  X(Indexed32SOA4, "Indexed32SOA4")                    \
  X(Indexed16BitPackSOA4, "Indexed16BitPackSOA4")      \
  X(Indexed32BitPackSOA4, "Indexed32BitPackSOA4")      \
  X(Float3SOA8, "Float3SOA8")                          \
  X(Float3SOA128, "Float3SOA128")                      \
  X(BitPackSOA4, "BitPackSOA4")                        \
  X(BitPackSOA128, "BitPackSOA128")                    \
  X(BitPack, "BitPack")                                \
  X(UncompressedStrip, "UncompressedStrip")            \
  X(CompressedStrip, "CompressedStrip")                \
  X(Float3PairSOA4, "Float3PairSOA4")                  \
  X(ClusterBitPackSOA8, "ClusterBitPackSOA8")          \
  X(ClusterFloat3SOA8, "ClusterFloat3SOA8")

namespace meshcast::layout {
#define MC_CHECK_CODEC(Codec, name) static_assert(TriangleCodec<Codec>, name " meets the codec contract");
MC_FOR_EACH_TRIANGLE_CODEC(MC_CHECK_CODEC)
#undef MC_CHECK_CODEC
}  // namespace meshcast::layout
