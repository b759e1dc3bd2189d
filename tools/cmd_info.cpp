// meshcast info MESH|BLOB: counts, bounds, layout and bytes per triangle by
// section. "walked" is what a ray cast reads (header, nodes, triangle blocks,
// vertices); the remap is read once per hit and reported beside it.
#include <algorithm>
#include <cstdio>

#include "layout/blob.h"
#include "tools/commands.h"
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
  cmd->add_option("input", args->input, "mesh file or blob")->required();
  add_layout_options(cmd, args->layout);
  cmd->add_flag("--json", args->json, "print the same as one JSON object");
  cmd->callback([args] {
    Loaded in = load_input(args->input, args->layout, args->json ? stderr : stdout);
    const layout::BlobHeader& h = layout::header_of(in.blob.data());
    SectionBytes s = section_bytes(in.blob);
    double n = h.triangle_count;
    std::string layout = layout_name(h.tree_format, h.triangle_format);
    if (args->json) {
      std::printf("{\"input\":\"%s\",\"layout\":\"%s\",\"leaf_size\":%u,\"triangles\":%u,\"nodes\":%u,"
                  "\"leaves\":%u,\"depth\":%u,\"sah_cost\":%.3f,\"build_ms\":%.3f,"
                  "\"bounds_min\":[%g,%g,%g],\"bounds_max\":[%g,%g,%g],"
                  "\"bytes\":{\"header\":%llu,\"nodes\":%llu,\"triangles\":%llu,\"vertices\":%llu,"
                  "\"remap\":%llu,\"total\":%llu},"
                  "\"bytes_per_triangle\":{\"header\":%.3f,\"nodes\":%.3f,\"triangles\":%.3f,\"vertices\":%.3f,"
                  "\"walked\":%.3f,\"remap\":%.3f,\"total\":%.3f},\"remap_bits\":%u}\n",
                  args->input.c_str(), layout.c_str(), h.leaf_size, h.triangle_count, h.node_count, h.leaf_count,
                  h.max_depth, in.report.sah_cost, in.build_ms, h.bounds_min[0], h.bounds_min[1], h.bounds_min[2],
                  h.bounds_max[0], h.bounds_max[1], h.bounds_max[2], (unsigned long long)s.header,
                  (unsigned long long)s.nodes, (unsigned long long)s.triangles, (unsigned long long)s.vertices,
                  (unsigned long long)s.remap, (unsigned long long)s.total, s.header / n, s.nodes / n,
                  s.triangles / n, s.vertices / n, s.walked() / n, s.remap / n, s.total / n, h.remap_bits);
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

}  // namespace meshcast::tools
