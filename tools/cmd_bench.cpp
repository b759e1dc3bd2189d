// meshcast bench TABLE: the source documents' tables and the issues'
// measurements on this machine, one function a table (bench auto has its own
// file).
#include <cstdio>
#include <filesystem>
#include <map>
#include <cmath>
#include <algorithm>
#include <optional>

#include "cpu/counters.h"
#include "check/ray_files.h"
#include "bench/encodings.h"
#include "bench/error.h"
#include "bench/exactness.h"
#include "bench/gpu.h"
#include "bench/gpu_scale.h"
#include "bench/latency.h"
#include "bench/pairing.h"
#include "bench/plot.h"
#include "bench/robustness.h"
#include "bench/trees.h"
#include "check/generate.h"
#include "layout/names.h"
#include "meshcast/read.h"
#include "tools/progress.h"
#include "tools/commands.h"
#include "tools/common.h"

namespace meshcast::tools {

namespace {

// The generated meshes: each name once, with the mesh it makes.
struct GeneratedMesh {
  const char* name;
  Mesh (*make)();
};
constexpr GeneratedMesh kGeneratedMeshes[] = {
    {"terrain_2M", [] { return make_terrain(1024, 1024, 5); }},
    {"terrain_66k", [] { return make_terrain(256, 256, 5); }},
    {"city_1M", [] { return make_city(1000000, 7); }},
    // Where neither meshcast's structure nor Embree's fits in the caches: the
    // terrain of terrain_2M over a ten times larger area (20.5M triangles).
    {"terrain_20M", [] { return make_terrain(3200, 3200, 5); }},
};

}  // namespace

const std::vector<std::string>& generated_mesh_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const GeneratedMesh& g : kGeneratedMeshes) out.push_back(g.name);
    return out;
  }();
  return names;
}

