#include "tools/common.h"

#include "tools/commands.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "builder/auto_layout.h"
#include "layout/message_text.h"
#include "check/ray_files.h"
#include "gpu/method.h"
#include "meshcast/blob.h"
#include "meshcast/read.h"
#include "tools/progress.h"
#include "layout/blob_format.h"

namespace meshcast::tools {

Loaded load_mesh_or_blob(const std::string& path, const MeshBuilder& build) {
  Loaded out;
  auto t0 = std::chrono::steady_clock::now();
  out.mesh = generated_mesh(path);
  if (!out.mesh) {
    std::vector<uint8_t> head;
    try {
      head = read_file(path);
    } catch (const InputError& e) {
      refuse_missing_mesh(path, e);
    }
    uint32_t magic = 0;
    if (head.size() >= 4) std::memcpy(&magic, head.data(), 4);
    if (magic == MC_BLOB_MAGIC) {
      std::string why = layout::validate(head);
      if (!why.empty()) throw InputError(path + ": " + why);
      out.blob = std::move(head);
      out.load_ms = ms_since(t0);
      return out;
    }
    out.mesh = read_mesh(path);
  }
  out.load_ms = ms_since(t0);
  auto t1 = std::chrono::steady_clock::now();
  {
    const size_t triangles = out.mesh->triangles.size();
    Progress progress("building " + path + " (" + std::to_string(triangles) + " triangles)", triangles > kProgressTriangles);
    out.blob = build(*out.mesh, &out.report);
  }
  out.build_ms = ms_since(t1);
  return out;
}

BuildOptions layout_options(const std::string& layout, uint32_t leaf, const std::string& splitter) {
  BuildOptions o = parse_layout(layout);
  if (leaf) o.leaf_size = leaf;  // 0: the layout's own
  if (!splitter.empty()) o.splitter = parse_splitter(splitter);  // else the layout's (Morton for StacklessLBVH)
  return o;
}

CLI::Validator integer_in(uint64_t lo, uint64_t hi) {
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const bool digits = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
        if (!digits) return "\"" + shown_text(text) + "\" is not an integer (" + range + ")";
        // CLI11 converts the text with base 0, where a leading zero means
        // octal: 010 would pass here as ten and be taken as eight.
        if (text.size() > 1 && text[0] == '0')
          return shown_text(text) + " has a leading zero (written without it, in decimal; " + range + ")";
        // Past 64 bits is past any range here.
        uint64_t value = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (error != std::errc() || value < lo || value > hi) return shown_text(text) + " is not in " + range;
        return {};
      },
      "INT in " + range);
}

CLI::Validator number_in(double lo, double hi, bool single) {
  // A float option's range is a float's too: past it the value would be
  // read as inf, and a nonzero one nearer 0 than a float holds as 0.
  if (single) hi = std::min(hi, double(std::numeric_limits<float>::max()));
  const std::string span = number_text(lo) + ".." + number_text(hi);
  const std::string range = std::isinf(hi) ? "a finite number at least " + number_text(lo) : "in " + span;
  const double least = single ? double(std::numeric_limits<float>::denorm_min()) : std::numeric_limits<double>::denorm_min();
  return CLI::Validator(
      [lo, hi, single, span, range, least](std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || std::isnan(value))
          return "\"" + shown_text(text) + "\" is not a number (" + (std::isinf(hi) ? range : span) + ")";
        // 1e400 is read as inf: past every range here.
        if (!std::isfinite(value) || value < lo || value > hi) return shown_text(text) + " is not " + range;
        if ((value == 0 && errno == ERANGE) || (single && value != 0 && float(value) == 0))
          return shown_text(text) + " is nearer 0 than the least " + (single ? "float" : "double") + " above 0 (" +
                 number_text(least) + ")";
        return {};
      },
      std::isinf(hi) ? "NUMBER >= " + number_text(lo) : "NUMBER in " + span);
}

