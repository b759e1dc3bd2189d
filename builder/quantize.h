// Quantization: the mesh grid a bit-packed triangle format stores positions
// on, the triangles' corners as the format stores them (and their boxes,
// from which every tree is built), and the nested block lattices of the
// BitPackSOA formats (layout/triangles/soa.h).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "builder/binary_tree.h"
#include "builder/build_threads.h"
#include "builder/first_touch.h"
#include "builder/writer.h"
#include "layout/blob_format.h"

namespace meshcast {

// The header's quant_offset and quant_scale for `codec`'s grid over
// `mesh_box` (zeros when the codec keeps floats). Throws InputError naming
// `name` when an axis is too thin for the grid's steps to stay normal floats.
void set_mesh_grid(const Box3& mesh_box, const CodecOps& codec, const std::string& name, layout::BlobHeader& h);

// Each triangle's corners as stored (on the header's grid when the codec has
// one; none for a codec with no blocks to encode) and the box of those
// corners.
struct StoredTriangles {
  FilledVector<layout::TriCorners> corners;  // every field set by store_triangles
  std::vector<Box3> boxes;
};
StoredTriangles store_triangles(const Mesh& mesh, const CodecOps& codec, const layout::BlobHeader& h,
                                BuildThreads* threads);

// Nested-lattice codecs (CodecOps::nested): moves every corner onto the
// coarsest lattice among the blocks of `lanes` consecutive triangles of a
// leaf of `t` that use it; returns the largest shift (the header's
// max_block_shift).
uint32_t snap_to_block_lattices(const BuildTree& t, FilledVector<layout::TriCorners>& corners, uint32_t lanes,
                                const float grid[3]);

}  // namespace meshcast
