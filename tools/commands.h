// Subcommands of the meshcast program; each adds itself to the parser.
#pragma once
#include <CLI/CLI.hpp>

namespace meshcast::tools {

void add_trace(CLI::App& app);
void add_build(CLI::App& app);
void add_info(CLI::App& app);
void add_rays(CLI::App& app);
void add_demo(CLI::App& app);
void add_bench(CLI::App& app);

}  // namespace meshcast::tools
