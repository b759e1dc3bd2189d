// The worst-case displacement each triangle format states for a stored
// corner (0 for the float formats that keep the input's bits).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast {

// True for the triangle formats that store moved vertices (grids, cleared
// flag bits): they are judged against stored_mesh(), not the input mesh.
bool moves_vertices(uint32_t triangle_format);

// Worst-case distance, per axis, between an input vertex and the position the
// 21-bit BitPack grid of seed 000 §3.4 stores for it.
void quantization_bound(const float offset[3], const float scale[3], float bound[3]);

// The stated worst-case displacement, per axis, of any stored corner from
// its input vertex, for the blob's triangle format (0 for the float ones).
void displacement_bound(std::span<const uint8_t> blob, float bound[3]);
// The same as one length (the per-axis bounds' Euclidean norm) over the
// mesh diagonal `diagonal`: the error the error report states and the
// automatic layout's --max-error limits.
double relative_error_bound(std::span<const uint8_t> blob, double diagonal);

// The least relative_error_bound a blob of `triangle_format` built from
// `mesh` can state, known before it is built: half its grid's step over the
// diagonal (0 for a format that keeps floats; the stated bound adds a
// rounding of the largest coordinate and, for nested formats, the block
// lattices). A caller choosing a layout under an error limit skips a build
// this already puts over the limit. A mesh too thin for the format's grid
// (which its build refuses) gets infinity.
double relative_error_floor(const Mesh& mesh, uint32_t triangle_format);

}  // namespace meshcast
