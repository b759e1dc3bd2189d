// The double-precision oracle for point queries: the nearest point of a
// mesh to a point, every triangle tried, worked out apart from the
// library's way (cpu/point_triangle.h): the point projected onto the
// triangle's plane and kept where its barycentrics (from cross products)
// are all non-negative, otherwise the nearest of the three edges.
#pragma once
#include <cstdint>

#include "meshcast/mesh.h"
#include "meshcast/ray.h"

namespace meshcast {

struct OraclePoint {
  double distance = INFINITY;
  double point[3] = {0, 0, 0};
  uint32_t triangle = kNoHit;  // the lowest index at the least distance
};

// The distance from p to triangle (a, b, c), its nearest point in `near`.
double oracle_point_triangle(const double p[3], const Vec3& a, const Vec3& b, const Vec3& c, double near[3]);

// Every triangle of the mesh, in input order.
OraclePoint oracle_closest_point(const Mesh& mesh, const double p[3]);

// The generalized winding number of the mesh at p: each triangle's signed
// solid angle over 4 pi, by Girard's theorem (the spherical triangle's
// angle excess, its corners projected onto the unit sphere about p), apart
// from the library's Van Oosterom and Strackee formula; positive where the
// normal (b - a) x (c - a) points away from p.
double oracle_winding_number(const Mesh& mesh, const double p[3]);

}  // namespace meshcast
