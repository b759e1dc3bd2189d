// Deterministic generated meshes for tests and benchmarks.
#pragma once
#include <array>
#include <random>
#include <cstdint>

#include "meshcast/mesh.h"

namespace meshcast {

// Closed, watertight UV sphere: `rings` >= 2 latitude bands, `segments` >= 3
// longitude bands. Each pole is one vertex and the seam is not duplicated, so
// every edge is shared by exactly two triangles. Outward-facing (CCW seen from
// outside). 2 + (rings-1)*segments vertices, 2*(rings-1)*segments triangles.
Mesh make_sphere(int rings, int segments, float radius, Vec3 centre);

// Grid in the z=0 plane with vertices at the integer points (x, y), 0<=x<=nx,
// 0<=y<=ny, two triangles per cell (2*nx*ny triangles), normals +z.
Mesh make_grid_plane(int nx, int ny);

// Heightfield terrain over an nx by ny grid of unit cells (2*nx*ny triangles),
// heights from a smooth noise fixed by `seed` (a sum of a few sines whose
// frequencies and phases come from the seed). Same arguments, same mesh.
Mesh make_terrain(int nx, int ny, uint32_t seed);

// A city-like scene of about `triangles` triangles over a square of 2 km: a
// terrain ground, buildings (closed boxes of many sizes, their walls split
// into cells of about 2.5 m, so a tower has thousands of triangles and a
// shed a few dozen) on a street grid, and among them detailed objects (UV
// spheres of 8 to 96 rings, 0.3 to 6 m across) scattered in the streets and
// on the roofs: large and tiny triangles side by side, as in a game level.
Mesh make_city(size_t triangles, uint32_t seed);
// A rotation drawn uniformly (a unit quaternion from four normal draws),
// row-major: what scenes' tests and benchmarks turn instances by.
std::array<double, 9> random_rotation(std::mt19937& rng);

}  // namespace meshcast
