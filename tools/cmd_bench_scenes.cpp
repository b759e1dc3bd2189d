// `meshcast bench scenes`: the table of bench/scenes.h, its CSV.
#include <cstdio>
#include <filesystem>

#include "bench/scenes.h"
#include "meshcast/blob.h"
#include "io/files.h"
#include "tools/commands.h"
#include "tools/common.h"

namespace meshcast::tools {

void add_bench_scenes(CLI::App* bench) {
  struct Args {
    std::string meshes = "data/bunny00.off,data/armadillo.off,data/ChineseDragon-10kv.off", out_dir = "out";
    bench::ScenesOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench->add_subcommand("scenes", "a level of placed meshes beside Embree's instancing");
  cmd->add_option("--meshes", args->meshes, "comma-separated mesh files placed in turn (default bunny00, armadillo, the dragon)");
  cmd->add_option("--counts", args->options.counts, "comma-separated instance counts, a level each (default 1000,10000)")
      ->delimiter(',')
      ->check(integer_in(1, 1000000));
  cmd->add_option("--layout", args->options.layout, "the meshes' layout");
  cmd->add_option("--rays", args->options.rays, "rays a level")->check(integer_in(100, 1000000));
  cmd->add_option("--rounds", args->options.rounds, "interleaved rounds; the median is reported")->check(integer_in(1, 100));
  cmd->add_option("--out-dir", args->out_dir, "where scenes.csv goes");
  cmd->callback([args] {
    const bench::ScenesOptions& o = args->options;
    std::vector<Mesh> meshes;
    for (const std::string& m : split(args->meshes)) meshes.push_back(bench_mesh(m));
    std::filesystem::create_directories(args->out_dir);
    const std::vector<bench::SceneRow> rows = bench::bench_scenes(meshes, o);
    std::printf("\n%s; one thread, %zu rays a level, median of %u interleaved rounds; bytes all "
                "included (meshcast: the blobs and the top level; Embree: its scenes and the meshes it keeps); update: "
                "a tenth / every instance moved, then the commit (median of 8 frames); as at the origin: the rays "
                "answered with the same instance and triangle as the level at the origin\n\n"
                "| instances | offset | contender | ns/ray | ratio | MB | update ms (tenth / all) | hit | as at the origin |\n"
                "|---:|---:|---|---:|---:|---:|---:|---:|---:|\n",
                bench_machine().c_str(), o.rays, o.rounds);
    OutputText csv(args->out_dir + "/scenes.csv");
    csv << "instances,offset,contender,ns_per_ray,bytes,update_tenth_ms,update_all_ms,hit_fraction,same_as_origin\n";
    double meshcast_ns = 0;
    for (const bench::SceneRow& r : rows) {
      if (r.contender.rfind("meshcast", 0) == 0) meshcast_ns = r.ns_per_ray;
      // ratio: Embree's rows against meshcast's on the same level
      const double ratio = meshcast_ns > 0 ? r.ns_per_ray / meshcast_ns : 0;
      std::printf("| %zu | %g | %s | %.0f | %.2f | %.1f | %.2f / %.2f | %.1f%% | %.2f%% |\n", r.instances, r.offset,
                  r.contender.c_str(), r.ns_per_ray, ratio, r.bytes / 1e6, r.update_ms, r.update_all_ms, 100 * r.hits,
                  100 * r.same_as_origin);
      csv << r.instances << "," << r.offset << "," << r.contender << "," << r.ns_per_ray << "," << r.bytes << ","
          << r.update_ms << "," << r.update_all_ms << "," << r.hits << "," << r.same_as_origin << "\n";
    }
    csv.commit();
    std::printf("\ncsv: %s/scenes.csv\n", args->out_dir.c_str());
  });
}

}  // namespace meshcast::tools
