// `meshcast bench robustness`: what the watertight test costs. The
// same layouts walked with the watertight test (the default) and with the
// plain Möller–Trumbore test, alternately in one run: time a ray on long
// rays through the mesh, their disagreements with the oracle, and leaks:
// rays from inside a closed sphere aimed exactly at its vertices and edge
// midpoints, each of which must hit.
#pragma once
#include <string>
#include <vector>

#include "bench/measure.h"
#include "meshcast/mesh.h"

namespace meshcast::bench {

struct RobustnessRow {
  std::string layout;
  Timing watertight{}, plain{};
  uint64_t probes = 0, leaks_watertight = 0, leaks_plain = 0;
};

std::vector<RobustnessRow> bench_robustness(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);

}  // namespace meshcast::bench
