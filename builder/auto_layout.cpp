#include "builder/auto_layout.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "builder/error_bounds.h"
#include "builder/ray_sets.h"
#include "layout/message_text.h"
#include "meshcast/blob.h"

namespace meshcast {

namespace {

constexpr uint32_t kLeaf = 8;  // seed 000 §4.2's middle size, fastest in bench leafsize

std::string format(const char* fmt, double a, double b) {
  char text[160];
  std::snprintf(text, sizeof text, fmt, a, b);
  return text;
}

// A limit as the caller gave it: nine digits tell any two apart, where
// "%.2f" made a limit of 0.001 "0.00" and 3.999 "4.00".
std::string limit_text(double limit) { return number_text(limit); }
std::string bytes_limit_text(double limit) { return limit_text(limit) + (limit == 1 ? " byte" : " bytes") + " a triangle"; }

// A measured figure over `limit`, with the digits ("%.2f", "%.2g" at the
// least) that show it over: 10.9141 against a limit of 10.914 is "10.9141",
// never "10.91". A figure within its limit, or no limit (0): the fewest.
std::string over_limit(double value, double limit, bool fixed) {
  char text[64];
  for (int digits = 2; digits < 17; ++digits) {
    std::snprintf(text, sizeof text, fixed ? "%.*f" : "%.*g", digits, value);
    if (!(limit > 0) || !(value > limit) || std::strtod(text, nullptr) > limit) break;
  }
  return text;
}

AutoCandidate candidate(const AutoLimits& l, const std::string& layout, uint32_t leaf, std::string why) {
  AutoCandidate c;
  c.options = parse_layout(layout);
  c.options.leaf_size = leaf;
  c.options.triangle_ids = l.triangle_ids;
  c.options.threads = l.build_threads;
  c.label = leaf == kLeaf ? layout : layout + " (leaf " + std::to_string(leaf) + ")";
  c.why = std::move(why);
  return c;
}

std::string tree_of(const std::string& layout) { return layout.substr(0, layout.find('/')); }

bool readable(const AutoLimits& l, const std::string& layout) {
  return l.readers.empty() || std::find(l.readers.begin(), l.readers.end(), parse_layout_name(layout)) != l.readers.end();
}

// The brute-force "tree" and the 128-lane GPU blocks: on the CPU never
// faster nor smaller than a tree over 4- or 8-wide blocks (the combos table
// leaves them out for that reason); with a GPU reader, brute force only on
// meshes small enough that testing every triangle is no worse than a walk.
bool worth_trying(const AutoLimits& l, const MeshStats& s, const std::string& layout) {
  const BuildOptions o = parse_layout(layout);
  if (!readable(l, layout)) return false;
  if (uint32_t(o.layout.tree) == MC_TREE_BRUTEFORCE) return !l.readers.empty() && s.triangles <= 4096;
  if (uint32_t(o.layout.triangles) == MC_TRI_FLOAT3SOA128 || uint32_t(o.layout.triangles) == MC_TRI_BITPACKSOA128) return !l.readers.empty();
  return true;
}

// Builds `c`, fills in its exact figures and checks them against the
// limits; returns the blob, or nothing when refused.
std::vector<uint8_t> judge(const Mesh& mesh, const MeshStats& s, const AutoLimits& l, AutoCandidate& c,
                           const std::string& name, BuildReport* report) {
  c.built = true;
  // A grid whose half step is already over the error limit is not built.
  const double floor = l.max_error > 0 ? relative_error_floor(mesh, uint32_t(c.options.layout.triangles)) : 0;
  if (std::isfinite(floor) && floor > l.max_error) {
    c.error = floor;
    c.refused = "stated error at least " + over_limit(floor, l.max_error, false) +
                " of the diagonal (half its grid's step), over the limit of " + limit_text(l.max_error) + "; not built";
    return {};
  }
  std::vector<uint8_t> blob;
  try {
    blob = build_blob(mesh, c.options, name, report);
  } catch (const InputError& e) {
    c.refused = e.what();
    return {};
  }
  c.bytes_per_triangle = double(blob.size()) / double(s.triangles);
  c.error = relative_error_bound(blob, s.diagonal);
  if (l.max_bytes_per_triangle > 0 && c.bytes_per_triangle > l.max_bytes_per_triangle)
    c.refused = over_limit(c.bytes_per_triangle, l.max_bytes_per_triangle, true) + " bytes a triangle, over the limit of " +
                limit_text(l.max_bytes_per_triangle);
  else if (l.max_error > 0 && c.error > l.max_error)
    c.refused = "stated error " + over_limit(c.error, l.max_error, false) + " of the diagonal, over the limit of " +
                limit_text(l.max_error);
  if (!c.refused.empty()) return {};
  return blob;
}

// Nanoseconds a ray, the fastest of `passes` passes.
double time_rays(const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, uint32_t passes) {
  BlobView view(blob, "trial");
  std::vector<Hit> hits(rays.size());
  double best = 1e300;
  for (uint32_t p = 0; p < std::max(1u, passes); ++p) {
    auto t0 = std::chrono::steady_clock::now();
    view.trace(rays, hits);
    best = std::min(best, std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
  }
  return best / double(rays.size());
}

// The narrowest index the indexed encodings can use: they store each used
// vertex once (layout/triangles/indexed.h), so the used vertices decide. Says why.
std::string index_width(const MeshStats& s, std::vector<std::string>& reasons) {
  const bool narrow = s.used_vertices <= 65536;
  reasons.push_back(format(narrow ? "%.0f used vertices (<= 65,536): 16-bit indices"
                                  : "%.0f used vertices (> 65,536): 32-bit indices",
                           double(s.used_vertices), 0));
  return narrow ? "16" : "32";
}

// Speed first. The order is the rule: the first candidate meeting the
// limits is taken when there is no trial.
std::vector<AutoCandidate> speed_list(const MeshStats& s, const AutoLimits& l, std::vector<std::string>& reasons) {
  std::vector<AutoCandidate> out;
  auto add = [&](const std::string& layout, const std::string& why, uint32_t leaf = kLeaf) {
    if (worth_trying(l, s, layout)) out.push_back(candidate(l, layout, leaf, why));
  };
  if (!l.readers.empty()) {
    reasons.push_back("CPU and GPU: only the layouts a Vulkan method reads, in the order of their CPU walkers' "
                      "speed (bench combos); the GPU's own order depends on the device (bench gpu)");
    // The readers in the order of their CPU walkers' speed in bench combos;
    // a reader the ranking does not know follows in the readers' order.
    static const Layout kCpuSpeedOrder[] = {
        {TreeFormat::OctTreeCompressed, TriangleFormat::ClusterBitPackSOA8},
        {TreeFormat::OctTreeCompressed, TriangleFormat::ClusterFloat3SOA8},
        {TreeFormat::QuadTreeHalfFloat, TriangleFormat::Indexed8BitPackSOA4},
        {TreeFormat::AABBTree, TriangleFormat::Float3},
        {TreeFormat::StacklessLBVH, TriangleFormat::Float3},
        {TreeFormat::AABBTree, TriangleFormat::UncompressedStrip},
        {TreeFormat::SKDTree, TriangleFormat::Float3},
        {TreeFormat::AABBList, TriangleFormat::Float3SOA128},
        {TreeFormat::AABBList, TriangleFormat::BitPackSOA128},
        {TreeFormat::BruteForce, TriangleFormat::Float3SOA128},
        {TreeFormat::BruteForce, TriangleFormat::BitPackSOA128}};
    std::vector<Layout> ordered;
    for (const Layout& r : kCpuSpeedOrder)
      if (std::find(l.readers.begin(), l.readers.end(), r) != l.readers.end()) ordered.push_back(r);
    for (const Layout& r : l.readers)
      if (std::find(ordered.begin(), ordered.end(), r) == ordered.end()) ordered.push_back(r);
    for (const Layout& r : ordered)
      add(layout_name(r), r == kCpuSpeedOrder[0] ? "read by a Vulkan method; the fastest CPU walker of bench peers"
                                                 : "read by a Vulkan method",
          default_leaf_size(r));
    return out;
  }
  const std::string w = index_width(s, reasons);
  // The 8-wide tree first, over clusters then 8-wide float blocks: the
  // fastest in bench peers on every mesh there (bench/RESULTS.md).
  reasons.push_back("the 8-wide compressed tree first (bench peers: fastest on every mesh), leaves of 16");
  add("OctTreeCompressed/ClusterBitPackSOA8", "8 children a node, clusters of shared grid vertices: fast and small", 16);
  // Exact next: the same clusters over the float vertices, about as fast
  // as the grid clusters (bench peers: 0.95-1.18x their time) and faster
  // than float blocks, at 19 bytes a triangle against 48-51.
  add("OctTreeCompressed/ClusterFloat3SOA8", "8 children a node, clusters of shared float vertices: exact, fast and small", 16);
  add("OctTreeCompressed/Float3SOA8", "8 children a node over exact 8-wide float blocks", 16);
  // Half-float nodes are half the bytes of a float node: once the nodes of
  // a mesh of millions of triangles outgrow the caches they win (terrain_2M:
  // QuadTreeHalfFloat first in bench combos); below that, float nodes (bunny00
  // and the dragon: QuadTree first).
  const bool large = s.triangles >= (1u << 20);
  const std::vector<std::string> trees =
      large ? std::vector<std::string>{"QuadTreeHalfFloat", "QuadTree"} : std::vector<std::string>{"QuadTree", "QuadTreeHalfFloat"};
  reasons.push_back(std::string(large ? "2^20 triangles or more: half-float quad tree nodes first (their nodes stay in cache)"
                                      : "under 2^20 triangles: float quad tree nodes first, half-float next") +
                    "; leaves of " + std::to_string(kLeaf));
  std::vector<std::pair<std::string, std::string>> encodings = {
      {"Float3SOA8", "8 triangles in one 8-wide test, exact"}, {"Float3SOA4", "4-wide, exact"}};
  if (s.paired_ratio >= 0.75) {
    encodings.push_back({"Float3PairSOA4", "most triangles pair: the shared edge stored once, one pair test"});
    reasons.push_back(format("%.0f%% of triangles pair (>= 75%%): the pair encoding is a candidate", 100 * s.paired_ratio, 0));
  }
  encodings.push_back({"BitPackSOA4", "quantized to 21 bits: 2/3 of the bytes at about the same speed"});
  if (s.corners_per_vertex >= 3) {
    encodings.push_back({"Indexed" + w + "SOA4", "welded mesh: vertices stored once, " + w + "-bit indices"});
    reasons.push_back(format("%.1f corners a vertex (>= 3): indexed encodings are candidates", s.corners_per_vertex, 0));
  }
  encodings.push_back({"Float3", "exact, one triangle at a time"});
  for (const auto& [enc, why] : encodings)
    for (const std::string& tree : trees) add(tree + "/" + enc, why);
  // Under a tight byte limit: the small layouts that walk fastest.
  for (const std::string& enc : {std::string("Indexed8BitPackSOA4"), "Indexed" + w + "BitPackSOA4", std::string("CompressedStrip")})
    add("QuadTreeHalfFloat/" + enc, "small and fast: half-float nodes over a compact encoding");
  add("QuadTreeHalfFloat/Indexed8BitPackSOA4", "small and fast; leaves of 16: fewer nodes", 16);
  add("AABBTreeCompressed/Indexed8BitPackSOA4", "the smallest tree in bench combos, when nothing faster fits");
  add("AABBTreeCompressed/Indexed8BitPackSOA4", "the smallest tree; leaves of 16: fewer nodes", 16);
  return out;
}

// Memory first: every candidate is built and the fewest bytes win.
std::vector<AutoCandidate> memory_list(const MeshStats& s, const AutoLimits& l, std::vector<std::string>& reasons) {
  std::vector<AutoCandidate> out;
  auto add = [&](const std::string& layout, const std::string& why) {
    if (worth_trying(l, s, layout)) out.push_back(candidate(l, layout, kLeaf, why));
  };
  if (!l.readers.empty()) {
    reasons.push_back("CPU and GPU: every layout a Vulkan method reads (brute force only up to 4096 triangles)");
    for (const Layout& r : l.readers) add(layout_name(r), "read by a Vulkan method");
    return out;
  }
  if (s.corners_per_vertex >= 2) {
    reasons.push_back(format("%.1f corners a vertex (>= 2): indexed encodings store each vertex once", s.corners_per_vertex, 0));
    if (worth_trying(l, s, "OctTreeCompressed/ClusterBitPackSOA8"))
      out.push_back(candidate(l, "OctTreeCompressed/ClusterBitPackSOA8", 16, "clusters of shared grid vertices under 8-wide nodes"));
    if (worth_trying(l, s, "OctTreeCompressed/ClusterFloat3SOA8"))
      out.push_back(candidate(l, "OctTreeCompressed/ClusterFloat3SOA8", 16, "clusters of shared float vertices under 8-wide nodes: exact"));
    const std::string w = index_width(s, reasons);
    add("AABBTreeCompressed/Indexed8BitPackSOA4", "12-byte nodes, 8-bit indices into a block's quantized vertices");
    add("SKDTree/Indexed8BitPackSOA4", "the smallest nodes (one plane pair)");
    add("AABBTreeCompressed/Indexed" + w + "BitPackSOA4", "quantized shared vertices, " + w + "-bit indices");
    add("AABBTreeCompressed/Indexed" + w, "exact shared vertices, " + w + "-bit indices");
    add("QuadTreeHalfFloat/Indexed8BitPackSOA4", "nearly as small, twice as fast");
    add("AABBList/Indexed8BitPackSOA4", "one box a 256-triangle batch: the fewest node bytes, a slow walk");
    if (s.triangles <= MC_ZBT_MAX_TRIANGLES && s.vertices <= MC_ZBT_MAX_VERTICES) {
      add("ZeroByteTree/Indexed24", "no node bytes at all: the index buffer is the tree (seed 004)");
      add("ZeroByteHybrid/Indexed24", "zero-byte leaves under a few nodes");
    }
  } else {
    reasons.push_back(format("%.1f corners a vertex (< 2, a triangle soup): indexing saves nothing", s.corners_per_vertex, 0));
  }
  add("AABBTreeCompressed/CompressedStrip", "strips: each triangle after the first adds one vertex");
  add("AABBTreeCompressed/BitPack", "quantized corners, no indexing");
  return out;
}

}  // namespace

const char* goal_name(AutoGoal goal) { return goal == AutoGoal::Speed ? "speed" : "memory"; }

AutoGoal parse_goal(const std::string& name) {
  return parse_named<AutoGoal>(name, {AutoGoal::Speed, AutoGoal::Memory}, goal_name, "goal");
}

AutoChoice choose_layout(const Mesh& mesh, const AutoLimits& limits, const std::string& name) {
  check_mesh(mesh, name);
  AutoChoice out;
  out.stats = measure_mesh(mesh);
  const MeshStats& s = out.stats;
  const bool speed = limits.goal == AutoGoal::Speed;
  out.candidates = speed ? speed_list(s, limits, out.reasons) : memory_list(s, limits, out.reasons);
  std::vector<Ray> rays;
  if (speed && limits.trial_rays > 0) {
    rays = make_rays(mesh, RayKind::Long, limits.trial_rays, 2);  // not the benches' seed 1
    out.reasons.push_back("timed trial: " + std::to_string(limits.trial_rays) + " long rays, the fastest of " +
                          std::to_string(limits.trial_passes) + " passes, on one thread");
  }
  // Judge the list; `pick` is the index taken so far.
  constexpr size_t kNone = ~size_t(0);
  size_t pick = kNone;
  double pick_ns = 1e300;
  auto run = [&](size_t from) {
    for (size_t i = from; i < out.candidates.size(); ++i) {
      AutoCandidate& c = out.candidates[i];
      BuildReport report;
      std::vector<uint8_t> blob = judge(mesh, s, limits, c, name, &report);
      if (blob.empty()) continue;
      bool better = false;
      if (!speed) {
        better = pick == kNone || c.bytes_per_triangle < out.candidates[pick].bytes_per_triangle;
      } else if (!rays.empty()) {
        c.trial_ns = time_rays(blob, rays, limits.trial_passes);
        better = c.trial_ns < pick_ns;
        if (better) pick_ns = c.trial_ns;
      } else {
        better = true;  // rule order: the first that meets the limits
      }
      if (better) {
        pick = i, out.blob = std::move(blob), out.report = report;
        if (speed && rays.empty()) return;
      }
    }
  };
  run(0);
  // Memory first: the two smallest tree layouts again with leaves of 16
  // (half the leaves, so about half the node bytes, and blocks filled better).
  if (!speed && pick != kNone) {
    std::vector<size_t> again;
    for (size_t i = 0; i < out.candidates.size(); ++i) {
      const AutoCandidate& c = out.candidates[i];
      const uint32_t tree = uint32_t(c.options.layout.tree);  // the formats whose leaves are not the builder's
      if (c.built && c.refused.empty() && tree != MC_TREE_ZEROBYTE && tree != MC_TREE_ZEROBYTEHYBRID &&
          tree != MC_TREE_AABBLIST && tree != MC_TREE_BRUTEFORCE)
        again.push_back(i);
    }
    std::sort(again.begin(), again.end(), [&](size_t a, size_t b) {
      return out.candidates[a].bytes_per_triangle < out.candidates[b].bytes_per_triangle;
    });
    if (again.size() > 2) again.erase(again.begin() + 2, again.end());
    const size_t from = out.candidates.size();
    for (size_t a : again) {
      const AutoCandidate& small = out.candidates[a];
      out.candidates.push_back(candidate(limits, layout_name(uint32_t(small.options.layout.tree), uint32_t(small.options.layout.triangles)), 16,
                                         small.why + "; leaves of 16: fewer nodes, fuller blocks"));
    }
    if (!again.empty()) out.reasons.push_back("memory first: the smallest tree layouts once more with leaves of 16");
    run(from);
  }
  // Nothing on the list meets the limits: every other layout, in the order
  // of their trees' speed.
  if (pick == kNone) {
    out.reasons.push_back("no shortlisted layout meets the limits: every other layout tried");
    const std::vector<std::string> order = {"QuadTree",  "QuadTreeHalfFloat",  "AABBTree", "AABBTreeSplitAxis",
                                            "AABBTreePNS", "StacklessLBVH", "AABBTreeCompressed", "ZeroByteHybrid",
                                            "SKDTree",   "AABBList", "ZeroByteTree", "BruteForce"};
    std::vector<std::string> rest;
    for (const std::string& layout : layout_names())
      if (worth_trying(limits, s, layout) &&
          std::none_of(out.candidates.begin(), out.candidates.end(), [&](const AutoCandidate& c) { return c.label == layout; }))
        rest.push_back(layout);
    auto rank = [&](const std::string& layout) { return std::find(order.begin(), order.end(), tree_of(layout)) - order.begin(); };
    std::stable_sort(rest.begin(), rest.end(), [&](const std::string& a, const std::string& b) { return rank(a) < rank(b); });
    const size_t from = out.candidates.size();
    for (const std::string& layout : rest) out.candidates.push_back(candidate(limits, layout, kLeaf, "no shortlisted layout fits"));
    run(from);
  }
  if (pick == kNone) {
    // A candidate whose grid was over the error limit before its build
    // (bytes 0, error its floor) tells the least error it could state.
    double bytes = 1e300, error = 1e300;
    bool error_is_floor = false;
    for (const AutoCandidate& c : out.candidates) {
      if (!c.built || (c.bytes_per_triangle == 0 && !(c.error > 0))) continue;
      if (c.bytes_per_triangle > 0) bytes = std::min(bytes, c.bytes_per_triangle);
      if (c.error < error) error = c.error, error_is_floor = c.bytes_per_triangle == 0;
    }
    std::string set;
    if (limits.max_bytes_per_triangle > 0) set += "at most " + bytes_limit_text(limits.max_bytes_per_triangle);
    if (limits.max_error > 0) set += (set.empty() ? "" : ", ") + ("error at most " + limit_text(limits.max_error) + " of the diagonal");
    if (!limits.readers.empty()) set += std::string(set.empty() ? "" : ", ") + "read by the GPU too";
    // What the nearest came to each limit, in whole words.
    const std::string exact = error > 0 ? std::string("states an error of ") + (error_is_floor ? "at least " : "") +
                                              over_limit(error, limits.max_error, false) + " of the diagonal"
                                        : std::string("is exact (an error of 0)");
    throw InputError(name + ": no layout meets the limits (" + set + "); " +
                     (bytes < 1e300   ? "the smallest built takes " + over_limit(bytes, limits.max_bytes_per_triangle, true) +
                                          " bytes a triangle and the most exact " + exact
                      : error < 1e300 ? "none was built (each grid's step is over the error limit): the most exact " + exact
                                      : std::string("no layout could be built")));
  }
  out.chosen = pick;
  return out;
}

AutoLimits parse_auto_setting(const std::string& text) {
  AutoLimits l;
  size_t at = 0;
  for (bool first = true; at <= text.size(); first = false) {
    const size_t comma = std::min(text.find(',', at), text.size());
    const std::string part = text.substr(at, comma - at);
    at = comma + 1;
    if (first) {
      l.goal = parse_goal(part);
      continue;
    }
    const size_t eq = part.find('=');
    const std::string key = part.substr(0, eq), value = eq == std::string::npos ? "" : part.substr(eq + 1);
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !(v >= 0))
      throw InputError("auto setting '" + text + "': '" + part + "' is not KEY=NUMBER (trial, bytes, error)");
    if (key == "trial")
      l.trial_rays = uint32_t(std::min(v, 1e6));
    else if (key == "bytes")
      l.max_bytes_per_triangle = v;
    else if (key == "error")
      l.max_error = v;
    else
      throw InputError("auto setting '" + text + "': unknown '" + key + "' (trial, bytes, error)");
  }
  return l;
}

std::string describe(const AutoLimits& limits) {
  std::string text = std::string(goal_name(limits.goal)) + " first, " + (limits.readers.empty() ? "CPU only" : "CPU and GPU");
  text += limits.max_bytes_per_triangle > 0 ? ", at most " + bytes_limit_text(limits.max_bytes_per_triangle) : "";
  text += limits.max_error > 0 ? ", error at most " + limit_text(limits.max_error) + " of the diagonal" : "";
  text += limits.trial_rays > 0 ? format(", a %.0f-ray trial", limits.trial_rays, 0) : "";
  return text;
}

std::string describe(const AutoLimits& limits, const AutoChoice& choice) {
  std::string text = "auto layout: " + describe(limits);
  text += "\n" + describe(choice.stats);
  for (const std::string& r : choice.reasons) text += "  rule             " + r + "\n";
  char line[512];
  std::snprintf(line, sizeof line, "  %-48s %8s %8s %8s  %s\n", "candidate", "B/tri", "error", "trial ns", "why / refused");
  text += line;
  std::string unbuilt;
  for (size_t i = 0; i < choice.candidates.size(); ++i) {
    const AutoCandidate& c = choice.candidates[i];
    if (!c.built) {
      unbuilt += (unbuilt.empty() ? "" : ", ") + c.label;
      continue;
    }
    if (c.bytes_per_triangle == 0) {
      std::snprintf(line, sizeof line, "  %-48s %8s %8s %8s  refused: %s\n", c.label.c_str(), "-", "-", "-", c.refused.c_str());
    } else {
      char ns[32] = "-";
      if (c.trial_ns >= 0) std::snprintf(ns, sizeof ns, "%.0f", c.trial_ns);
      std::snprintf(line, sizeof line, "%s %-48s %8.2f %8.2g %8s  %s\n", i == choice.chosen ? "->" : "  ", c.label.c_str(),
                    c.bytes_per_triangle, c.error, ns, (c.refused.empty() ? c.why : "refused: " + c.refused).c_str());
    }
    text += line;
  }
  if (!unbuilt.empty()) text += "  next in rule order, not built (one before them met the limits): " + unbuilt + "\n";
  const AutoCandidate& c = choice.choice();
  text += "chose " + c.label + ": " + c.why +
          (limits.goal == AutoGoal::Memory ? " (the fewest bytes that meet the limits)"
           : c.trial_ns >= 0              ? " (the fastest in the trial that meets the limits)"
                                           : " (the first in rule order that meets the limits)") +
          "\n";
  return text;
}

}  // namespace meshcast
