// The automatic layout (`meshcast build MESH --layout auto`): which tree
// format, triangle encoding, leaf size and index width this mesh is best
// built with under the caller's limits.
//
// Three steps, each printed by describe():
//   1. measure the mesh (builder/mesh_stats.h);
//   2. shortlist candidates by rules drawn from the measured tables of
//      bench/RESULTS.md and the mesh's statistics (index width from the
//      vertex count, indexed encodings only where vertices are shared, the
//      pair encoding only where most triangles pair, half-float nodes first
//      on large meshes, ...);
//   3. build the shortlisted candidates and judge them on exact figures:
//      the blob's bytes and its stated error bound (relative_error_bound)
//      against the limits; speed first takes the first candidate in rule
//      order that meets them, or with a trial the fastest on a sample of
//      rays; memory first takes the fewest bytes.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "builder/mesh_stats.h"

namespace meshcast {

enum class AutoGoal { Speed, Memory };
const char* goal_name(AutoGoal goal);
AutoGoal parse_goal(const std::string& name);  // "speed" or "memory"; InputError otherwise

struct AutoLimits {
  AutoGoal goal = AutoGoal::Speed;
  double max_bytes_per_triangle = 0;  // the whole blob over the triangle count; 0: no limit
  double max_error = 0;               // relative_error_bound, of the diagonal; 0: no limit
  // Layouts another backend must read as well (the Vulkan methods':
  // gpu::method_layouts()); empty: the CPU walkers only, which read all.
  std::vector<Layout> readers;
  // Speed first: time the buildable candidates on this many rays (long
  // rays, their own seed) and take the fastest; 0: no trial, rule order.
  uint32_t trial_rays = 0;
  uint32_t trial_passes = 3;  // the fastest pass of these counts
  bool triangle_ids = true;   // BuildOptions::triangle_ids of every candidate
  uint32_t build_threads = 0; // BuildOptions::threads of every candidate
};

// A setting as text, for benches and tests: "speed" or "memory", then any
// of ",trial=RAYS", ",bytes=B" (bytes a triangle), ",error=E" (of the
// diagonal). InputError naming the part it cannot read.
AutoLimits parse_auto_setting(const std::string& text);
// "speed first, CPU only, at most 20 bytes a triangle, ...": each limit as given.
std::string describe(const AutoLimits& limits);

struct AutoCandidate {
  std::string label;  // the layout, with the leaf size where not 8
  BuildOptions options;
  std::string why;    // the rule that shortlisted it
  bool built = false;
  double bytes_per_triangle = 0;  // whole blob
  double error = 0;               // relative_error_bound (not built: relative_error_floor)
  double trial_ns = -1;           // per ray; -1: not timed
  std::string refused;            // why it cannot be used: the builder's refusal or the limit it exceeds
};

struct AutoChoice {
  MeshStats stats;
  std::vector<AutoCandidate> candidates;
  size_t chosen = 0;
  std::vector<std::string> reasons;  // the rules that applied, in order
  std::vector<uint8_t> blob;         // the chosen candidate's blob
  BuildReport report;
  const AutoCandidate& choice() const { return candidates[chosen]; }
};

// Throws InputError naming `name` when no layout meets the limits (saying
// how close the nearest came).
AutoChoice choose_layout(const Mesh& mesh, const AutoLimits& limits, const std::string& name);

// The limits, statistics, rules, every candidate's figures and the choice.
std::string describe(const AutoLimits& limits, const AutoChoice& choice);

}  // namespace meshcast
