// meshcast bench auto [MESHES]: the table of the automatic layout's
// choice under each setting against the best layout of the combos table
// meeting the same limits, measured in one run.
#include <cstdio>
#include <filesystem>

#include "bench/auto.h"
#include "check/ray_files.h"
#include "tools/commands.h"

namespace meshcast::tools {

void add_bench_auto(CLI::App* bench) {
  struct Args {
    std::vector<std::string> meshes;
    size_t rays = 1024;
    uint32_t repeat = 7;
    std::string out_dir = "out";
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench->add_subcommand("auto", "--layout auto under each setting against every combos layout");
  cmd->add_option("meshes", args->meshes,
                  "mesh files, terrain_2M or terrain_66k (default bunny00, armadillo, refined_elephant, "
                  "ChineseDragon-10kv, terrain_2M, terrain_66k)");
  cmd->add_option("--rays", args->rays, "long random rays (seed 1; auto's trial uses its own)")
      ->check(integer_in(1, 1000000));
  cmd->add_option("--repeat", args->repeat, "passes; the minimum is kept")->check(integer_in(1, 1000));
  cmd->add_option("--out-dir", args->out_dir, "where auto.csv goes");
  cmd->callback([args] {
    std::vector<std::string> names = args->meshes;
    if (names.empty())
      names = {"data/bunny00.off", "data/armadillo.off", "data/refined_elephant.off", "data/ChineseDragon-10kv.off",
               "terrain_2M", "terrain_66k"};
    std::filesystem::create_directories(args->out_dir);
    const std::string csv_path = args->out_dir + "/auto.csv";
    OutputText csv(csv_path);
    csv << "mesh,setting,choice,ns_per_ray,bytes_per_tri,error_bound,disagreements,choose_ms,best,best_value,value,"
           "ratio,eligible\n";
    std::printf("%zu long rays (seed 1), one thread, minimum of %u passes; bytes: the whole blob a triangle; "
                "best: the best layout of the combos table meeting the setting's limits, measured in the same run\n\n"
                "| mesh | setting | auto's choice | ns/ray | B/tri | stated error | oracle disagreements | decided in ms | "
                "best combos layout | its ns/ray or B/tri | choice / best | layouts meeting the limits |\n"
                "|---|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|\n",
                args->rays, args->repeat);
    size_t outside = 0, unmatched = 0;
    for (const std::string& name : names) {
      Mesh mesh = bench_mesh(name);
      std::fprintf(stderr, "%s: %zu triangles, %zu vertices\n", name.c_str(), mesh.triangles.size(), mesh.vertices.size());
      bench::AutoTable t = bench::bench_auto(mesh, name, args->rays, args->repeat);
      for (const bench::AutoRow& r : t.rows) {
        // No combos layout meets the limits: nothing to compare with, counted apart.
        const double ratio = r.eligible ? r.value / r.best_value : 0;
        outside += r.eligible && ratio > 1.10;
        unmatched += r.eligible == 0;
        std::printf("| %s | %s | %s | %.0f | %.2f | %.2g | %llu | %.0f | %s | %.2f | %.3f | %zu |\n", name.c_str(),
                    r.setting.c_str(), r.choice.c_str(), r.timing.min_ms * 1e6 / double(args->rays), r.timing.total_bytes,
                    r.timing.error_bound, (unsigned long long)r.timing.disagreements, r.choose_ms, r.best.c_str(),
                    r.best_value, ratio, r.eligible);
        csv << name << ",\"" << r.setting << "\",\"" << r.choice << "\"," << r.timing.min_ms * 1e6 / double(args->rays)
            << "," << r.timing.total_bytes << "," << r.timing.error_bound << "," << r.timing.disagreements << ","
            << r.choose_ms << ",\"" << r.best << "\"," << r.best_value << "," << r.value << "," << ratio << ","
            << r.eligible << "\n";
      }
      std::fflush(stdout);
    }
    csv.commit();
    std::printf("\n%zu of %zu choices more than 10%% from the best meeting their limits (%zu with no combos layout "
                "meeting them)\ncsv: %s\n",
                outside, names.size() * bench::auto_settings().size(), unmatched, csv_path.c_str());
  });
}

}  // namespace meshcast::tools
