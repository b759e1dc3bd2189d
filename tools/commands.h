// Subcommands of the meshcast program; each adds itself to the parser.
#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "cpu/encode.h"

namespace meshcast::tools {

void add_trace(CLI::App& app);
void add_build(CLI::App& app);
void add_info(CLI::App& app);
void add_rays(CLI::App& app);
void add_demo(CLI::App& app);
void add_bench(CLI::App& app);
void add_render(CLI::App& app);

// The layout options trace, build and info share: --layout, --leaf,
// --splitter, --order, --lbvh-depth, --lbvh-left-first, --grouping, --pairing.
struct LayoutArgs {
  std::string layout = "QuadTreeHalfFloat/Indexed8BitPackSOA4";
  std::string splitter, order, grouping;  // empty: the layout's own
  uint32_t leaf = 8, lbvh_depth = 0;
  bool lbvh_left_first = false;
  bool pairing = false;
  bool zbt_no_shuffle = false, zbt_no_cache = false;  // zero-byte trees (seed 004)
  uint32_t hybrid_leaf = 256;
};
void add_layout_options(CLI::App* cmd, LayoutArgs& args);
BuildOptions build_options(const LayoutArgs& args);  // throws InputError for bad names

}  // namespace meshcast::tools
