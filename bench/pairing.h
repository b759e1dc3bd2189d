// `meshcast bench pairing` (seed 003's results table): per mesh the
// pairing pass's time, the paired share before (input order, window N = 2)
// and after, and what pairs as the builder's unit change in bytes per
// triangle, time per ray and (in a counting build, cpu/counters.h) box and
// triangle tests a ray.
#pragma once
#include <string>
#include <vector>

#include "bench/measure.h"
#include "meshcast/mesh.h"

namespace meshcast::bench {

struct PairingRow {
  std::string mesh, layout, decision;
  size_t triangles = 0;
  double pairing_ms = 0, before = 0, after = 0;
  Timing plain{}, paired{};
};

// The cases: each named mesh file that exists, the generated 2M terrain, and
// two copies of bunny00 made hard: its triangle order shuffled, and rotated
// 45 degrees with its own pairs baked in as consecutive triangles (the seed's
// third case: an input that looks paired, with pairs chosen before the
// rotation). `only`, when not empty: the cases whose names begin with one
// of its names alone (bunny00: its two copies too; the terrain is made only
// when named); UsageError when that leaves none.
std::vector<PairingRow> bench_pairing(const std::string& data_dir, size_t rays, uint32_t repeat,
                                      const std::vector<std::string>& only = {});

}  // namespace meshcast::bench