void add_layout_options(CLI::App* cmd, LayoutArgs& a) {
  const size_t before = cmd->get_options().size();
  cmd->add_option("--layout", a.layout, "TREE/TRIANGLES when building from a mesh, or auto (chosen for the mesh)");
  cmd->add_option("--goal", a.goal, "auto: speed (fastest) or memory (fewest bytes)");
  cmd->add_option("--max-bytes", a.max_bytes, "auto: at most this many blob bytes a triangle (0: no limit)")
      ->check(number_in(0));
  cmd->add_option("--max-error", a.max_error,
                  "auto: stated error bound at most this fraction of the mesh diagonal (0: no limit; bench error)")
      ->check(number_in(0));
  cmd->add_flag("--gpu", a.gpu, "auto: only layouts a Vulkan method reads as well (CPU and GPU)");
  cmd->add_option("--trial", a.trial, "auto, speed first: time the candidates on this many rays (0: rules only)")
      ->check(integer_in(0, 1u << 20));
  cmd->add_option("--leaf", a.leaf, "largest triangle count of a leaf (default: 16 for OctTreeCompressed, 8 for the others)")
      ->check(integer_in(1, 31));
  cmd->add_option("--splitter", a.splitter, "Binning, LongestAxis, Mean, Morton or FixedLeafSize (default Binning: SAH)");
  cmd->add_option("--order", a.order,
                  "node order: DepthFirst, DepthFirstTrianglesLast, BreadthFirst or "
                  "BreadthFirstTrianglesLast; the quad trees take all four");
  cmd->add_option("--lbvh-depth", a.lbvh_depth, "StacklessLBVH depth limit D (0: bit_width(triangles) + 1)")
      ->check(integer_in(0, uint32_t(MC_LBVH_MAX_DEPTH + 1)));
  cmd->add_flag("--lbvh-left-first", a.lbvh_left_first, "StacklessLBVH: walk left child first, as the stackless LBVH paper does");
  cmd->add_option("--grouping", a.grouping, "AABBList batches: ClosestCentroid (greedy, the default) or Morton");
  cmd->add_flag("--no-triangle-ids", a.no_triangle_ids,
                "leave the remap out: hits name triangles by the blob's slot numbers, not the input's");
  cmd->add_flag("--pairing", a.pairing, "pair triangles across shared edges first; leaves hold whole pairs");
  cmd->add_flag("--no-shuffle", a.zbt_no_shuffle, "zero-byte trees: any bound triangles, not 6 each naming its extreme's corner");
  cmd->add_flag("--no-box-cache", a.zbt_no_cache, "zero-byte trees: recompute every box (no per-thread box cache)");
  cmd->add_option("--hybrid-leaf", a.hybrid_leaf, "ZeroByteHybrid: largest leaf, each one zero-byte tree")
      ->check(integer_in(8, uint32_t(MC_ZBT_MAX_TRIANGLES)));
  cmd->add_option("--build-threads", a.build_threads,
                  "threads the build may use (0: every core); the blob is the same bytes on any number")
      ->check(integer_in(0, 1024));
  const std::vector<CLI::Option*> all = cmd->get_options();
  a.options.assign(all.begin() + std::ptrdiff_t(before), all.end());
}

// load_input's work once the limits are checked.
static Loaded load_as_asked(const std::string& path, const LayoutArgs& a, std::FILE* report) {
  const LayoutArgs defaults;
  const bool automatic = a.layout == "auto";
  // Options that would be silently dropped are refused instead.
  if (automatic && (a.leaf != defaults.leaf || !a.splitter.empty() || !a.order.empty() || !a.grouping.empty() ||
                    a.pairing || a.lbvh_depth != 0 || a.lbvh_left_first || a.zbt_no_shuffle || a.zbt_no_cache ||
                    a.hybrid_leaf != defaults.hybrid_leaf))
    throw InputError("--layout auto chooses the leaf size and builds each layout with its own options; leave out "
                     "--leaf, --splitter, --order, --grouping, --pairing, --lbvh-*, --no-shuffle, --no-box-cache and "
                     "--hybrid-leaf, or name a layout");
  if (!automatic && (a.goal != defaults.goal || a.max_bytes != 0 || a.max_error != 0 || a.gpu || a.trial != 0))
    throw InputError("--goal, --max-bytes, --max-error, --gpu and --trial are limits for --layout auto");
  if (!automatic) {
    const BuildOptions options = build_options(a);
    return load_mesh_or_blob(path, [&](const Mesh& mesh, BuildReport* r) { return build_blob(mesh, options, path, r); });
  }
  AutoLimits limits;
  limits.goal = parse_goal(a.goal);
  limits.max_bytes_per_triangle = a.max_bytes, limits.max_error = a.max_error;
  if (a.gpu)
    for (const gpu::MethodLayout& m : gpu::method_layouts())
      if (a.gpu_method.empty() || a.gpu_method == m.method) limits.readers.push_back(m.layout);
  limits.trial_rays = a.trial;
  limits.triangle_ids = !a.no_triangle_ids;
  limits.build_threads = a.build_threads;
  return load_mesh_or_blob(path, [&](const Mesh& mesh, BuildReport* r) {
    AutoChoice choice = choose_layout(mesh, limits, path);
    std::fprintf(report, "%s", describe(limits, choice).c_str());
    *r = choice.report;
    return std::move(choice.blob);
  });
}

