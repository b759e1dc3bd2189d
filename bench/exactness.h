// `meshcast bench exactness`: how far the reported t, u, v and hit points
// lie from exact arithmetic (check/exact_t.h, GMP) on each mesh, for the
// recommended layout and its exact twin, on each ray kind, for the closest
// hit, any hit and every hit, plus grazing rays (along a triangle's edge,
// 1e-4 of its normal off its plane, through its centroid). t is measured
// against the stored triangle's plane, in float ulps of the exact t; u and
// v as absolute errors; the hit point against o + t d at the exact t, in
// ulps of the largest coordinate of o, t d and the point.
#pragma once
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast::bench {

struct ExactnessRow {
  std::string mesh, layout, rays;  // rays: a ray kind, or "grazing"
  uint64_t hits = 0;               // every query's hits together
  uint64_t rounded = 0;            // hits whose t is correctly rounded (within half an ulp)
  double t_ulps = 0;               // the largest t error, ulps
  double uv = 0;                   // the largest u or v error
  double point_ulps = 0;           // the largest hit-point error, ulps of the largest of o, t d and the point
};

std::vector<ExactnessRow> bench_exactness(const Mesh& mesh, const std::string& name, size_t rays);

}  // namespace meshcast::bench
