// What the automatic layout (builder/auto_layout.h) measures of a mesh before it
// chooses: one pass over the triangles, plus seed 003's pairing pass.
#pragma once
#include <cstddef>
#include <string>

#include "meshcast/mesh.h"

namespace meshcast {

struct MeshStats {
  size_t triangles = 0;
  size_t vertices = 0;        // in the vertex array
  size_t used_vertices = 0;   // named by at least one triangle
  // Triangle corners a used vertex: about 6 on a closed welded mesh, 1 on a
  // triangle soup. Indexed formats store a vertex once for all its corners,
  // so they pay off only where this is well above 1.
  double corners_per_vertex = 0;
  double paired_ratio = 0;    // share of triangles seed 003's pass pairs across a shared edge
  double diagonal = 0;        // of the mesh box
  double origin_distance = 0; // of the box centre from the origin, in diagonals
  double flatness = 0;        // smallest box extent over the largest (a terrain: well under 1)
  // Spread of triangle sizes: the 90th over the 10th percentile of the
  // square roots of the triangles' areas (1: all alike). Degenerate
  // triangles (area 0) are left out of the percentiles and counted.
  double size_spread = 0;
  size_t degenerate = 0;
};

// `mesh` must have passed check_mesh.
MeshStats measure_mesh(const Mesh& mesh);

// The statistics on one line each, for `meshcast build --layout auto`.
std::string describe(const MeshStats& s);

}  // namespace meshcast