bool is_generated_mesh(const std::string& name) {
  const std::vector<std::string>& names = generated_mesh_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::optional<Mesh> generated_mesh(const std::string& name) {
  for (const GeneratedMesh& g : kGeneratedMeshes)
    if (name == g.name) return g.make();
  return std::nullopt;
}

std::string generated_mesh_offer(const std::string& name) {
  return "did you mean " + closest_names(name, generated_mesh_names()) + "?";
}

void refuse_missing_mesh(const std::string& input, const InputError& e) {
  // A word with no folder and no extension that is no file may be a
  // generated mesh's name mistyped ("terrain_66K"): the names are offered,
  // nearest first, as a mistyped layout's are.
  std::error_code ec;
  if (input.find_first_of("/.") == std::string::npos && !std::filesystem::exists(std::filesystem::symlink_status(input, ec)))
    throw InputError(std::string(e.what()) + "; nor is it a generated mesh: " + generated_mesh_offer(input));
  throw;  // as it was: its own type, its own words
}

Mesh bench_mesh(const std::string& input) {
  if (std::optional<Mesh> generated = generated_mesh(input)) return std::move(*generated);
  try {
    return read_mesh(input);
  } catch (const InputError& e) {
    refuse_missing_mesh(input, e);
  }
}

namespace {

// Options every table takes.
// Every row of `meshcast bench exactness` summed: hits, and the largest errors.
struct ExactnessTotals {
  unsigned long long hits = 0, rounded = 0;
  double t_ulps = 0, uv = 0, point_ulps = 0;
  void add(const bench::ExactnessRow& r) {
    hits += r.hits, rounded += r.rounded;
    t_ulps = std::max(t_ulps, r.t_ulps), uv = std::max(uv, r.uv), point_ulps = std::max(point_ulps, r.point_ulps);
  }
};

struct BenchArgs {
  std::string input = "data/bunny00.off", out_dir = "out";
  size_t rays = 1024;
  uint32_t repeat = 7;
  std::string only;  // combos: the layouts naming one of these (comma separated)
};

// Seed 000 §3.11: every triangle encoding, brute force and in a QuadTree.
void add_bench_encodings(CLI::App* bench) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = bench->add_subcommand("encodings", "Rouwe 2019, table 3.11: every triangle encoding, brute force and in a QuadTree");
  cmd->add_option("mesh", args->input, "mesh file (default data/bunny00.off)");
  cmd->add_option("--rays", args->rays, "long random rays (the source used 1024)")->check(integer_in(1, 1000000));
  cmd->add_option("--repeat", args->repeat, "passes; the minimum (as the source) and the median are reported")
      ->check(integer_in(1, 1000));
  cmd->add_option("--out-dir", args->out_dir, "where encodings.csv and encodings.png go");
  cmd->callback([args] {
    Mesh mesh = bench_mesh(args->input);
    std::filesystem::create_directories(args->out_dir);
    std::fprintf(stderr, "%s: %zu triangles, %zu long rays, %u passes\n", args->input.c_str(), mesh.triangles.size(),
                 args->rays, args->repeat);
    std::vector<bench::EncodingRow> rows = bench::bench_encodings(mesh, args->input, {args->rays, args->repeat, 1});
    double scale = 1024.0 / double(args->rays);  // the source's unit: ms for 1024 rays
    std::printf("\n%s, %zu triangles, %zu long rays, one thread; time = ms for 1024 rays (minimum of %u passes, "
                "median beside it), as Rouwe (2019) reports it in table 3.11 (its column: i7-7700HQ, 69,451-triangle bunny)\n\n",
                args->input.c_str(), mesh.triangles.size(), args->rays, args->repeat);
    std::printf("| encoding | brute force ms (min) | median | bytes/tri | seed ms | seed bytes/tri | QuadTree ms (min) "
                "| median | bytes/tri in QuadTree | disagreements |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    std::string csv_path = args->out_dir + "/encodings.csv";
    OutputText csv(csv_path);
    csv << "encoding,brute_min_ms_1024,brute_median_ms_1024,brute_bytes_per_tri,seed_ms_1024,seed_bytes_per_tri,"
           "quadtree_min_ms_1024,quadtree_median_ms_1024,quadtree_bytes_per_tri,disagreements\n";
    bench::Series brute{"BruteForce", {}}, tree{"QuadTree, leaf 8", {}};
    for (const bench::EncodingRow& r : rows) {
      auto seed = [](double v) { return v > 0 ? std::to_string(v).substr(0, std::to_string(v).find('.') + 2) : std::string("-"); };
      std::printf("| %s | %.1f | %.1f | %.1f | %s | %s | %.3f | %.3f | %.1f | %llu |\n", r.encoding.c_str(),
                  r.brute_min_ms * scale, r.brute_median_ms * scale, r.brute_bytes, seed(r.seed_ms).c_str(),
                  seed(r.seed_bytes).c_str(), r.tree_min_ms * scale, r.tree_median_ms * scale, r.tree_bytes,
                  (unsigned long long)r.disagreements);
      csv << r.encoding << "," << r.brute_min_ms * scale << "," << r.brute_median_ms * scale << "," << r.brute_bytes
          << "," << r.seed_ms << "," << r.seed_bytes << "," << r.tree_min_ms * scale << "," << r.tree_median_ms * scale
          << "," << r.tree_bytes << "," << r.disagreements << "\n";
      brute.points.push_back({r.brute_bytes, r.brute_min_ms * 1000.0 / double(args->rays), r.encoding});
      tree.points.push_back({r.tree_bytes, r.tree_min_ms * 1000.0 / double(args->rays), r.encoding});
    }
    std::string png = args->out_dir + "/encodings.png";
    std::string why = bench::plot_scatter(png, "Triangle encodings on " + args->input + " (minimum of passes)",
                                          "bytes per triangle (blocks + shared vertices)", "microseconds per ray",
                                          {brute, tree}, true);
    csv.commit();
    std::printf("\ncsv: %s\nplot: %s\n", csv_path.c_str(), why.empty() ? png.c_str() : why.c_str());
  });
}

// Seed 000 §4.1, §4.2, §4.3 and §6: one subcommand a table.
void add_bench_tables(CLI::App* bench) {
  // §4.1, §4.2, §4.3 and §6: the same columns, one table each, a CSV and a
  // plot of time per ray against walked bytes per triangle.
  struct Table { const char* name; const char* what; };
  const Table tables[] = {
      {"splitters", "Rouwe 2019, 4.1: every splitter, AABBTree with Float3 and Float3SOA4, leaf 8"},
      {"leafsize", "Rouwe 2019, 4.2: leaf sizes 4, 8, 16, AABBTree/Float3, Binning"},
      {"order", "Rouwe 2019, 4.3: the four node orders, QuadTree and QuadTreeHalfFloat with Float3"},
      {"trees", "Rouwe 2019, 6: every tree format with Float3, Binning, leaf 8"},
      {"combos", "Rouwe 2019, 6: every tree with every CPU triangle encoding"}};
  for (const Table& table : tables) {
    auto targs = std::make_shared<BenchArgs>();
    CLI::App* sub = bench->add_subcommand(table.name, table.what);
    sub->add_option("mesh", targs->input, "mesh file, or terrain_2M for the generated 2M-triangle terrain (default data/bunny00.off)");
    sub->add_option("--rays", targs->rays, "long random rays (the source used 1024)")->check(integer_in(1, 1000000));
    sub->add_option("--repeat", targs->repeat, "passes; minimum and median reported")->check(integer_in(1, 1000));
    sub->add_option("--out-dir", targs->out_dir, "where the CSV and the plot go");
    if (std::string(table.name) == "combos")
      sub->add_option("--only", targs->only, "only the layouts whose name contains one of these, comma separated");
    std::string kind = table.name;
    sub->callback([targs, kind] {
      Mesh mesh = bench_mesh(targs->input);
      std::filesystem::create_directories(targs->out_dir);
      std::vector<bench::TreeRow> rows =
          kind == "splitters" ? bench::bench_splitters(mesh, targs->input, targs->rays, targs->repeat)
          : kind == "leafsize" ? bench::bench_leafsize(mesh, targs->input, targs->rays, targs->repeat)
          : kind == "order"    ? bench::bench_order(mesh, targs->input, targs->rays, targs->repeat)
          : kind == "combos"   ? bench::bench_combos(mesh, targs->input, targs->rays, targs->repeat, targs->only)
                               : bench::bench_trees(mesh, targs->input, targs->rays, targs->repeat);
      // Microseconds per ray, the unit of the source's "Time 1024 Rays (us)" columns.
      double scale = 1000.0 / double(targs->rays);
      std::printf("\n%s, %zu triangles, %zu long rays, one thread; us per ray (minimum of %u passes, median "
                  "beside it); seed column: Rouwe 2019 (i7-7700HQ)\n\n",
                  targs->input.c_str(), mesh.triangles.size(), targs->rays, targs->repeat);
      const char* label = kind == "splitters" ? "splitter" : kind == "leafsize" ? "leaf size" : kind == "order" ? "order" : "tree";
      std::printf("| %s | layout | us/ray (min) | median | seed | build ms | SAH cost | tree bytes (seed) | tree B/tri | "
                  "walked B/tri (seed) | holes B/tri | disagreements |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
                  label);
      std::string stem = targs->out_dir + "/" + kind + (targs->input == "terrain_2M" ? "_terrain_2M" : "");
      OutputText csv(stem + ".csv");
      csv << "label,layout,min_us_per_ray,median_us_per_ray,seed_us_per_ray,build_ms,sah_cost,tree_bytes_per_tri,"
             "walked_bytes_per_tri,seed_bytes_per_tri,hole_bytes_per_tri,disagreements\n";
      // One series (colour) per tree format, each point labelled.
      std::vector<bench::Series> series;
      for (const bench::TreeRow& r : rows) {
        const bench::Timing& t = r.timing;
        if (!r.refused.empty()) {
          std::printf("| %s | %s | refused: %s |\n", r.label.c_str(), r.layout.c_str(), r.refused.c_str());
          csv << r.label << "," << r.layout << ",,,,,,,,,,refused\n";
          continue;
        }
        std::string seed_bytes = r.seed_tree_bytes > 0 ? " (" + std::to_string(uint64_t(r.seed_tree_bytes)) + ")" : "";
        char seed_walked[32] = "", seed_ms[32] = "-";
        if (r.seed_bytes_per_tri > 0) std::snprintf(seed_walked, sizeof seed_walked, " (%.1f)", r.seed_bytes_per_tri);
        if (r.seed_ms > 0) std::snprintf(seed_ms, sizeof seed_ms, "%g", r.seed_ms);
        std::printf("| %s | %s | %.3f | %.3f | %s | %.0f | %.1f | %.0f%s | %.2f | %.2f%s | %.2f | %llu |\n", r.label.c_str(),
                    r.layout.c_str(), t.min_ms * scale, t.median_ms * scale, seed_ms, t.build_ms, t.sah_cost,
                    t.tree_bytes * double(mesh.triangles.size()), seed_bytes.c_str(), t.tree_bytes, t.walked_bytes,
                    seed_walked, t.hole_bytes, (unsigned long long)t.disagreements);
        csv << r.label << "," << r.layout << "," << t.min_ms * scale << "," << t.median_ms * scale << "," << r.seed_ms
            << "," << t.build_ms << "," << t.sah_cost << "," << t.tree_bytes << "," << t.walked_bytes << ","
            << r.seed_bytes_per_tri << "," << t.hole_bytes << "," << t.disagreements << "\n";
        std::string tree = r.layout.substr(0, r.layout.find('/'));
        std::string point = kind == "combos" ? r.layout.substr(r.layout.find('/') + 1) : r.label;
        if (series.empty() || series.back().title != tree) series.push_back({tree, {}});
        series.back().points.push_back({t.walked_bytes, t.min_ms * 1000.0 / double(targs->rays), point});
      }
      std::string png = stem + ".png";
      std::string why = bench::plot_scatter(png, std::string(kind) + " on " + targs->input + " (minimum of passes)",
                                            "bytes per triangle walked (nodes, blocks, vertices)", "microseconds per ray",
                                            series, kind == "combos", kind == "combos" || kind == "trees");
      csv.commit();
      std::printf("\ncsv: %s.csv\nplot: %s\n", stem.c_str(), why.empty() ? png.c_str() : why.c_str());
    });
  }
}

// "1k", "16k", "1M", "4096": a batch size as --sizes takes it.
uint64_t parse_size(const std::string& text) {
  size_t used = 0;
  uint64_t n = 0;
  try {
    n = std::stoull(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string unit = text.substr(used);
  const uint64_t scale = unit == "" ? 1 : unit == "k" ? 1024 : unit == "M" ? 1024 * 1024 : 0;
  if (used == 0 || scale == 0 || n == 0 || n * scale > (uint64_t(1) << 26))
    throw CLI::ValidationError("--sizes", "'" + text + "' is not a batch size from 1 to 64M (a number, or with k or M)");
  return n * scale;
}

// The batch-size sweep: a table, a CSV and a plot of rays a second.
void print_gpu_scale(const bench::GpuScaleResult& res, const std::string& mesh_name, size_t triangles, uint32_t repeat,
                     const std::string& out_dir) {
  std::printf("\n%s, %zu triangles, long random rays, method %s on %s, device: %s; median of %u passes a size. "
              "device: GPU timestamps; wall: submit() until the hits are readable in host-visible memory, one batch; "
              "stream: %u batches in flight, each slot refilled as it is read; host: the submitting thread's CPU time "
              "in rays(), submit() and hits(), waits left out; copy: the bench writing its rays into the mapped "
              "buffer; CPU: BlobView::trace on %u threads of this machine; differ: rays whose triangle is not the "
              "CPU's\n\n"
              "| rays | device ms | wall ms | device Grays/s | wall Grays/s | stream Grays/s | host ns/ray | copy ns/ray "
              "| CPU ms | CPU Grays/s | differ |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
              mesh_name.c_str(), triangles, res.method.c_str(), res.layout.c_str(), res.device.c_str(), repeat,
              res.frames, res.cpu_threads);
  std::filesystem::create_directories(out_dir);
  const std::string stem = out_dir + "/gpu_scale";
  OutputText csv(stem + ".csv");
  csv << "rays,device_ms,wall_ms,device_rays_per_s,wall_rays_per_s,stream_rays_per_s,host_ns_per_ray,copy_ns_per_ray,"
         "cpu_ms,cpu_rays_per_s,differ\n";
  std::vector<bench::Series> series = {{"GPU device", {}}, {"GPU wall, one batch", {}}, {"GPU stream", {}},
                                       {"CPU, every core", {}}};
  auto per_s = [](uint64_t rays, double ms) { return ms > 0 ? double(rays) / (ms * 1e-3) : 0.0; };
  for (const bench::GpuScaleRow& r : res.rows) {
    const double device = per_s(r.rays, r.device_ms), wall = per_s(r.rays, r.wall_ms), cpu = per_s(r.rays, r.cpu_ms);
    std::printf("| %llu | %.3f | %.3f | %.4f | %.4f | %.4f | %.3f | %.3f | %.3f | %.4f | %llu |\n",
                (unsigned long long)r.rays, r.device_ms, r.wall_ms, device * 1e-9, wall * 1e-9,
                r.stream_rays_per_s * 1e-9, r.host_ns_per_ray, r.copy_ns_per_ray, r.cpu_ms, cpu * 1e-9,
                (unsigned long long)r.differ);
    csv << r.rays << "," << r.device_ms << "," << r.wall_ms << "," << device << "," << wall << "," << r.stream_rays_per_s
        << "," << r.host_ns_per_ray << "," << r.copy_ns_per_ray << "," << r.cpu_ms << "," << cpu << "," << r.differ << "\n";
    const double x = double(r.rays);
    if (device > 0) series[0].points.push_back({x, device, ""});
    series[1].points.push_back({x, wall, ""});
    series[2].points.push_back({x, r.stream_rays_per_s, ""});
    series[3].points.push_back({x, cpu, ""});
  }
  csv.commit();
  const std::string png = stem + ".png";
  const std::string why = bench::plot_scatter(png, "rays a second against batch size, " + res.device, "rays a batch",
                                              "rays a second", series, true, true, true);
  std::printf("\ncsv: %s.csv\nplot: %s\n", stem.c_str(), why.empty() ? png.c_str() : why.c_str());
}

// Seed 000 §7 on this machine's Vulkan device, then the batch-size sweep.
void add_bench_gpu(CLI::App* bench) {
  auto gargs = std::make_shared<BenchArgs>();
  auto gdevice = std::make_shared<std::string>();
  auto gsizes = std::make_shared<std::vector<std::string>>(std::vector<std::string>{"1k", "16k", "256k", "1M", "4M", "16M"});
  CLI::App* gsub = bench->add_subcommand("gpu", "Rouwe 2019, 7: the GPU methods on the Vulkan device, the CPU's best "
                                                "beside them; then batches from 1k to 16M rays against every core");
  gsub->add_option("mesh", gargs->input, "mesh file (default data/bunny00.off)");
  gsub->add_option("--rays", gargs->rays, "long random rays (the source used 1024)")->check(integer_in(1, 1000000));
  gsub->add_option("--repeat", gargs->repeat, "passes; the median is reported")->check(integer_in(1, 1000));
  gsub->add_option("--device", *gdevice, "Vulkan device: index or part of its name");
  gsub->add_option("--sizes", *gsizes, "the sweep's batch sizes (1k = 1024, 1M = 1048576), comma separated")
      ->delimiter(',');
  gsub->add_option("--out-dir", gargs->out_dir, "where gpu_scale.csv and gpu_scale.png go");
  gsub->callback([gargs, gdevice, gsizes] {
    std::vector<uint64_t> sizes;
    for (const std::string& text : *gsizes) sizes.push_back(parse_size(text));
    Mesh mesh = bench_mesh(gargs->input);
    std::string device;
    std::vector<bench::GpuRow> rows = bench::bench_gpu(mesh, gargs->input, gargs->rays, gargs->repeat, *gdevice, &device);
    std::printf("\n%s, %zu triangles, %zu long rays, device: %s; us per ray, median of %u passes (device: GPU "
                "timestamps; wall: copy into the mapped buffer, submission and read-back); leaf 4 as the source's GPU table; any / closest, "
                "all / closest: each query's time (device, else wall) on the same rays, all hits in rows of 16\n\n"
                "| method | layout | us/ray device | us/ray wall | walked B/tri | seed (GTX 1050, DX11) | disagreements "
                "| any / closest | all / closest |\n"
                "|---|---|---:|---:|---:|---|---:|---:|---:|\n",
                gargs->input.c_str(), mesh.triangles.size(), gargs->rays, device.c_str(), gargs->repeat);
    for (const bench::GpuRow& r : rows)
      std::printf("| %s | %s | %s | %.3f | %.2f | %s | %llu | %.2f | %.2f |\n", r.method.c_str(), r.layout.c_str(),
                  r.device_us > 0 ? std::to_string(r.device_us).substr(0, std::to_string(r.device_us).find('.') + 4).c_str() : "-",
                  r.wall_us, r.bytes, r.seed.empty() ? "-" : r.seed.c_str(), (unsigned long long)r.disagreements,
                  r.any_to_closest, r.all_to_closest);
    std::fflush(stdout);
    const bench::GpuScaleResult scale = bench::bench_gpu_scale(mesh, gargs->input, sizes, gargs->repeat, *gdevice);
    print_gpu_scale(scale, gargs->input, mesh.triangles.size(), gargs->repeat, gargs->out_dir);
  });
}

// The host layer's latency against batch size.
void add_bench_latency(CLI::App* bench) {
  auto largs = std::make_shared<BenchArgs>();
  auto lopts = std::make_shared<std::pair<std::string, double>>("", 16.7);  // device, frame ms
  CLI::App* lat = bench->add_subcommand("latency", "the host layer: batch latency from 1 to 65,536 rays, CPU and Vulkan");
  lat->add_option("mesh", largs->input, "mesh file, or terrain_2M (default data/bunny00.off)");
  lat->add_option("--device", lopts->first, "Vulkan device: index or part of its name");
  lat->add_option("--frame-ms", lopts->second, "the frame of other work in the frame-ahead columns")->check(number_in(0, 1000));
  lat->add_option("--out-dir", largs->out_dir, "where the CSV and the plot go");
  lat->callback([largs, lopts] {
    Mesh mesh = bench_mesh(largs->input);
    bench::LatencyResult res = bench::bench_latency(mesh, largs->input, lopts->second, lopts->first);
    std::printf("\n%s, %zu triangles, %s, long rays; Vulkan device: %s%s; CPU: %u threads\n"
                "latency: submit() until the hits are ready, back to back; frame ahead: submit, %.1f ms of other work "
                "on the submitting thread, collect (10 frames)\n\n"
                "| backend | batch | batches | p50 ms | p99 ms | rays/s | GPU device ms | frame ahead: ready | frame ahead rays/s |\n"
                "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
                largs->input.c_str(), mesh.triangles.size(), res.layout.c_str(), res.device.c_str(),
                res.gpu_error.empty() ? "" : (" (" + res.gpu_error + ")").c_str(), res.threads, lopts->second);
    std::filesystem::create_directories(largs->out_dir);
    std::string stem = largs->out_dir + "/latency" + (largs->input == "terrain_2M" ? "_terrain_2M" : "");
    OutputText csv(stem + ".csv");
    csv << "backend,batch,batches,p50_ms,p99_ms,rays_per_second,device_ms,frame_ahead_ready,frame_ahead_rays_per_second\n";
    std::vector<bench::Series> series;
    double lo = 1e30, hi = 0;
    for (const bench::LatencyRow& r : res.rows) {
      std::printf("| %s | %u | %u | %.3f | %.3f | %.3g | %s | %.0f%% | %.3g |\n", r.backend.c_str(), r.batch, r.batches,
                  r.p50_ms, r.p99_ms, r.rays_per_second, r.device_ms > 0 ? std::to_string(r.device_ms).substr(0, 6).c_str() : "-",
                  100 * r.ready_share, r.ahead_rays_per_second);
      csv << r.backend << "," << r.batch << "," << r.batches << "," << r.p50_ms << "," << r.p99_ms << "," << r.rays_per_second
          << "," << r.device_ms << "," << r.ready_share << "," << r.ahead_rays_per_second << "\n";
      if (series.empty() || series.back().title != r.backend) series.push_back({r.backend, {}});
      series.back().points.push_back({double(r.batch), r.p50_ms, ""});
      lo = std::min(lo, r.p50_ms), hi = std::max(hi, r.p99_ms);
    }
    std::printf("\ncrossover (automatic backend, measured at its start-up): %s\n  %s\n  %s\n",
                res.crossover == ~0u ? "none, the CPU finished every size first" : (std::to_string(res.crossover) + " rays").c_str(),
                res.why_small.c_str(), res.why_large.c_str());
    if (res.crossover != ~0u)
      series.push_back({"crossover (" + std::to_string(res.crossover) + " rays)",
                        {{double(res.crossover), lo, "crossover"}, {double(res.crossover), hi, ""}}});
    std::string png = stem + ".png";
    const std::string title = "batch latency (p50) on " + largs->input + ", Vulkan device: " + res.device +
                              (res.crossover == ~0u ? " (no crossover: the CPU first at every size)" : "");
    std::string why = bench::plot_scatter(png, title,
                                          "rays in the batch", "milliseconds, submit to ready", series, true, true, true);
    csv.commit();
    std::printf("csv: %s.csv\nplot: %s\n", stem.c_str(), why.empty() ? png.c_str() : why.c_str());
  });
}

// Error against run time and bytes.
void add_bench_error(CLI::App* bench) {
  auto eargs = std::make_shared<BenchArgs>();
  auto emeshes = std::make_shared<std::vector<std::string>>();
  auto edevice = std::make_shared<std::string>();
  CLI::App* err = bench->add_subcommand("error", "error against run time and bytes, every tree x encoding (and GPU method)");
  err->add_option("meshes", *emeshes, "mesh files or terrain_2M (default bunny00, ChineseDragon-10kv, terrain_2M)");
  err->add_option("--rays", eargs->rays, "long random rays")->check(integer_in(1, 1000000));
  err->add_option("--repeat", eargs->repeat, "passes; the minimum is kept (GPU: the median)")->check(integer_in(1, 1000));
  err->add_option("--device", *edevice, "also the GPU methods on this Vulkan device (any: the default one)");
  err->add_option("--out-dir", eargs->out_dir, "where the CSV and the plots go");
  err->callback([eargs, emeshes, edevice] {
    std::vector<std::string> names = *emeshes;
    if (names.empty()) names = {"data/bunny00.off", "data/ChineseDragon-10kv.off", "terrain_2M"};
    std::vector<bench::NamedInput> inputs;
    for (const std::string& n : names) inputs.push_back({n, bench_mesh(n)});
    std::vector<bench::ErrorRow> rows = bench::bench_error(inputs, eargs->rays, eargs->repeat, *edevice);
    std::filesystem::create_directories(eargs->out_dir);
    OutputText csv(eargs->out_dir + "/error.csv");
    csv << "mesh,backend,layout,us_per_ray,bytes_per_tri,max_dt,mean_dt,max_surface,bound,rays,false_misses,false_hits,"
           "wrong_triangles\n";
    std::printf("\n%zu long rays a mesh, one thread (GPU: device time); errors relative to the mesh diagonal against the "
                "double-precision oracle on the input mesh; bound: the format's stated largest corner move\n\n"
                "| mesh | backend | layout | us/ray | B/tri | max dt | mean dt | max surface | bound | false misses | false "
                "hits | wrong triangles |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
                eargs->rays);
    std::map<std::string, bench::Series> by_time, by_bytes;
    for (const bench::ErrorRow& r : rows) {
      std::printf("| %s | %s | %s | %.3f | %.2f | %.2e | %.2e | %.2e | %.2e | %llu | %llu | %llu |\n", r.mesh.c_str(),
                  r.backend.c_str(), r.layout.c_str(), r.us_per_ray, r.bytes_per_tri, r.max_dt, r.mean_dt, r.max_surface,
                  r.bound, (unsigned long long)r.false_misses, (unsigned long long)r.false_hits,
                  (unsigned long long)r.wrong_triangles);
      csv << r.mesh << ",\"" << r.backend << "\"," << r.layout << "," << r.us_per_ray << "," << r.bytes_per_tri << ","
          << r.max_dt << "," << r.mean_dt << "," << r.max_surface << "," << r.bound << "," << r.rays << ","
          << r.false_misses << "," << r.false_hits << "," << r.wrong_triangles << "\n";
      // A log axis has no 0: errors below 1e-12 are drawn at 1e-12.
      double y = std::max(r.max_surface, 1e-12);
      std::string series = r.mesh + (r.backend.rfind("Vulkan", 0) == 0 ? " (Vulkan)" : "");
      by_time[series].title = by_bytes[series].title = series;
      by_time[series].points.push_back({r.us_per_ray, y, ""});
      by_bytes[series].points.push_back({r.bytes_per_tri, y, ""});
    }
    // The Pareto front of each series: no other point both faster (smaller) and more exact.
    auto with_fronts = [](const std::map<std::string, bench::Series>& all) {
      std::vector<bench::Series> out;
      for (const auto& [name, s] : all) {
        out.push_back(s);
        std::vector<bench::Point> pts = s.points;
        std::sort(pts.begin(), pts.end(), [](const bench::Point& a, const bench::Point& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
        bench::Series front{name + ": Pareto front", {}};
        double best = INFINITY;
        for (const bench::Point& p : pts)
          if (p.y < best) best = p.y, front.points.push_back(p);
        out.push_back(front);
      }
      return out;
    };
    std::string png1 = eargs->out_dir + "/error_time.png", png2 = eargs->out_dir + "/error_bytes.png";
    std::string why1 = bench::plot_scatter(png1, "Error against time a ray", "microseconds per ray (log)",
                                           "largest distance of a hit from the input surface / diagonal (log)",
                                           with_fronts(by_time), true, true);
    std::string why2 = bench::plot_scatter(png2, "Error against bytes a triangle", "bytes per triangle walked (log)",
                                           "largest distance of a hit from the input surface / diagonal (log)",
                                           with_fronts(by_bytes), true, true);
    size_t above = 0;
    for (const bench::ErrorRow& r : rows)
      if (r.max_surface > r.bound) {
        std::printf("above its bound: %s %s %s (%.2e > %.2e)\n", r.mesh.c_str(), r.backend.c_str(), r.layout.c_str(),
                    r.max_surface, r.bound);
        ++above;
      }
    std::printf("\n%zu of %zu rows within their format's stated bound\n", rows.size() - above, rows.size());
    csv.commit();
    std::printf("\ncsv: %s/error.csv\nplots: %s, %s\n", eargs->out_dir.c_str(), why1.empty() ? png1.c_str() : why1.c_str(),
                why2.empty() ? png2.c_str() : why2.c_str());
  });
}

// The watertight test against Moller-Trumbore.
void add_bench_robustness(CLI::App* bench) {
  auto rargs = std::make_shared<BenchArgs>();
  CLI::App* rob = bench->add_subcommand("robustness", "the watertight test against plain Moller-Trumbore, time and leaks");
  rob->add_option("mesh", rargs->input, "mesh file, or terrain_2M (default data/bunny00.off)");
  rob->add_option("--rays", rargs->rays, "long random rays")->check(integer_in(1, 1000000));
  rob->add_option("--repeat", rargs->repeat, "passes; the minimum and the median are kept")->check(integer_in(1, 1000));
  rob->callback([rargs] {
    Mesh mesh = bench_mesh(rargs->input);
    std::vector<bench::RobustnessRow> rows = bench::bench_robustness(mesh, rargs->input, rargs->rays, rargs->repeat);
    const double scale = 1000.0 / double(rargs->rays);
    std::printf("\n%s, %zu triangles, %zu long rays, one thread; us per ray, minimum of %u passes, both tests in this "
                "run; leaks: rays from inside a closed sphere (96 rings, 192 segments) aimed at its vertices and edge midpoints "
                "that miss\n\n| layout | us/ray watertight | us/ray Moller-Trumbore | watertight / plain | disagreements "
                "(watertight, plain) | leaks watertight | leaks plain |\n|---|---:|---:|---:|---|---:|---:|\n",
                rargs->input.c_str(), mesh.triangles.size(), rargs->rays, rargs->repeat);
    for (const bench::RobustnessRow& r : rows)
      std::printf("| %s | %.3f | %.3f | %.2f | %llu, %llu | %llu of %llu | %llu of %llu |\n", r.layout.c_str(),
                  r.watertight.min_ms * scale, r.plain.min_ms * scale, r.watertight.min_ms / r.plain.min_ms,
                  (unsigned long long)r.watertight.disagreements, (unsigned long long)r.plain.disagreements,
                  (unsigned long long)r.leaks_watertight, (unsigned long long)r.probes,
                  (unsigned long long)r.leaks_plain, (unsigned long long)r.probes);
  });
}

// t, u, v and hit points against exact arithmetic, mesh by mesh.
void add_bench_exactness(CLI::App* bench) {
  auto meshes = std::make_shared<std::vector<std::string>>();
  auto rays = std::make_shared<size_t>(2000);
  CLI::App* cmd = bench->add_subcommand("exactness", "t, u, v and hit points against exact rational arithmetic, "
                                                     "every ray kind and query, grazing rays too");
  cmd->add_option("meshes", *meshes, "mesh files (default data/*.off)");
  cmd->add_option("--rays", *rays, "rays of each kind")->check(integer_in(1, 1000000));
  cmd->callback([meshes, rays] {
    std::vector<std::string> paths = *meshes;
    if (paths.empty()) {
      if (!std::filesystem::is_directory("data")) throw InputError("data/: no meshes to measure (scripts/fetch_meshes.sh)");
      for (const auto& e : std::filesystem::directory_iterator("data"))
        if (e.path().extension() == ".off") paths.push_back(e.path().string());
      std::sort(paths.begin(), paths.end());
    }
    std::printf("\nt against the exact distance to the stored triangle's plane (ulps of the exact t; 0.5: correctly "
                "rounded), u and v (absolute), the hit point against o + t d at the exact t (ulps of the largest "
                "coordinate of o, t d and the point); the closest hit, any hit and every hit together, %zu rays a kind\n\n"
                "| mesh | layout | rays | hits | t correctly rounded | t, largest error (ulps) | u, v largest error | "
                "point, largest error (ulps) |\n|---|---|---|---:|---:|---:|---:|---:|\n", *rays);
    ExactnessTotals totals;
    for (const std::string& path : paths) {
      Mesh mesh;
      try {
        mesh = bench_mesh(path);
      } catch (const InputError& e) {  // a mesh the library refuses has no hits to measure
        std::printf("| %s | (refused: %s) | | | | | | |\n", path.c_str(), e.what());
        continue;
      }
      if (mesh.triangles.empty()) continue;
      const std::string name = std::filesystem::path(path).stem().string();
      for (const bench::ExactnessRow& r : bench::bench_exactness(mesh, name, *rays)) {
        std::printf("| %s | %s | %s | %llu | %llu | %.3f | %.3g | %.3f |\n", r.mesh.c_str(), r.layout.c_str(), r.rays.c_str(),
                    (unsigned long long)r.hits, (unsigned long long)r.rounded, r.t_ulps, r.uv, r.point_ulps);
        totals.add(r);
      }
      std::fflush(stdout);
    }
    std::printf("\n%zu meshes: %llu hits, %llu with t correctly rounded; largest t error %.3f ulps, u or v %.3g, "
                "point %.3f ulps\n", paths.size(), (unsigned long long)totals.hits, (unsigned long long)totals.rounded,
                totals.t_ulps, totals.uv, totals.point_ulps);
  });
}

// Seed 003: triangle pairing.
void add_bench_pairing(CLI::App* bench) {
  auto pargs = std::make_shared<BenchArgs>();
  auto pdata = std::make_shared<std::string>("data");
  CLI::App* pair = bench->add_subcommand("pairing", "Aman and Fenney's triangle pairing, before and after, as the builder's unit");
  pair->add_option("--data", *pdata, "folder of the public meshes (bunny00, armadillo, refined_elephant, ChineseDragon-10kv)");
  pair->add_option("--rays", pargs->rays, "long random rays")->check(integer_in(1, 1000000));
  pair->add_option("--repeat", pargs->repeat, "passes; the minimum and the median are kept")->check(integer_in(1, 1000));
  pair->add_option("--out-dir", pargs->out_dir, "where the CSV goes");
  auto ponly = std::make_shared<std::vector<std::string>>();
  pair->add_option("--only", *ponly, "comma-separated cases by the start of their names (bunny00 with its shuffled and "
                  "rotated copies, armadillo, terrain_2M, ...)")
      ->delimiter(',');
  pair->callback([pargs, pdata, ponly] {
    std::vector<bench::PairingRow> rows;
    try {
      rows = bench::bench_pairing(*pdata, pargs->rays, pargs->repeat, *ponly);
    } catch (const UsageError& e) {  // --only named no case: a refused value (exit 2)
      throw CLI::ValidationError("--only", e.what());
    }
    const double scale = 1000.0 / double(pargs->rays);
    std::printf("\n%zu long rays, one thread, leaf 8; us per ray, minimum of %u passes; paired: before = input order "
                "(window N = 2), after = the pass (or the input's pairs when the pre-scan skips it)\n\n"
                "| mesh | triangles | pairing ms | paired before | after | layout | us/ray | paired | change | walked B/tri | "
                "paired | box tests/ray | paired | triangle tests/ray | paired | disagreements |\n"
                "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
                pargs->rays, pargs->repeat);
    std::filesystem::create_directories(pargs->out_dir);
    OutputText csv(pargs->out_dir + "/pairing.csv");
    csv << "mesh,triangles,pairing_ms,paired_before,paired_after,decision,layout,us_per_ray,us_per_ray_paired,"
           "walked_bytes,walked_bytes_paired,box_tests,box_tests_paired,triangle_tests,triangle_tests_paired,disagreements\n";
    // Test counts exist in a counting build alone (MESHCAST_COUNT_TESTS).
    auto count = [](double v) {
      char text[32];
      if (v < 0) return std::string("-");
      std::snprintf(text, sizeof text, "%.1f", v);
      return std::string(text);
    };
    for (const bench::PairingRow& r : rows) {
      const double plain = r.plain.min_ms * scale, paired = r.paired.min_ms * scale;
      const uint64_t wrong = r.plain.disagreements + r.paired.disagreements;
      std::printf("| %s | %zu | %.1f | %.1f%% | %.1f%% | %s | %.3f | %.3f | %+.1f%% | %.2f | %.2f | %s | %s | %s | %s | %llu |\n",
                  r.mesh.c_str(), r.triangles, r.pairing_ms, 100 * r.before, 100 * r.after, r.layout.c_str(), plain, paired,
                  100 * (paired / plain - 1), r.plain.walked_bytes, r.paired.walked_bytes,
                  count(r.plain.boxes_per_ray).c_str(), count(r.paired.boxes_per_ray).c_str(),
                  count(r.plain.triangles_per_ray).c_str(), count(r.paired.triangles_per_ray).c_str(),
                  (unsigned long long)wrong);
      csv << r.mesh << "," << r.triangles << "," << r.pairing_ms << "," << r.before << "," << r.after << ",\"" << r.decision
          << "\"," << r.layout << "," << plain << "," << paired << "," << r.plain.walked_bytes << "," << r.paired.walked_bytes
          << "," << r.plain.boxes_per_ray << "," << r.paired.boxes_per_ray << "," << r.plain.triangles_per_ray << ","
          << r.paired.triangles_per_ray << "," << wrong << "\n";
    }
    std::printf("\ndecisions:\n");
    for (size_t i = 0; i < rows.size(); i += 2) std::printf("  %s: %s\n", rows[i].mesh.c_str(), rows[i].decision.c_str());
    csv.commit();
    std::printf("csv: %s/pairing.csv\n%s\n", pargs->out_dir.c_str(),
                kCountTests ? "test counts: one more pass with the counters (this build counts; its times are not for comparison)"
                            : "test counts: '-' (build with -DMESHCAST_COUNT_TESTS=ON to count them)");
  });
}

// The half-float tree far from the origin.
void add_bench_offset(CLI::App* bench) {
  auto oargs = std::make_shared<BenchArgs>();
  CLI::App* off = bench->add_subcommand("offset", "QuadTreeHalfFloat far from the origin: 0.15 units at 1000, 150 at 30000");
  off->add_option("mesh", oargs->input, "mesh file (default data/bunny00.off), scaled to each case's size");
  off->add_option("--rays", oargs->rays, "long random rays")->check(integer_in(1, 1000000));
  off->add_option("--repeat", oargs->repeat, "passes a measurement (3 measurements each, interleaved)")->check(integer_in(1, 1000));
  off->callback([oargs] {
    Mesh mesh = bench_mesh(oargs->input);
    std::vector<bench::OffsetRow> rows = bench::bench_offset(mesh, oargs->input, oargs->rays, oargs->repeat);
    double scale = 1000.0 / double(oargs->rays);
    std::printf("\n%s scaled and moved, %zu long rays; us per ray, minimum over 3 interleaved measurements of %u "
                "passes each, in this one run\n\n| layout | mesh | at the origin | moved | ratio | disagreements |\n"
                "|---|---|---:|---:|---:|---:|\n",
                oargs->input.c_str(), oargs->rays, oargs->repeat);
    for (const bench::OffsetRow& r : rows)
      std::printf("| %s | %s | %.3f | %.3f | %.2f | %llu |\n", r.layout.c_str(), r.mesh.c_str(), r.origin.min_ms * scale,
                  r.offset.min_ms * scale, r.offset.min_ms / r.origin.min_ms,
                  (unsigned long long)(r.origin.disagreements + r.offset.disagreements));
  });
}

}  // namespace

void add_bench(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "measure meshcast: speed, bytes, error, beside Embree where installed");
  bench->require_subcommand(1);
  add_bench_auto(bench);
  add_bench_peers(bench);
  add_bench_scenes(bench);
  add_bench_encodings(bench);
  add_bench_tables(bench);
  add_bench_gpu(bench);
  add_bench_latency(bench);
  add_bench_error(bench);
  add_bench_robustness(bench);
  add_bench_exactness(bench);
  add_bench_pairing(bench);
  add_bench_offset(bench);
  // Each bench runs for minutes: a line on a terminal says it is running
  // (main ends it before printing anything of its own).
  for (CLI::App* sub : bench->get_subcommands({}))
    sub->preparse_callback([sub](size_t) { begin_command_progress("meshcast bench " + sub->get_name()); });
}

}  // namespace meshcast::tools
