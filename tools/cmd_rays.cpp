// meshcast rays MESH --kind long|probe|radial --count N --seed S --out R.rays
#include <cstdio>

#include "check/ray_files.h"
#include "meshcast/read.h"
#include "tools/commands.h"
#include "tools/common.h"

namespace meshcast::tools {

void add_rays(CLI::App& app) {
  struct Args {
    std::string input, kind = "long", out;
    size_t count = 10000;
    uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("rays", "write a rays file for a mesh");
  cmd->add_option("input", args->input, "mesh file")->required();
  cmd->add_option("--kind", args->kind, "long, probe or radial")->check(CLI::IsMember({"long", "probe", "radial"}));
  cmd->add_option("--count", args->count, "number of rays, at most 2^27")->check(integer_in(1, kMaxRayCount));
  cmd->add_option("--seed", args->seed, "random seed");
  cmd->add_option("--out", args->out, "rays file to write")->required();
  cmd->callback([args] {
    Mesh mesh = read_mesh(args->input);
    // Made and written a chunk at a time: 2^27 rays take 3.5 GiB on disk.
    RaySource source(mesh, parse_ray_kind(args->kind), args->seed);
    write_rays(args->out, args->count, [&](std::span<Ray> rays) { source.fill(rays); });
    std::printf("%s: %zu %s rays -> %s\n", args->input.c_str(), args->count, args->kind.c_str(), args->out.c_str());
  });
}

}  // namespace meshcast::tools
