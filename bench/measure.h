// One measured layout: build it, time a ray set over repeated passes, judge
// the answers against the oracle. Shared by the `meshcast bench` tables.
#pragma once
#include <string>
#include <vector>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "check/oracle.h"
#include "cpu/which_triangle_test.h"
#include "meshcast/blob.h"

namespace meshcast::bench {

struct Timing {
  double min_ms, median_ms;  // for the whole ray set
  double bytes;              // triangle blocks + shared vertices, per triangle
  uint64_t disagreements;    // with the oracle (over the stored mesh for formats that move vertices)
  double build_ms;
  double tree_bytes;         // nodes, per triangle
  double walked_bytes;       // everything a walk reads, per triangle
  double sah_cost;
  double hole_bytes = 0;     // StacklessLBVH: node slots no walk reaches, per triangle
  double total_bytes = 0;    // the whole blob, per triangle
  double error_bound = 0;    // relative_error_bound: the format's stated error, of the diagonal
  // Box and triangle tests a ray, from one more pass; -1 unless the build
  // counts them (MESHCAST_COUNT_TESTS, cpu/counters.h).
  double boxes_per_ray = -1, triangles_per_ray = -1;
};

// The tables' ray set: `count` long rays (seed 1) and the oracle's answers
// over the input mesh.
struct Setup {
  std::vector<Ray> rays;
  std::vector<OracleHit> oracle;
};
Setup setup(const Mesh& mesh, size_t count);

// Rays whose triangle or t differ from the oracle's (`oracle`: over the
// input mesh); formats that move vertices are judged on the mesh they store.
uint64_t oracle_mistakes(const Mesh& mesh, const std::vector<uint8_t>& blob, const std::vector<Ray>& rays,
                         const std::vector<Hit>& hits, const std::vector<OracleHit>& oracle);

// Traces `rays` `repeat` times through `view` (the hits of the last pass
// kept); returns each pass's milliseconds, sorted. `test`: the triangle test
// walked (cpu/trace_with_triangle_test.h), the library's own by default.
std::vector<double> time_passes(const BlobView& view, const std::vector<Ray>& rays, std::vector<Hit>& hits, uint32_t repeat,
                                TriangleTest test = TriangleTest::Watertight);

Timing measure(const Mesh& mesh, const std::string& name, const BuildOptions& options, const std::vector<Ray>& rays,
               const std::vector<OracleHit>& oracle, uint32_t repeat, TriangleTest test = TriangleTest::Watertight);

}  // namespace meshcast::bench
