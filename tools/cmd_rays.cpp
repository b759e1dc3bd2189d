// meshcast rays MESH --kind long|probe|radial --count N --seed S --out R.rays
// meshcast generate terrain_2M|terrain_66k|city_1M --out MESH.off
#include <cstdint>
#include <cstdio>
#include <memory>

#include "check/ray_files.h"
#include "layout/message_text.h"
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
  cmd->add_option("input", args->input, "mesh file, or a generated mesh: terrain_2M, terrain_66k, city_1M, terrain_20M")->required();
  cmd->add_option("--kind", args->kind, "long, probe, radial or segment")->check(CLI::IsMember(ray_kind_names()));
  cmd->add_option("--count", args->count, "number of rays, at most 2^27")->check(integer_in(1, kMaxRayCount));
  cmd->add_option("--seed", args->seed, "random seed")->check(integer_in(0, UINT64_MAX));
  cmd->add_option("--out", args->out, "rays file to write")->required();
  cmd->callback([args] {
    Mesh mesh = bench_mesh(args->input);
    // Made and written a chunk at a time: 2^27 rays take 3.5 GiB on disk.
    RaySource source(mesh, parse_ray_kind(args->kind), args->seed);
    write_rays(args->out, args->count, [&](std::span<Ray> rays) { source.fill(rays); });
    std::printf("%s: %zu %s rays -> %s\n", args->input.c_str(), args->count, args->kind.c_str(), args->out.c_str());
  });
}

// The generated meshes the benchmarks measure, as OFF files for other
// programs (the Python benchmark, a peer's loader): every coordinate
// written with 9 significant digits, so it reads back as the same float.
void add_generate(CLI::App& app) {
  struct Args {
    std::string name, out;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("generate", "write a generated benchmark mesh (terrain_2M, terrain_66k, city_1M, terrain_20M) as OFF");
  cmd->add_option("name", args->name, "terrain_2M, terrain_66k, city_1M or terrain_20M")
      ->required()
      ->check(CLI::Validator(
          [](std::string& name) -> std::string {
            return is_generated_mesh(name) ? std::string() : "\"" + shown_text(name) + "\" is not a generated mesh; " + generated_mesh_offer(name);
          },
          "NAME"));
  cmd->add_option("--out", args->out, "OFF file to write")->required();
  cmd->callback([args] {
    const Mesh mesh = bench_mesh(args->name);
    std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(args->out.c_str(), "w"), std::fclose);
    if (!file) throw OutputError("generate: cannot write " + args->out);
    std::fprintf(file.get(), "OFF\n%zu %zu 0\n", mesh.vertices.size(), mesh.triangles.size());
    for (const Vec3& v : mesh.vertices) std::fprintf(file.get(), "%.9g %.9g %.9g\n", v.x, v.y, v.z);
    for (const Triangle& t : mesh.triangles) std::fprintf(file.get(), "3 %u %u %u\n", t[0], t[1], t[2]);
    if (std::fflush(file.get()) != 0 || std::ferror(file.get())) throw OutputError("generate: writing " + args->out + " failed");
    std::printf("%s: %zu vertices, %zu triangles -> %s\n", args->name.c_str(), mesh.vertices.size(),
                mesh.triangles.size(), args->out.c_str());
  });
}

}  // namespace meshcast::tools
