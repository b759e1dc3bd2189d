// What each lossy triangle format states it may move a vertex by: the
// bounds the error report prints, the automatic layout's --max-error
// limits, and StoredCornersWithinBound checks on every test mesh.
#include "builder/error_bounds.h"

#include <algorithm>
#include <cmath>

#include "builder/quantize.h"
#include "builder/writer.h"
#include "layout/blob_format.h"

namespace meshcast {

using layout::BlobHeader;

void quantization_bound(const float offset[3], const float scale[3], float bound[3]) {
  for (int a = 0; a < 3; ++a) {
    float top = std::fabs(offset[a]) + float(MC_BITPACK_MAX) * scale[a];
    float ulp = std::nextafter(std::max(std::fabs(offset[a]), top), INFINITY) - std::max(std::fabs(offset[a]), top);
    bound[a] = 0.5f * scale[a] + float(MC_BITPACK_MAX) * scale[a] * 0x1p-23f + ulp;
  }
}

void displacement_bound(std::span<const uint8_t> blob, float bound[3]) {
  const BlobHeader& h = layout::header_of(blob.data());
  if (h.triangle_format == MC_TRI_INDEXED24) {  // the mesh's own floats
    for (int a = 0; a < 3; ++a) bound[a] = 0;
    return;
  }
  layout::GridKind grid = codec_ops(h.triangle_format).grid;
  if (grid == layout::kGridMeshBox) return quantization_bound(h.quant_offset, h.quant_scale, bound);
  for (int a = 0; a < 3; ++a) {
    float top = std::max(std::fabs(h.bounds_min[a]), std::fabs(h.bounds_max[a]));
    if (grid == layout::kGridNone) {  // floats kept, or moved by 1 ulp (UncompressedStrip)
      bound[a] = codec_ops(h.triangle_format).moves_floats ? std::nextafter(top, INFINITY) - top : 0.0f;
      continue;
    }
    // Half the grid step (the input rounded to the mesh grid), half the
    // coarsest block step for nested formats (the grid position rounded once
    // to its block lattice), and one rounding of the largest coordinate.
    float lattice = codec_ops(h.triangle_format).nested ? 0.5f * h.quant_scale[a] * std::ldexp(1.0f, int(h.max_block_shift)) : 0.0f;
    bound[a] = 0.5f * h.quant_scale[a] + lattice + (std::nextafter(top, INFINITY) - top);
  }
}

double relative_error_bound(std::span<const uint8_t> blob, double diagonal) {
  float b[3];
  displacement_bound(blob, b);
  return std::sqrt(double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2]) / std::max(1e-30, diagonal);
}

double relative_error_floor(const Mesh& mesh, uint32_t triangle_format) {
  if (!moves_vertices(triangle_format)) return 0;
  const CodecOps codec = codec_ops(triangle_format);
  if (codec.grid == layout::kGridNone) return 0;
  BlobHeader h{};
  h.triangle_format = triangle_format;
  try {
    set_mesh_grid(mesh.bounds(), codec, "mesh", h);
  } catch (const InputError&) {
    return INFINITY;
  }
  const double half[3] = {0.5 * h.quant_scale[0], 0.5 * h.quant_scale[1], 0.5 * h.quant_scale[2]};
  return std::sqrt(half[0] * half[0] + half[1] * half[1] + half[2] * half[2]) /
         std::max(1e-30, mesh.bounds().diagonal());
}

bool moves_vertices(uint32_t triangle_format) {
  if (triangle_format == MC_TRI_INDEXED24) return false;
  CodecOps c = codec_ops(triangle_format);
  return c.grid != layout::kGridNone || c.moves_floats;
}

}  // namespace meshcast
