// Subcommands of the meshcast program; each adds itself to the parser.
#pragma once
#include <CLI/CLI.hpp>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "tools/common.h"

namespace meshcast::tools {

void add_trace(CLI::App& app);
void add_build(CLI::App& app);
void add_info(CLI::App& app);
void add_layouts(CLI::App& app);
void add_rays(CLI::App& app);
void add_generate(CLI::App& app);
void add_demo(CLI::App& app);
void add_bench(CLI::App& app);
void add_render(CLI::App& app);
void add_distance(CLI::App& app);
void add_bench_auto(CLI::App* bench);   // `meshcast bench auto`, under `bench`
void add_bench_peers(CLI::App* bench);  // `meshcast bench peers`
void add_bench_scenes(CLI::App* bench);  // `meshcast bench scenes`

// A mesh file, or a generated mesh: "terrain_2M" (2,097,152 triangles,
// 1,050,625 vertices), "terrain_66k" (131,072 triangles, 66,049 vertices:
// just past 16-bit indices) or "city_1M" (about a million triangles). Every
// command that takes a mesh reads it here (or through load_mesh_or_blob).
Mesh bench_mesh(const std::string& input);
// The generated meshes' names, and the mesh of one (nothing for any other name).
const std::vector<std::string>& generated_mesh_names();
bool is_generated_mesh(const std::string& name);
std::optional<Mesh> generated_mesh(const std::string& name);
// "did you mean terrain_66k, terrain_2M or city_1M?": every generated mesh, nearest `name` first.
std::string generated_mesh_offer(const std::string& name);
// Called in the handler that caught `e`, the refusal of a mesh input:
// rethrows it with the generated meshes' names offered when `input` looks
// like a mistyped one (a word that is no file), else as it is.
[[noreturn]] void refuse_missing_mesh(const std::string& input, const InputError& e);

// The layout options trace, build and info share: --layout, --leaf,
// --splitter, --order, --lbvh-depth, --lbvh-left-first, --grouping, --pairing.
struct LayoutArgs {
  std::string layout = "OctTreeCompressed/ClusterBitPackSOA8";
  std::string splitter, order, grouping;  // empty: the layout's own
  uint32_t leaf = 0, lbvh_depth = 0;  // leaf 0: the layout's own
  bool lbvh_left_first = false;
  bool pairing = false;
  bool no_triangle_ids = false;  // BuildOptions::triangle_ids
  bool zbt_no_shuffle = false, zbt_no_cache = false;  // zero-byte trees (seed 004)
  uint32_t hybrid_leaf = 256;
  uint32_t build_threads = 0;  // BuildOptions::threads (0: every core)
  // --layout auto (builder/auto_layout.h): the limits it chooses under.
  std::string goal = "speed";
  double max_bytes = 0, max_error = 0;
  bool gpu = false;
  std::string gpu_method;  // with gpu: only the layouts this GPU method reads ("": any method's)
  uint32_t trial = 0;
  // The options add_layout_options added: a blob input refuses any the user gave.
  std::vector<const CLI::Option*> options;
};
void add_layout_options(CLI::App* cmd, LayoutArgs& args);

// The check of an integer option: decimal digits alone, within lo..hi
// ("1e3" or "2.5" is refused as not an integer, where CLI::Range would
// read it as a number and call it out of range).
CLI::Validator integer_in(uint64_t lo, uint64_t hi);
// The check of a real-number option on the text as written, so a refusal
// names it so ("1e39", not the "inf" it would become): a number (NaN is
// not), within lo..hi; `single`: also within a float's range, and not a
// nonzero value a float would hold as 0.
CLI::Validator number_in(double lo, double hi = INFINITY, bool single = false);
BuildOptions build_options(const LayoutArgs& args);  // throws InputError for bad names
// load_mesh_or_blob with these options; with --layout auto the layout is
// chosen for the mesh, and what was chosen and why is printed to `report`.
Loaded load_input(const std::string& path, const LayoutArgs& args, std::FILE* report = stdout);
// load_input for a --backend: with vulkan, --layout auto keeps to the
// layouts a GPU method reads (the one `method` names, when named), and an
// empty `method` becomes the one that reads the blob's layout (InputError
// naming the layout when none does). trace and render choose so.
Loaded load_input_for(const std::string& path, LayoutArgs& args, const std::string& backend, std::string& method,
                      std::FILE* report = stdout);
// Every GPU method and the layouts it reads: "aabbtree (AABBTree/Float3 or ...), ...".
std::string gpu_methods_text();

}  // namespace meshcast::tools