Loaded load_input(const std::string& path, const LayoutArgs& a, std::FILE* report) {
  Loaded in = load_as_asked(path, a, report);
  // A blob's layout was fixed when it was built.
  if (!in.mesh)
    for (const CLI::Option* option : a.options)
      if (option->count() > 0)
        throw InputError(path + ": is a blob, whose layout was fixed when it was built; " + option->get_name() +
                         " applies only to a mesh input");
  return in;
}

std::string gpu_methods_text() {
  std::string text;
  for (const std::string& m : gpu::method_names()) text += (text.empty() ? "" : ", ") + m + " (" + gpu::layouts_read_by(m) + ")";
  return text;
}

Loaded load_input_for(const std::string& path, LayoutArgs& layout, const std::string& backend, std::string& method,
                      std::FILE* report) {
  if (backend != "vulkan") return load_input(path, layout, report);
  const std::vector<std::string> names = gpu::method_names();
  if (!method.empty() && std::find(names.begin(), names.end(), method) == names.end())
    throw InputError("--method " + shown_text(method) + ": no such GPU method; the methods: " + gpu_methods_text());
  // --layout auto: a layout a GPU method reads (the named one's, when named).
  if (layout.layout == "auto") layout.gpu = true, layout.gpu_method = method;
  Loaded in = load_input(path, layout, report);
  if (method.empty()) {
    method = gpu::method_reading(in.blob);
    const layout::BlobHeader& h = layout::header_of(in.blob.data());
    if (method.empty())
      throw InputError(path + ": no GPU method reads " + layout_name(h.tree_format, h.triangle_format) +
                       " blobs (--layout auto chooses one that a method reads); the methods: " + gpu_methods_text());
  }
  return in;
}

BuildOptions build_options(const LayoutArgs& a) {
  BuildOptions o = layout_options(a.layout, a.leaf, a.splitter);
  if (!a.order.empty()) o.node_order = parse_node_order(a.order);
  o.lbvh_depth = a.lbvh_depth;
  o.lbvh_near_first = !a.lbvh_left_first;
  if (!a.grouping.empty()) o.grouping = parse_grouping(a.grouping);
  o.pairing = a.pairing;
  o.triangle_ids = !a.no_triangle_ids;
  o.zbt_shuffle = !a.zbt_no_shuffle, o.zbt_box_cache = !a.zbt_no_cache, o.hybrid_leaf = a.hybrid_leaf;
  o.threads = a.build_threads;
  return o;
}

void print_json(const nlohmann::ordered_json& object) {
  std::printf("%s\n", object.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace).c_str());
}



SectionBytes section_bytes(const std::vector<uint8_t>& blob) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  SectionBytes s;
  s.header = sizeof(layout::BlobHeader);
  s.nodes = h.node_bytes;
  s.triangles = h.tree_size - h.node_bytes;
  s.vertices = h.vertex_size;
  s.remap = h.remap_size;
  s.total = blob.size();
  return s;
}

std::string processor_name() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  std::string flags;
  std::string name = "unknown processor";
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0 && name == "unknown processor") name = line.substr(line.find(':') + 2);
    if (line.rfind("flags", 0) == 0 && flags.empty()) flags = line;
  }
  const bool avx512 = flags.find(" avx512f") != std::string::npos, avx2 = flags.find(" avx2") != std::string::npos;
  return name + (avx512 ? " (AVX-512)" : avx2 ? " (AVX2, no AVX-512)" : " (no AVX2)");
}

std::string bench_machine() {
  return processor_name() + ", meshcast walkers: " + std::string(walker_isa_name(walker_isa()));
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');)
    if (!part.empty()) out.push_back(part);
  return out;
}

}  // namespace meshcast::tools
