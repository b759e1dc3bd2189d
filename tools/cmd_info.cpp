// meshcast info MESH|BLOB: counts, bounds, layout and bytes per triangle by
// section. "walked" is what a ray cast reads (header, nodes, triangle blocks,
// vertices); the remap is read once per hit and reported beside it.
#include <algorithm>
#include <cstdio>

#include "layout/blob_format.h"
#include "tools/commands.h"
#include "tools/progress.h"
#include "tools/common.h"

namespace meshcast::tools {

void add_info(CLI::App& app) {
  struct Args {
    std::string input;
    LayoutArgs layout;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("info", "describe a mesh's blob: counts, bounds, bytes per section");
  cmd->add_option("input", args->input, "mesh file, generated mesh (terrain_2M, terrain_66k, city_1M, terrain_20M) or blob")->required();
  add_layout_options(cmd, args->layout);
  cmd->add_flag("--json", args->json, "print the same as one JSON object");
  cmd->callback([args] {
    if (args->json) hide_progress();
    Loaded in = load_input(args->input, args->layout, args->json ? stderr : stdout);
    const layout::BlobHeader& h = layout::header_of(in.blob.data());
    SectionBytes s = section_bytes(in.blob);
    double n = h.triangle_count;
    std::string layout = layout_name(h.tree_format, h.triangle_format);
    if (args->json) {
      auto per_triangle = [&](uint64_t b) { return double(b) / n; };
      print_json({{"input", args->input},
                  {"layout", layout},
                  {"leaf_size", h.leaf_size},
                  {"triangles", h.triangle_count},
                  {"nodes", h.node_count},
                  {"leaves", h.leaf_count},
                  {"depth", h.max_depth},
                  {"sah_cost", in.mesh ? nlohmann::ordered_json(in.report.sah_cost) : nlohmann::ordered_json(nullptr)},  // a blob has none
                  {"build_ms", in.build_ms},
                  {"bounds_min", {h.bounds_min[0], h.bounds_min[1], h.bounds_min[2]}},
                  {"bounds_max", {h.bounds_max[0], h.bounds_max[1], h.bounds_max[2]}},
                  {"bytes",
                   {{"header", s.header}, {"nodes", s.nodes}, {"triangles", s.triangles}, {"vertices", s.vertices},
                    {"remap", s.remap}, {"total", s.total}}},
                  {"bytes_per_triangle",
                   {{"header", per_triangle(s.header)}, {"nodes", per_triangle(s.nodes)},
                    {"triangles", per_triangle(s.triangles)}, {"vertices", per_triangle(s.vertices)},
                    {"walked", per_triangle(s.walked())}, {"remap", per_triangle(s.remap)},
                    {"total", per_triangle(s.total)}}},
                  {"remap_bits", h.remap_bits}});
      return;
    }
    std::printf("%s\n  layout       %s, leaf size %u\n", args->input.c_str(), layout.c_str(), h.leaf_size);
    std::printf("  triangles    %u\n  nodes        %u (%u leaves), depth %u", h.triangle_count, h.node_count,
                h.leaf_count, h.max_depth);
    if (in.mesh) std::printf(", SAH cost %.2f, build %.1f ms", in.report.sah_cost, in.build_ms);
    if (in.mesh && !in.report.pairing.empty())
      std::printf("\n  pairing      %.1f%% of triangles paired; %s", 100 * in.report.paired_ratio, in.report.pairing.c_str());
    if (!in.report.zerobyte.empty()) std::printf("\n  zero-byte    %s", in.report.zerobyte.c_str());
    std::printf("\n  bounds       (%g, %g, %g) .. (%g, %g, %g)\n", h.bounds_min[0], h.bounds_min[1], h.bounds_min[2],
                h.bounds_max[0], h.bounds_max[1], h.bounds_max[2]);
    std::printf("  %-10s %12s %10s\n", "section", "bytes", "B/tri");
    auto row = [&](const char* name, uint64_t b) { std::printf("  %-10s %12llu %10.2f\n", name, (unsigned long long)b, b / n); };
    row("header", s.header);
    row("nodes", s.nodes);
    row("triangles", s.triangles);
    row("vertices", s.vertices);
    row("walked", s.walked());
    row("remap", s.remap);
    row("total", s.total);
    if (!layout::has_remap(h))
      std::printf("  remap: none (asked for): a hit names its triangle by slot number, below %u\n", h.remap_slots);
    else if (h.remap_bits == 0)
      std::printf("  remap: in input order, %u slot numbers (%.0f%% used): the used-slot bitmap and ranks only\n",
                  h.remap_slots, 100.0 * h.triangle_count / std::max(1u, h.remap_slots));
    else
      std::printf("  remap: %u entries of %u bits, %u slot numbers (%.0f%% used)\n", h.triangle_count, h.remap_bits,
                  h.remap_slots, 100.0 * h.triangle_count / std::max(1u, h.remap_slots));
  });
}

// meshcast layouts: every TREE/TRIANGLES name --layout takes, a line each.
void add_layouts(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("layouts", "list every layout --layout takes (TREE/TRIANGLES), a line each");
  cmd->callback([] {
    for (const std::string& name : layout_names()) std::printf("%s\n", name.c_str());
  });
}

}  // namespace meshcast::tools
