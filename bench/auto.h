// `meshcast bench auto`: the check of the automatic layout. On each
// mesh every layout of the combos table is measured, then the layout `auto`
// chooses under each setting, in the same run on the same rays; the choice
// is set against the best combos layout that meets the setting's limits
// (fastest for speed first, fewest bytes for memory first).
#pragma once
#include <string>
#include <vector>

#include "bench/trees.h"
#include "builder/auto_layout.h"

namespace meshcast::bench {

struct AutoSetting {
  std::string label;
  AutoLimits limits;
};
// Speed first (rules only, and with a 1024-ray trial), memory first, and
// memory first under a 2e-6 error bound.
std::vector<AutoSetting> auto_settings();

struct AutoRow {
  std::string setting, choice;
  Timing timing;          // the choice, measured like the combos rows
  double choose_ms = 0;   // auto's whole decision: statistics, builds, trial
  std::string best;       // the best combos layout meeting the limits
  double best_value = 0;  // its ns a ray (speed) or bytes a triangle (memory); 0 when none is eligible
  double value = 0;       // the choice's, in the same unit
  size_t eligible = 0;    // combos layouts meeting the limits
};

struct AutoTable {
  std::vector<TreeRow> combos;
  std::vector<AutoRow> rows;
};
AutoTable bench_auto(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);

}  // namespace meshcast::bench
