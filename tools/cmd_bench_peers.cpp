// `meshcast bench peers`: meshcast's layouts beside Embree's
// builds on the test meshes, the 2M terrain and the 1M city; Markdown, CSV
// and a plot of time against bytes, one point per layout and peer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>
#include <sstream>

#include "bench/peers.h"
#include "bench/plot.h"
#include "meshcast/blob.h"
#include "io/files.h"
#include "layout/queries.h"
#include "tools/commands.h"
#include "tools/common.h"

namespace meshcast::tools {


void add_bench_peers(CLI::App* bench) {
  struct Args {
    std::string meshes = "data/bunny00.off,data/armadillo.off,data/refined_elephant.off,data/ChineseDragon-10kv.off,"
                         "terrain_2M,city_1M";
    std::string layouts, kinds, queries = "closest,any", out_dir = "out", peers = "default,high,robust,compact";
    size_t rays = 10000;
    uint32_t rounds = 7;
    bool no_cores = false, no_packets = false, no_build_times = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench->add_subcommand("peers", "meshcast's layouts beside Embree's default, high-quality, robust and compact builds");
  cmd->add_option("--meshes", args->meshes, "comma-separated mesh files or generated meshes (terrain_2M, city_1M, terrain_20M; default: the six of the README table)");
  cmd->add_option("--layouts", args->layouts,
                  "comma-separated meshcast layouts, each TREE/TRIANGLES, @LEAF for another leaf size, :embree to lay "
                  "it out over the binary tree Embree's builder makes (rtcBuildBVH) instead of meshcast's own "
                  "(default: the OctTree and QuadTree ones)");
  cmd->add_option("--kinds", args->kinds, "comma-separated ray kinds: long, probe, radial, segment (default: all four)");
  cmd->add_option("--queries", args->queries,
                  "comma-separated queries: closest, any (Embree: rtcOccluded1), all (every hit, rows of 16), "
                  "each with a culling as in closest-back or any-front; Embree answers closest and any "
                  "(default: closest,any)");
  cmd->add_option("--peers", args->peers,
                  "comma-separated Embree builds: default, high, robust, compact (default: all four; ratios are to "
                  "default and high where measured)")
      ->check([](const std::string& text) -> std::string {
        const std::vector<std::string>& builds = bench::embree_build_names();
        for (const std::string& p : split(text))
          if (std::find(builds.begin(), builds.end(), p) == builds.end())
            return "\"" + p + "\" is not an Embree build: default, high, robust or compact";
        return "";
      });
  cmd->add_option("--rays", args->rays, "rays a set (each ray kind)")->check(integer_in(100, 1000000));
  cmd->add_option("--rounds", args->rounds, "interleaved rounds; the median is reported")->check(integer_in(1, 100));
  cmd->add_option("--out-dir", args->out_dir, "where peers.csv, cores.csv and peers.png go");
  cmd->add_flag("--no-cores", args->no_cores,
                "leave out the multi-core rows (the first layout through the Caster's CPU workers and Embree default "
                "through a TBB loop, rays a second on one thread and on every core)");
  cmd->add_flag("--no-build-times", args->no_build_times,
                "leave out the build times (every contender built again in interleaved rounds; the build columns "
                "read 0)");
  cmd->add_flag("--no-packets", args->no_packets,
                "leave out the sorted sets (a kind of one origin's rays, radial, sorted by direction: meshcast's "
                "packets beside Embree's single rays and its 16-wide packets)");
  cmd->callback([args] {
    bench::PeersOptions o;
    o.layouts = args->layouts.empty() ? bench::default_peer_layouts() : split(args->layouts);
    if (!args->kinds.empty()) o.kinds = split(args->kinds);
    o.queries = split(args->queries);
    for (const std::string& q : o.queries) layout::query_spec_named(q, "--queries");  // refused before any build
    o.rays = args->rays, o.rounds = args->rounds;
    o.cores = !args->no_cores;
    o.packets = !args->no_packets;
    o.peers = split(args->peers);
    o.build_times = !args->no_build_times;
    std::filesystem::create_directories(args->out_dir);
    std::vector<bench::PeerRow> rows;
    std::vector<bench::CoreRow> core_rows;
    std::vector<bench::CountRow> count_rows;
    for (const std::string& input : split(args->meshes)) {
      Mesh mesh = bench_mesh(input);
      std::fprintf(stderr, "%s: %zu triangles\n", input.c_str(), mesh.triangles.size());
      std::vector<bench::PeerRow> r =
          bench::bench_peers(mesh, std::filesystem::path(input).stem().string(), o, &core_rows, &count_rows);
      rows.insert(rows.end(), r.begin(), r.end());
    }
    std::printf("\n%s; one thread tracing, %zu rays a set, median of %u interleaved rounds; ratio: to Embree default "
                "on the same rays and query (any: Embree's rtcOccluded1); / high: to Embree's high-quality build (spatial "
                "splits); / closest: time against the same row's closest "
                "hit on the same rays; / 16-wide: to Embree default's rtcIntersect16 / rtcOccluded16 on the same rays (the "
                "sorted sets alone: one origin's rays sorted by direction, which meshcast walks as packets; every other "
                "set one ray at a time); bytes a triangle all included (meshcast: the whole blob with its remap; Embree: "
                "its scene plus the mesh it keeps); build: median ms on one thread / on every core (%u); build peak: the "
                "resident memory the first build (one thread) added at its peak, what it keeps included, a triangle\n\n"
                "| mesh | rays | query | layout or peer | ns/ray | ratio | / high | / 16-wide | / closest | B/tri | build ms (1 / all) | build peak B/tri |\n"
                "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
                bench_machine().c_str(), o.rays, o.rounds, std::max(1u, std::thread::hardware_concurrency()));
    OutputText csv(args->out_dir + "/peers.csv");
    csv << "mesh,rays,contender,peer,ns_per_ray,ratio_to_embree_default,bytes_per_triangle,build_ms_one_thread,"
           "build_ms_all_cores,query,ratio_to_closest,ratio_to_embree_high,ratio_to_embree_16_wide,build_peak_bytes_per_triangle\n";
    // The plot: each contender's geometric mean ratio over the closest-hit
    // rows against its mean bytes a triangle.
    std::map<std::string, std::pair<double, double>> log_ratio_bytes;
    std::map<std::string, int> counted;
    std::vector<std::string> order;
    for (const bench::PeerRow& r : rows) {
      std::printf("| %s | %s | %s | %s | %.0f | %.2f | %.2f | %.2f | %.2f | %.1f | %.0f / %.0f | %.0f |\n", r.mesh.c_str(),
                  r.kind.c_str(), r.query.c_str(), r.contender.c_str(), r.ns_per_ray, r.ratio, r.ratio_high, r.ratio_packets, r.to_closest,
                  r.bytes_per_triangle, r.build_ms_one, r.build_ms_all, r.build_peak_bytes_per_triangle);
      csv << r.mesh << "," << r.kind << "," << r.contender << "," << (r.is_peer ? 1 : 0) << "," << r.ns_per_ray << ","
          << r.ratio << "," << r.bytes_per_triangle << "," << r.build_ms_one << "," << r.build_ms_all << "," << r.query
          << "," << r.to_closest << "," << r.ratio_high << "," << r.ratio_packets << "," << r.build_peak_bytes_per_triangle
          << "\n";
      // The plot is of single rays: the sorted sets and the 16-wide packets are left out.
      if (r.query != "closest" || r.kind.ends_with(" sorted") || r.contender.find("16-wide") != std::string::npos) continue;
      if (!counted.count(r.contender)) order.push_back(r.contender);
      auto& [lr, b] = log_ratio_bytes[r.contender];
      lr += std::log(r.ratio > 0 ? r.ratio : 1.0), b += r.bytes_per_triangle;
      ++counted[r.contender];
    }
    csv.commit();
    if (!core_rows.empty()) {
      const uint32_t every = core_rows[0].cores;
      std::printf("\nEvery core (%u hardware threads) against one, the same rays: meshcast's Caster (its CPU workers, "
                  "Backend::Cpu) and Embree default (a TBB loop over rtcIntersect1 / rtcOccluded1), batches of the "
                  "set repeated to 100,000 rays or more, median of %u interleaved rounds (the Caster's times include "
                  "its copies of the rays in and the hits out); ratio: time on every core to Embree default's on every "
                  "core\n\n"
                  "| mesh | rays | query | contender | Mrays/s, 1 thread | Mrays/s, %u threads | scaling | ratio |\n"
                  "|---|---|---|---|---:|---:|---:|---:|\n",
                  every, o.rounds, every);
      OutputText cores_csv(args->out_dir + "/cores.csv");
      cores_csv << "mesh,rays,query,contender,cores,rays_per_s_one_thread,rays_per_s_all_cores,scaling,ratio_to_embree_all_cores\n";
      for (const bench::CoreRow& r : core_rows) {
        std::printf("| %s | %s | %s | %s | %.2f | %.2f | %.2f | %.2f |\n", r.mesh.c_str(), r.kind.c_str(), r.query.c_str(),
                    r.contender.c_str(), r.rays_per_s_one / 1e6, r.rays_per_s_all / 1e6, r.scaling(), r.ratio_all);
        cores_csv << r.mesh << "," << r.kind << "," << r.query << "," << r.contender << "," << r.cores << ","
                  << r.rays_per_s_one << "," << r.rays_per_s_all << "," << r.scaling() << "," << r.ratio_all << "\n";
      }
      cores_csv.commit();
    }
    if (!count_rows.empty()) {
      std::printf("\nCounted (a build with MESHCAST_COUNT_TESTS, one more walk of each set, one ray at a time): "
                  "inner nodes (a node's children tested together), leaves and triangle lanes tested, a ray\n\n"
                  "| mesh | rays | query | layout | nodes | leaves | triangles |\n|---|---|---|---|---:|---:|---:|\n");
      for (const bench::CountRow& r : count_rows)
        std::printf("| %s | %s | %s | %s | %.2f | %.2f | %.2f |\n", r.mesh.c_str(), r.kind.c_str(), r.query.c_str(),
                    r.contender.c_str(), r.nodes, r.leaves, r.triangles);
    }
    bench::Series meshcast{"meshcast", {}}, embree{"Embree", {}};
    for (const std::string& c : order) {
      const double n = counted[c];
      const bench::Point p{log_ratio_bytes[c].second / n, std::exp(log_ratio_bytes[c].first / n), c};
      (c.rfind("Embree", 0) == 0 ? embree : meshcast).points.push_back(p);
    }
    const std::string png = args->out_dir + "/peers.png";
    const std::string why = bench::plot_scatter(png, "time against bytes, geometric mean over the rows",
                                                "bytes a triangle, all included", "time a ray / Embree default time a ray",
                                                {meshcast, embree}, false);
    std::printf("\ncsv: %s/peers.csv\nplot: %s\n", args->out_dir.c_str(), why.empty() ? png.c_str() : why.c_str());
  });
}

}  // namespace meshcast::tools
