// meshcast trace MESH|BLOB --rays R.rays --out H.hits [--query closest|any|all]
// [--max-hits N] [--cull none|back|front] [--t-min T]: one thread, the whole batch cast
// --repeat times, the median pass reported per ray. --query all writes HITC
// (compact rows: the file's size follows the hits found).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>

#include "check/ray_files.h"
#include "meshcast/blob.h"
#include "gpu/method.h"
#include "gpu/scene.h"
#include "gpu/vulkan.h"
#include "host/chunks.h"
#include "host/jobs.h"
#include "layout/queries.h"
#include "tools/commands.h"
#include "tools/progress.h"
#include "tools/common.h"
#include "tools/render.h"
#include "tools/scene_file.h"

namespace meshcast::tools {

namespace {

struct TraceArgs {
  std::string input, rays, out;
  LayoutArgs layout;
  uint32_t repeat = 5;
  bool json = false;
  std::string backend = "cpu", method, device, query = "closest", cull = "none";  // method "": the blob's
  uint32_t max_hits = 16;
  float t_min = 0;
  uint32_t threads = 1;  // the CPU backend's, on a blob (0: every core)
};

// --t-min on every ray read (the rays files hold no t_min of their own). A
// ray whose t_max is below it is refused by the walk, as any ray with
// t_min past t_max: a counted miss.
template <class R>
void apply_t_min(std::vector<R>& rays, float t_min) {
  for (R& r : rays) r.tmin = t_min;
}

// trace on a scene file: RAYD or RAYS rays in, a HITI file out; on the
// CPU (one thread) or the Vulkan scene method (gpu/scene.h), whose meshes
// are built in the layout it reads unless --layout names another.
void trace_scene(TraceArgs a) {
  if (a.json) hide_progress();
  const Query query = layout::query_named(a.query, "--query");
  const Cull cull = layout::cull_named(a.cull, "--cull");
  if (query == Query::All)
    throw InputError("trace " + a.input + ": --query all on a scene has no hits file yet (the library answers it: Scene::trace_all_hits)");
  const bool vulkan = a.backend == "vulkan";
  if (vulkan && a.layout.layout == "auto") a.layout.layout = "OctTreeCompressed/ClusterBitPackSOA8";
  auto t0 = std::chrono::steady_clock::now();
  SceneFile file = load_scene_file(a.input, a.layout, a.json ? stderr : stdout);
  const double load_ms = ms_since(t0);
  // Double origins (RAYD) or float ones (RAYS: Scene's float-ray trace on
  // the CPU; the GPU method reads RAYD records, so they are widened).
  const bool double_origins = is_scene_rays_file(a.rays);
  std::vector<Ray> rays_f = double_origins ? std::vector<Ray>{} : read_rays(a.rays);
  std::vector<RayD> rays_d = double_origins ? read_scene_rays(a.rays) : std::vector<RayD>{};
  apply_t_min(rays_f, a.t_min), apply_t_min(rays_d, a.t_min);
  if (vulkan && !double_origins)
    std::transform(rays_f.begin(), rays_f.end(), std::back_inserter(rays_d), widened);
  const size_t ray_count = double_origins ? rays_d.size() : rays_f.size();
  std::vector<SceneHit> hits(ray_count);
  std::vector<double> pass_ms;
  uint64_t skipped = 0;
  std::string device = "CPU, one thread";
  if (vulkan) {
    gpu::Context ctx(gpu::DeviceChoice{a.device, false});
    device = ctx.device_name();
    gpu::SceneMethod method(ctx, layout::query_bits(query, cull));
    const std::shared_ptr<const SceneSnapshot> frame = file.scene.snapshot();
    for (uint32_t r = 0; r < a.repeat; ++r) {
      auto t1 = std::chrono::steady_clock::now();
      skipped = method.trace(*frame, rays_d, hits);
      pass_ms.push_back(ms_since(t1));
    }
  } else {
    for (uint32_t r = 0; r < a.repeat; ++r) {
      auto t1 = std::chrono::steady_clock::now();
      skipped = double_origins ? file.scene.trace(rays_d, hits, HitOutputs::None, query, cull)
                               : file.scene.trace(rays_f, hits, HitOutputs::None, query, cull);
      pass_ms.push_back(ms_since(t1));
    }
  }
  write_scene_hits(a.out, hits);
  size_t hit_count = 0;
  for (const SceneHit& h : hits) hit_count += h.instance != kNoHit;
  const double ns = ray_count == 0 ? 0 : median(pass_ms) * 1e6 / double(ray_count);
  if (a.json) {
    print_json({{"input", a.input}, {"meshes", file.mesh_names.size()}, {"instances", file.instances},
                {"blob_bytes", file.blob_bytes}, {"load_ms", load_ms}, {"device", device}, {"query", a.query},
                {"cull", a.cull}, {"t_min", a.t_min}, {"rays", ray_count}, {"hits", hit_count}, {"invalid_rays", skipped},
                {"repeat", a.repeat}, {"ns_per_ray", ns}});
    return;
  }
  std::printf("%s: %zu meshes (%llu blob bytes), %zu instances, loaded and built in %.1f ms\n", a.input.c_str(),
              file.mesh_names.size(), (unsigned long long)file.blob_bytes, file.instances, load_ms);
  std::printf("%zu rays, %zu hits, %llu invalid rays answered as misses\n", ray_count, hit_count,
              (unsigned long long)skipped);
  std::printf("cast on %s: %.1f ns/ray (median of %u passes, wall clock) -> %s\n", device.c_str(), ns, a.repeat,
              a.out.c_str());
}

}  // namespace

void add_trace(CLI::App& app) {
  auto args = std::make_shared<TraceArgs>();
  CLI::App* cmd = app.add_subcommand("trace", "cast a rays file against a mesh, blob or scene (.json), write a hits file");
  cmd->add_option("input", args->input, "mesh file (OFF, OBJ, PLY, STL), generated mesh (terrain_2M, terrain_66k, city_1M, terrain_20M), blob or scene file (.json: RAYD or RAYS rays in, HITI hits out)")->required();
  cmd->add_option("--rays", args->rays, "rays file")->required();
  cmd->add_option("--out", args->out, "hits file to write")->required();
  add_layout_options(cmd, args->layout);
  cmd->add_option("--repeat", args->repeat, "passes over the batch; the median is reported")->check(integer_in(1, 1000));
  cmd->add_flag("--json", args->json, "print the figures as one JSON object");
  cmd->add_option("--query", args->query,
                  "closest (the nearest hit), any (a hit, the walk ending at the first) or all (every hit along the "
                  "ray, nearest first, written as a HITC file: per ray the hits found, then the kept hits alone)")
      ->check(CLI::IsMember({"closest", "any", "all"}));
  const CLI::Option* max_hits =
      cmd->add_option("--max-hits", args->max_hits,
                      "--query all: the most hits a ray keeps (more are counted, not kept); memory and the file follow "
                      "the hits found")
          ->check(integer_in(1, kMaxHitsLimit));
  cmd->add_option("--cull", args->cull,
                  "none (two-sided), back or front: the face culled; the front face's corners run counter-clockwise "
                  "seen from the ray's origin")
      ->check(CLI::IsMember({"none", "back", "front"}));
  cmd->add_option("--t-min", args->t_min,
                  "the nearest t a hit may have, on every ray read (a hit needs t-min <= t <= t_max; default 0): "
                  "secondary rays from a surface skip it. A ray whose t_max is below it is an invalid ray (a miss)")
      ->check(number_in(0, INFINITY, true));
  cmd->add_option("--backend", args->backend, "cpu (one thread, or --threads) or vulkan")->check(CLI::IsMember({"cpu", "vulkan"}));
  cmd->add_option("--threads", args->threads,
                  "cpu, a mesh or blob: the threads the batch is split over, in chunks of rays (0: every core; default 1)")
      ->check(integer_in(0, 1024));
  // The methods and what each reads, from the one table (gpu/method_table.cpp).
  cmd->add_option("--method", args->method,
                  "GPU method (default: the one that reads the blob's layout; with --layout auto, a layout the named "
                  "method reads): " + gpu_methods_text() + ".");
  cmd->add_option("--device", args->device, "Vulkan device: index or part of its name (default $MESHCAST_VK_DEVICE, "
                                            "else the first discrete GPU)");
  cmd->callback([args, max_hits] {
    if (args->json) hide_progress();
    const Query query = layout::query_named(args->query, "--query");
    const Cull cull = layout::cull_named(args->cull, "--cull");
    // Given with a query that keeps one hit a ray, it would be ignored.
    if (max_hits->count() > 0 && query != Query::All)
      throw InputError("trace: --max-hits is for --query all (every hit); --query " + args->query + " keeps one hit a ray");
    if (args->threads != 1 && (args->backend != "cpu" || is_scene_file(args->input)))
      throw InputError("trace: --threads is for --backend cpu on a mesh or blob (scene files are cast on one thread)");
    if (is_scene_file(args->input)) {
      trace_scene(*args);
      return;
    }
    Loaded in = load_input_for(args->input, args->layout, args->backend, args->method);
    std::vector<Ray> rays = read_rays(args->rays);
    apply_t_min(rays, args->t_min);
    std::vector<Hit> hits(rays.size());
    HitLists lists;
    lists.max_hits = args->max_hits;
    std::vector<double> pass_ms, device_ms;
    uint64_t skipped = 0;
    std::string device = "CPU, one thread";
    if (args->backend == "vulkan") {
      gpu::Context ctx(gpu::DeviceChoice{args->device, false});
      device = ctx.device_name();
      // The query and culling are the method's specialization constants.
      const uint32_t flags = layout::query_bits(query, cull);
      std::unique_ptr<gpu::Method> method = gpu::make_method(ctx, args->method, in.blob, args->input, 1, flags, args->max_hits);
      // A batch beyond the device's buffers (Query::All's fixed device rows
      // above all) is the input's fault: refused before any pass, exit 2.
      if (const std::string why = method->refusal(uint32_t(rays.size())); !why.empty())
        throw InputError("trace " + args->rays + ": " + why + "; cast fewer rays" +
                         (query == Query::All ? " or lower --max-hits" : "") + ", or use --backend cpu");
      Progress progress("tracing " + std::to_string(rays.size()) + " rays x " + std::to_string(args->repeat) + " on " + device,
                        rays.size() > kProgressRays);
      for (uint32_t r = 0; r < args->repeat; ++r) {
        progress.set(double(r) / double(args->repeat));
        gpu::GpuTiming timing;
        skipped = query == Query::All ? method->trace_all_hits(rays, lists, &timing) : method->trace(rays, hits, &timing);
        pass_ms.push_back(timing.wall_ms), device_ms.push_back(timing.device_ms);
      }
    } else if (args->threads != 1) {
      // The batch split over a pool's threads, as the Python package splits
      // one: each pass is the whole batch's wall time.
      BlobView view(in.blob, args->input);
      host::WorkerPool pool(args->threads);
      device = "CPU, " + std::to_string(pool.threads()) + " threads";
      const host::Chunks plan = host::plan_chunks(rays.size(), pool.threads());
      std::vector<HitLists> parts(query == Query::All ? plan.chunks : 0);
      for (HitLists& part : parts) part.max_hits = args->max_hits;
      std::vector<uint64_t> refused(plan.chunks);
      for (uint32_t r = 0; r < args->repeat; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        host::for_each_chunk(plan, &pool, [&](size_t c) {
          const auto chunk_rays = std::span(rays).subspan(plan.begin(c), plan.end(c) - plan.begin(c));
          refused[c] = query == Query::All
                           ? view.trace_all_hits(chunk_rays, parts[c], HitOutputs::None, cull)
                           : view.trace(chunk_rays, std::span(hits).subspan(plan.begin(c), chunk_rays.size()),
                                        HitOutputs::None, query, cull);
        });
        pass_ms.push_back(ms_since(t0));
      }
      skipped = 0;
      for (uint64_t n : refused) skipped += n;
      lists.clear();
      for (const HitLists& part : parts) lists.append(part);
    } else {
      BlobView view(in.blob, args->input);
      Progress progress("tracing " + std::to_string(rays.size()) + " rays x " + std::to_string(args->repeat),
                        rays.size() > kProgressRays);
      // Closest and any hits in slices, to say how far a pass is (a slice
      // of a million rays takes long enough that the cut costs nothing).
      constexpr size_t kSlice = size_t(1) << 20;
      for (uint32_t r = 0; r < args->repeat; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        if (query == Query::All) {
          skipped = view.trace_all_hits(rays, lists, HitOutputs::None, cull);
        } else {
          skipped = 0;
          for (size_t at = 0; at < rays.size(); at += kSlice) {
            const size_t n = std::min(kSlice, rays.size() - at);
            skipped += view.trace(std::span(rays).subspan(at, n), std::span(hits).subspan(at, n), HitOutputs::None, query, cull);
            progress.set((double(r) * double(rays.size()) + double(at + n)) / (double(args->repeat) * double(rays.size())));
          }
        }
        pass_ms.push_back(ms_since(t0));
      }
    }
    // hit_count: rays that hit; Query::All also counts every hit found.
    size_t hit_count = 0, every_hit = 0;
    if (query == Query::All) {
      write_hit_lists(args->out, lists);
      for (uint32_t found : lists.found) hit_count += found != 0, every_hit += found;
    } else {
      write_hits(args->out, hits);
      for (const Hit& h : hits) hit_count += h.triangle != MC_NO_HIT;
    }
    const layout::BlobHeader& h = layout::header_of(in.blob.data());
    double ns = rays.empty() ? 0 : median(pass_ms) * 1e6 / double(rays.size());
    std::string layout = layout_name(h.tree_format, h.triangle_format);
    double device_ns = rays.empty() || device_ms.empty() ? 0 : median(device_ms) * 1e6 / double(rays.size());
    if (args->json) {
      print_json({{"input", args->input}, {"layout", layout}, {"device", device}, {"query", args->query},
                  {"cull", args->cull}, {"t_min", args->t_min}, {"every_hit", every_hit}, {"load_ms", in.load_ms},
                  {"build_ms", in.build_ms}, {"rays", rays.size()}, {"hits", hit_count}, {"invalid_rays", skipped},
                  {"repeat", args->repeat}, {"ns_per_ray", ns}, {"device_ns_per_ray", device_ns}});
    } else {
      std::printf("%s: %s, load %.1f ms, build %.1f ms\n", args->input.c_str(), layout.c_str(), in.load_ms,
                  in.build_ms);
      std::printf("%zu rays, %zu hits, %llu invalid rays answered as misses\n", rays.size(), hit_count,
                  (unsigned long long)skipped);
      std::printf("query %s, cull %s", args->query.c_str(), args->cull.c_str());
      if (args->t_min != 0) std::printf(", t_min %g", double(args->t_min));
      if (query == Query::All) std::printf(": %zu hits in all, rows of %u", every_hit, args->max_hits);
      std::printf("\n");
      std::printf("device: %s\n", device.c_str());
      std::printf("cast: %.1f ns/ray (median of %u passes%s)\n", ns, args->repeat,
                  device_ms.empty() ? ", one thread" : ", submission to read-back");
      if (!device_ms.empty()) std::printf("device time: %.1f ns/ray (GPU timestamps)\n", device_ns);
    }
  });
}


void add_render(CLI::App& app) {
  struct Args {
    std::string input, png = "out/render.png", backend = "cpu", method, device;  // method "": the blob's
    LayoutArgs layout;
    int width = 800, height = 600;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("render", "a depth-shaded picture of a mesh, blob or scene, one primary ray a pixel");
  cmd->add_option("input", args->input, "mesh file, generated mesh, blob or scene file (.json)")->required();
  add_layout_options(cmd, args->layout);
  cmd->add_option("--png", args->png, "picture to write");
  cmd->add_option("--width", args->width)->check(integer_in(16, 8192));
  cmd->add_option("--height", args->height)->check(integer_in(16, 8192));
  cmd->add_option("--backend", args->backend, "cpu (one thread) or vulkan")->check(CLI::IsMember({"cpu", "vulkan"}));
  cmd->add_option("--method", args->method, "GPU method (see trace --help; default: the one that reads the blob's layout)");
  cmd->add_option("--device", args->device, "Vulkan device: index or part of its name");
  cmd->callback([args] {
    if (is_scene_file(args->input)) {
      if (args->backend != "cpu") throw InputError("render " + args->input + ": scenes are cast on the CPU (--backend cpu)");
      SceneFile file = load_scene_file(args->input, args->layout, stdout);
      const Picture p = render_scene(file.scene, args->width, args->height);
      write_png(args->png, p.width, p.height, p.rgb);
      std::printf("%s: %zu instances of %zu meshes, CPU, one thread, %dx%d, %.0f ns/ray -> %s\n", args->input.c_str(),
                  file.instances, file.mesh_names.size(), p.width, p.height, p.ns_per_ray, args->png.c_str());
      return;
    }
    Loaded in = load_input_for(args->input, args->layout, args->backend, args->method);
    std::string device = "CPU, one thread";
    Picture p;
    if (args->backend == "vulkan") {
      gpu::Context ctx(gpu::DeviceChoice{args->device, false});
      device = ctx.device_name();
      std::unique_ptr<gpu::Method> method = gpu::make_method(ctx, args->method, in.blob, args->input);
      p = render(in.blob, args->width, args->height, {}, {},
                 [&](std::span<const Ray> rays, std::span<Hit> hits) { method->trace(rays, hits); });
    } else {
      p = render(in.blob, args->width, args->height, {}, {});
    }
    write_png(args->png, p.width, p.height, p.rgb);
    const layout::BlobHeader& h = layout::header_of(in.blob.data());
    std::printf("%s: %s, device: %s, %dx%d, %.0f ns/ray -> %s\n", args->input.c_str(),
                layout_name(h.tree_format, h.triangle_format).c_str(), device.c_str(), p.width, p.height, p.ns_per_ray,
                args->png.c_str());
  });
}

void add_build(CLI::App& app) {
  struct Args {
    std::string input, out;
    LayoutArgs layout;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("build", "build a mesh into a blob file");
  cmd->add_option("input", args->input, "mesh file, or a generated mesh: terrain_2M, terrain_66k, city_1M, terrain_20M")->required();
  cmd->add_option("--out", args->out, "blob file to write")->required();
  add_layout_options(cmd, args->layout);
  cmd->callback([args] {
    Loaded in = load_input(args->input, args->layout);
    if (!in.mesh) throw InputError(args->input + ": is already a blob; give a mesh file");
    write_file(args->out, in.blob.data(), in.blob.size());
    std::printf("%s: %zu triangles -> %s (%zu bytes, %.2f bytes/triangle), build %.1f ms\n", args->input.c_str(),
                in.mesh->triangles.size(), args->out.c_str(), in.blob.size(),
                double(in.blob.size()) / double(in.mesh->triangles.size()), in.build_ms);
  });
}

}  // namespace meshcast::tools
