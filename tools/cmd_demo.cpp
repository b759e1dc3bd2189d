// meshcast demo MESH: the main job. Builds the three layouts of the
// foundation, casts 10,000 rays of each kind on the CPU and on the Vulkan
// device (the recommended layout's very bytes), compares every answer with
// the double-precision oracle, prints a table and renders a picture.
#include <array>
#include <cstdio>
#include <functional>
#include <memory>

#include "bench/peer.h"
#include "check/agreement.h"
#include "check/oracle.h"
#include "check/ray_files.h"
#include "meshcast/blob.h"
#include "gpu/method.h"
#include "gpu/vulkan.h"
#include "meshcast/read.h"
#include "layout/blob_format.h"
#include "tools/commands.h"
#include "tools/common.h"
#include "tools/render.h"

namespace meshcast::tools {

void add_demo(CLI::App& app) {
  struct Args {
    std::string input, png = "out/render.png";
    size_t count = 10000, gpu_count = 10000;
    uint32_t repeat = 5, leaf = 0;  // 0: each layout's own
    std::string device;
    int width = 800, height = 600;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("demo", "the main job: three layouts, three ray kinds, oracle, picture");
  cmd->add_option("input", args->input, "mesh file, or a generated mesh: terrain_2M, terrain_66k, city_1M, terrain_20M")->required();
  cmd->add_option("--count", args->count, "rays of each kind")->check(integer_in(1, 10000000));
  cmd->add_option("--repeat", args->repeat, "timed rounds (each casts every CPU row and ray kind once); the median is reported")->check(integer_in(1, 100));
  cmd->add_option("--leaf", args->leaf, "largest triangle count of a leaf (default: each layout's own)")->check(integer_in(1, 31));
  cmd->add_option("--png", args->png, "picture to write");
  cmd->add_option("--gpu-count", args->gpu_count, "rays of each kind for the Vulkan row (0: no GPU row)")
      ->check(integer_in(0, 10000000));
  cmd->add_option("--device", args->device, "Vulkan device: index or part of its name");
  cmd->add_option("--width", args->width)->check(integer_in(16, 8192));
  cmd->add_option("--height", args->height)->check(integer_in(16, 8192));
  cmd->callback([args] {
    auto t0 = std::chrono::steady_clock::now();
    Mesh mesh = bench_mesh(args->input);
    double load_ms = ms_since(t0);
    std::printf("%s: %zu triangles, %zu vertices, read in %.0f ms\n", args->input.c_str(), mesh.triangles.size(),
                mesh.vertices.size(), load_ms);
    const RayKind kinds[] = {RayKind::Long, RayKind::Probe, RayKind::Radial};
    std::vector<Ray> rays[3];
    std::vector<OracleHit> oracle[3];
    OracleTree tree(mesh);
    for (int k = 0; k < 3; ++k) {
      rays[k] = make_rays(mesh, kinds[k], args->count, 1);
      oracle[k].resize(rays[k].size());
      for (size_t i = 0; i < rays[k].size(); ++i) oracle[k][i] = tree.closest(rays[k][i]);
    }
    double tolerance = 1e-5 * mesh.bounds().diagonal();
    const double n = double(mesh.triangles.size());
    struct Row {
      std::string name;
      double build_ms, walked, remap, ns[3];
      uint64_t disagreements;
    };
    // The CPU contenders (the three layouts, then Embree when meshcast was
    // built with it), timed in rounds that interleave every contender and
    // ray kind, so a slow spell of the machine falls on all of them alike
    // (as `bench peers`); the median of --repeat rounds is reported.
    struct Contender {
      Row row;
      std::function<void(const std::vector<Ray>&, std::vector<Hit>&)> cast;
      std::function<Agreement(int, const std::vector<Hit>&)> judge;
    };
    std::vector<Contender> cpu;
    std::vector<std::unique_ptr<std::vector<uint8_t>>> blobs;  // what the views read
    std::vector<std::unique_ptr<BlobView>> views;
    std::vector<std::unique_ptr<Mesh>> stored_meshes;
    std::vector<std::unique_ptr<OracleTree>> stored_trees;
    for (const char* name : {"AABBTree/Float3", "QuadTreeHalfFloat/Indexed8BitPackSOA4", "OctTreeCompressed/ClusterBitPackSOA8"}) {
      BuildOptions o = layout_options(name, args->leaf);
      BuildReport report;
      blobs.push_back(std::make_unique<std::vector<uint8_t>>(build_blob(mesh, o, args->input, &report)));
      views.push_back(std::make_unique<BlobView>(*blobs.back(), name));
      // The bit-packed layouts are judged on the mesh they store (vertices
      // moved by at most the quantization bound), the others on the input.
      const Mesh* judged_mesh = &mesh;
      const OracleTree* judged_tree = nullptr;
      if (moves_vertices(uint32_t(o.layout.triangles))) {
        stored_meshes.push_back(std::make_unique<Mesh>(stored_mesh(*blobs.back())));
        stored_trees.push_back(std::make_unique<OracleTree>(*stored_meshes.back()));
        judged_mesh = stored_meshes.back().get(), judged_tree = stored_trees.back().get();
      }
      SectionBytes s = section_bytes(*blobs.back());
      const BlobView* view = views.back().get();
      cpu.push_back({Row{name, report.build_ms, s.walked() / n, s.remap / n, {}, 0},
                     // One ray at a time, as the peer's rows: the radial rays share an
                     // origin, which would otherwise walk as packets.
                     [view](const std::vector<Ray>& r, std::vector<Hit>& h) {
                       view->trace(r, h, HitOutputs::None, Query::Closest, Cull::None, Packets::Off);
                     },
                     [&, judged_mesh, judged_tree](int k, const std::vector<Hit>& hits) {
                       if (!judged_tree) return compare(*judged_mesh, rays[k], hits, oracle[k], tolerance);
                       std::vector<OracleHit> answers(rays[k].size());
                       for (size_t i = 0; i < rays[k].size(); ++i) answers[i] = judged_tree->closest(rays[k][i]);
                       return compare(*judged_mesh, rays[k], hits, answers, tolerance);
                     }});
    }
    const std::vector<uint8_t>& picture_blob = *blobs.back();
    // A peer measured in the same run, when meshcast was built with it.
    std::unique_ptr<bench::Peer> peer = bench::make_embree(mesh);
    if (peer) {
      const bench::Peer* p = peer.get();
      cpu.push_back({Row{peer->name() + " (peer)", peer->build_ms(), double(peer->bytes()) / n, 0, {}, 0},
                     [p](const std::vector<Ray>& r, std::vector<Hit>& h) { p->trace(r, h); },
                     [&](int k, const std::vector<Hit>& hits) { return compare(mesh, rays[k], hits, oracle[k], tolerance); }});
    }
    std::vector<std::array<std::vector<double>, 3>> pass_ms(cpu.size());
    std::vector<Hit> hits(args->count);
    for (uint32_t round = 0; round <= args->repeat; ++round)  // round 0 warms the caches
      for (size_t c = 0; c < cpu.size(); ++c)
        for (int k = 0; k < 3; ++k) {
          auto t1 = std::chrono::steady_clock::now();
          cpu[c].cast(rays[k], hits);
          if (round > 0) pass_ms[c][k].push_back(ms_since(t1));
        }
    for (size_t c = 0; c < cpu.size(); ++c)
      for (int k = 0; k < 3; ++k) {
        cpu[c].row.ns[k] = median(pass_ms[c][k]) * 1e6 / double(rays[k].size());
        cpu[c].cast(rays[k], hits);  // judged on one more pass
        Agreement a = cpu[c].judge(k, hits);
        cpu[c].row.disagreements += a.wrong + a.t_errors;
      }
    std::vector<Row> rows;
    for (size_t c = 0; c < 3; ++c) rows.push_back(cpu[c].row);
    // The GPU: the octtree method on the very bytes of the CPU's
    // recommended layout (OctTreeCompressed/ClusterBitPackSOA8), the first
    // gpu_count rays of each kind, timed from submission to read-back (the
    // device's own time beside it), judged by the same oracle.
    std::string gpu_note;
    if (args->gpu_count > 0) {
      try {
        gpu::Context ctx(gpu::DeviceChoice{args->device, false});
        BuildReport report;
        std::vector<uint8_t> blob =
            build_blob(mesh, layout_options("OctTreeCompressed/ClusterBitPackSOA8", args->leaf), args->input, &report);
        std::unique_ptr<gpu::Method> method = gpu::make_method(ctx, "octtree", blob, args->input);
        Mesh stored = stored_mesh(blob);  // quantized: judged on what it stores, as the CPU row
        OracleTree stored_tree(stored);
        SectionBytes s = section_bytes(blob);
        Row row{"Vulkan OctTreeCompressed/ClusterBitPackSOA8", report.build_ms, s.walked() / n, s.remap / n, {}, 0};
        double device_ns[3] = {};
        for (int k = 0; k < 3; ++k) {
          size_t m = std::min(args->gpu_count, rays[k].size());
          std::span<const Ray> subset(rays[k].data(), m);
          std::vector<Hit> hits(m);
          std::vector<double> wall, device;
          for (uint32_t r = 0; r < std::min(args->repeat, 3u); ++r) {
            gpu::GpuTiming timing;
            method->trace(subset, hits, &timing);
            wall.push_back(timing.wall_ms), device.push_back(timing.device_ms);
          }
          row.ns[k] = median(wall) * 1e6 / double(m);
          device_ns[k] = median(device) * 1e6 / double(m);
          std::vector<Ray> judged(subset.begin(), subset.end());
          std::vector<OracleHit> answers;
          for (const Ray& ray : judged) answers.push_back(stored_tree.closest(ray));
          Agreement a = compare(stored, judged, hits, answers, tolerance);
          row.disagreements += a.wrong + a.t_errors;
        }
        rows.push_back(row);
        char buf[256];
        std::snprintf(buf, sizeof buf, "Vulkan row: %s, %zu rays of each kind, submission to read-back (device time %.0f, %.0f, %.0f ns/ray)",
                      ctx.device_name().c_str(), std::min(args->gpu_count, rays[0].size()), device_ns[0], device_ns[1], device_ns[2]);
        gpu_note = buf;
      } catch (const gpu::GpuError& e) {
        gpu_note = std::string("no Vulkan row: ") + e.what();
      }
    }
    // meshcast's rows decide the exit status; the peer's disagreements are
    // printed, not judged (Embree's default build is not watertight).
    uint64_t disagreements_total = 0;
    for (const Row& r : rows) disagreements_total += r.disagreements;
    Row peer_row{};
    if (peer) rows.push_back(peer_row = cpu.back().row);
    std::printf("\n| layout | build ms | bytes/tri walked | remap B/tri | ns/ray long | ns/ray probe | ns/ray radial "
                "| disagreements |\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const Row& r : rows)
      std::printf("| %s | %.0f | %.2f | %.2f | %.0f | %.0f | %.0f | %llu |\n", r.name.c_str(), r.build_ms, r.walked,
                  r.remap, r.ns[0], r.ns[1], r.ns[2], (unsigned long long)r.disagreements);
    std::printf("\n%zu rays of each kind, one thread, median of %u rounds interleaving the CPU rows; disagreements = rays whose triangle or t "
                "differs from the double-precision oracle beyond exact ties (t tolerance %.3g)\n",
                args->count, args->repeat, tolerance);
    if (!gpu_note.empty()) std::printf("%s\n", gpu_note.c_str());
    if (peer) {
      std::printf("time / %s time (long, probe, radial):", peer->name().c_str());
      for (size_t i = 0; i < rows.size(); ++i)
        if (rows[i].name.find("(peer)") == std::string::npos && rows[i].name.find("Vulkan") == std::string::npos)
          std::printf("  %s %.2f %.2f %.2f;", rows[i].name.c_str(), rows[i].ns[0] / peer_row.ns[0],
                      rows[i].ns[1] / peer_row.ns[1], rows[i].ns[2] / peer_row.ns[2]);
      std::printf("\n%s bytes/tri: the memory its device reported for the scene, plus the mesh it reads (vertices, indices)\n",
                  peer->name().c_str());
    } else {
      std::printf("no peer: meshcast was built without Embree (apt-get install libembree-dev)\n");
    }
    std::vector<Hit> long_hits(rays[0].size());
    BlobView(picture_blob, "picture").trace(rays[0], long_hits);
    Picture p = render(picture_blob, args->width, args->height, rays[0], long_hits);
    write_png(args->png, p.width, p.height, p.rgb);
    std::printf("picture: %s (%dx%d, OctTreeCompressed/ClusterBitPackSOA8, %.0f ns/ray; green: long-ray hits)\n",
                args->png.c_str(), p.width, p.height, p.ns_per_ray);
    if (disagreements_total) throw std::runtime_error("the walkers disagree with the oracle");
  });
}

}  // namespace meshcast::tools
