// What the subcommands of the meshcast program share: loading a mesh or a
// blob, timing, and printing.
#pragma once
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/timing.h"
#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "meshcast/mesh.h"

namespace meshcast::tools {

struct Loaded {
  std::optional<Mesh> mesh;  // absent when a blob file was given
  std::vector<uint8_t> blob;
  double load_ms = 0, build_ms = 0;
  BuildReport report;
};

// A path whose first bytes are the blob magic is read as a blob (and
// validated); anything else is read as a mesh and built by `build`.
using MeshBuilder = std::function<std::vector<uint8_t>(const Mesh& mesh, BuildReport* report)>;
Loaded load_mesh_or_blob(const std::string& path, const MeshBuilder& build);

// Options of --layout and --leaf, with the defaults of the foundation issue.
BuildOptions layout_options(const std::string& layout, uint32_t leaf, const std::string& splitter = "");

using bench::median;
using bench::ms_since;

// Bytes of each blob section and per triangle.
struct SectionBytes {
  uint64_t header, nodes, triangles, vertices, remap, total;
  uint64_t walked() const { return header + nodes + triangles + vertices; }
};
SectionBytes section_bytes(const std::vector<uint8_t>& blob);

// The processor, as /proc/cpuinfo names it, with its widest vector set
// (a benchmark's figures count only with it).
std::string processor_name();
// A benchmark table's first words: the processor and the walkers' instruction set.
std::string bench_machine();
// The parts of a comma-separated list, empty parts dropped.
std::vector<std::string> split(const std::string& text);

void write_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

// One JSON object on a line of stdout, written by nlohmann::json: strings are
// escaped, bytes that are not UTF-8 (a path's) become U+FFFD, NaN and
// infinities become null. Keys stay in the order given.
void print_json(const nlohmann::ordered_json& object);

}  // namespace meshcast::tools
