// Quantization (builder/quantize.h): the mesh grid, the stored corners, and
// the BitPackSOA block lattices.
#include "builder/quantize.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <unordered_map>

#include "layout/triangles/codecs.h"
#include "layout/message_text.h"

namespace meshcast {

using layout::TriCorners;

namespace {

// The least extent an axis of a grid format's mesh may have (above 0):
// where its step reaches FLT_MIN. A mesh box grid divides the extent into
// MC_BITPACK_MAX steps; a power-of-two grid's step is at most 2^(1 - bits)
// of the extent (codes = 2^bits - 2).
double least_grid_extent(const CodecOps& codec) {
  if (codec.grid == layout::kGridMeshBox) return double(FLT_MIN) * MC_BITPACK_MAX;
  return double(FLT_MIN) * 0.5 * (std::ldexp(1.0, int(codec.grid_bits)) - 2);
}

}  // namespace

void set_mesh_grid(const Box3& mesh_box, const CodecOps& codec, const std::string& name, layout::BlobHeader& h) {
  const bool grid = codec.grid != layout::kGridNone;
  for (int a = 0; a < 3; ++a) {
    double lo = mesh_box.min[a], extent = double(mesh_box.max[a]) - lo;
    if (codec.grid == layout::kGridMeshBox) {
      h.quant_offset[a] = float(lo), h.quant_scale[a] = float(extent / MC_BITPACK_MAX);
    } else if (codec.grid == layout::kGridPowerOfTwo) {
      // The smallest power of two that spans the extent in 2^21 - 2 steps,
      // and the grid point at or below the minimum.
      // A flat axis keeps its one coordinate (step 0).
      double codes = std::ldexp(1.0, int(codec.grid_bits)) - 2;
      double step = extent > 0 ? std::ldexp(1.0, std::ilogb(extent / codes) + 1) : 0.0;
      h.quant_scale[a] = float(step), h.quant_offset[a] = step > 0 ? float(std::floor(lo / step) * step) : float(lo);
    } else {
      h.quant_offset[a] = 0, h.quant_scale[a] = 0;
    }
    // A step below FLT_MIN would be a denormal float: rounded coarser than
    // the format states, flushed to 0 by a GPU (the axis flattened), or 0
    // outright (float's own underflow). The least extent a grid takes is
    // about 2^-105 (2.5e-32), beside kMaxCoordinate's 2^100 above.
    if (grid && extent > 0 && !(h.quant_scale[a] >= FLT_MIN))
      throw InputError(name + ": the mesh spans " + number_text(extent) + " on axis " + "xyz"[a] + ", less than the " +
                       number_text(least_grid_extent(codec)) + " that " +
                       std::string(layout::triangle_format_name(h.triangle_format)) + "'s grid of " +
                       std::to_string(codec.grid_bits) + "-bit codes needs (a step below 2^-126, the least normal float, "
                       "would round vertices coarser than stated); build it in a float format (Float3) or scale it up");
  }
}

StoredTriangles store_triangles(const Mesh& mesh, const CodecOps& codec, const layout::BlobHeader& h,
                                BuildThreads* threads) {
  const bool grid = codec.grid != layout::kGridNone;
  FilledVector<uint64_t> packed(grid ? mesh.vertices.size() : 0);
  for_each_on(threads, packed.size(), 4096, [&](uint64_t v) {
    float p[3] = {mesh.vertices[v].x, mesh.vertices[v].y, mesh.vertices[v].z};
    packed[v] = layout::bitpack_encode(p, h.quant_offset, h.quant_scale);
  });
  // A format with no blocks to encode (CodecOps::encode null) keeps no
  // corners: its tree is built from the boxes alone.
  const bool blocks = codec.encode != nullptr;
  StoredTriangles s{FilledVector<TriCorners>(blocks ? mesh.triangles.size() : 0), std::vector<Box3>(mesh.triangles.size())};
  std::vector<Box3>& boxes = s.boxes;
  for_each_on(threads, mesh.triangles.size(), 4096, [&](uint64_t t) {
    TriCorners unkept;
    TriCorners& tri = blocks ? s.corners[t] : unkept;
    tri.input = uint32_t(t);
    for (int c = 0; c < 3; ++c) {
      uint32_t v = mesh.triangles[t][c];
      if (grid) {
        tri.vertex[c] = v;
        tri.packed[c] = packed[v];
        layout::bitpack_decode(packed[v], h.quant_offset, h.quant_scale, tri.v[c]);
      } else {
        tri.packed[c] = 0;
        tri.vertex[c] = v;
        tri.v[c][0] = mesh.vertices[v].x, tri.v[c][1] = mesh.vertices[v].y;
        tri.v[c][2] = mesh.vertices[v].z;
      }
      boxes[t].grow(Vec3{tri.v[c][0], tri.v[c][1], tri.v[c][2]});
    }
  });
  return s;
}

// kGridPowerOfTwo formats (BitPackSOA, layout/triangles/soa.h): blocks of `lanes`
// consecutive triangles of each leaf; every position goes to the coarsest
// block lattice among the blocks that use it, repeated until no block needs
// a coarser step, so all blocks decode a shared position to the same bits.
// Positions are keyed by their mesh-grid word (so unwelded copies of a
// vertex move together) and rounded once, from the grid position, to their
// final lattice. Returns the largest shift.
uint32_t snap_to_block_lattices(const BuildTree& t, FilledVector<TriCorners>& corners, uint32_t lanes,
                                const float grid[3]) {
  const FilledVector<TriCorners> original = corners;
  uint32_t largest = 0;
  for (int axis = 0; axis < 3; ++axis) {
    std::unordered_map<uint64_t, uint32_t> shift;  // grid word -> lattice shift
    for (bool changed = true; changed;) {
      changed = false;
      for (const BuildNode& leaf : t.nodes) {
        if (!leaf.leaf()) continue;
        for (uint32_t b = 0; b < leaf.count; b += lanes) {
          float lo = INFINITY, hi = -INFINITY;
          uint32_t end = std::min(leaf.count, b + lanes);
          for (uint32_t i = b; i < end; ++i)
            for (int c = 0; c < 3; ++c) {
              float v = corners[t.order[leaf.first + i]].v[c][axis];
              lo = std::min(lo, v), hi = std::max(hi, v);
            }
          float step, offset;
          uint32_t m;
          layout::block_step(lo, hi, grid[axis], &step, &offset, &m);
          for (uint32_t i = b; i < end; ++i)
            for (int c = 0; c < 3; ++c) {
              uint32_t& s = shift[original[t.order[leaf.first + i]].packed[c]];
              if (m > s) s = m, changed = true;
            }
        }
      }
      for (size_t k = 0; k < corners.size(); ++k)
        for (int c = 0; c < 3; ++c) {
          auto it = shift.find(original[k].packed[c]);
          uint32_t m = it == shift.end() ? 0 : it->second;
          double step = double(grid[axis]) * std::ldexp(1.0, int(m));
          float v = original[k].v[c][axis];
          corners[k].v[c][axis] = step > 0 ? float(std::round(double(v) / step) * step) : v;
        }
    }
    for (const auto& [word, m] : shift) largest = std::max(largest, m);
  }
  return largest;
}

}  // namespace meshcast
