// `meshcast distance`: the distance from query points to a mesh's nearest
// point (BlobView::closest_points), unsigned or signed, the points read
// from a .npy file or laid on a grid over the mesh's box, the answers
// written as .npy files numpy reads directly.
#include <chrono>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "cpu/crossings.h"
#include "host/chunks.h"
#include "host/jobs.h"
#include "layout/blob_format.h"
#include "meshcast/blob.h"
#include "meshcast/winding_number.h"
#include "tools/commands.h"
#include "tools/npy.h"

namespace meshcast::tools {

namespace {

struct DistanceArgs {
  std::string input, points, out, triangles_out;
  uint32_t grid = 0;
  double margin = 0.05;
  float max_distance = INFINITY;
  bool signed_distance = false;
  std::string sign = "parity";  // how --signed tells inside: parity or winding
  uint32_t threads = 0;
  bool json = false;
  LayoutArgs layout;
};

// The inside test's direction: along no axis or diagonal (a mesh's edges
// often are); a crossing through an edge or vertex counts once anyway.
constexpr float kInsideDirection[3] = {0.3216f, 0.8812f, 0.3466f};

void run(const DistanceArgs& a) {
  if (a.points.empty() == (a.grid == 0)) throw InputError("distance: give --points FILE.npy or --grid N, one of them");
  auto t0 = std::chrono::steady_clock::now();
  Loaded in = load_input(a.input, a.layout, a.json ? nullptr : stdout);
  const BlobView view(in.blob, a.input);
  const layout::BlobHeader& h = layout::header_of(in.blob.data());
  if (view.layout().tree != TreeFormat::OctTreeCompressed)
    throw InputError("distance " + a.input + ": point queries walk OctTreeCompressed layouts (the recommended one, or "
                     "OctTreeCompressed/ClusterFloat3SOA8, exact); this blob is " + layout_name(view.layout()));
  // The points, and the shape the answers take.
  std::vector<Vec3> points;
  std::vector<uint64_t> shape;
  if (!a.points.empty()) {
    const NpyReals read = read_npy_reals(a.points);
    if (read.shape.empty() || read.shape.back() != 3)
      throw InputError(a.points + ": shape is not (..., 3): each point is x, y, z");
    shape.assign(read.shape.begin(), read.shape.end() - 1);
    points.resize(read.values.size() / 3);
    for (size_t i = 0; i < points.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const double v = read.values[3 * i + size_t(k)];
        if (!std::isfinite(v) || std::fabs(v) > FLT_MAX)
          throw InputError(a.points + ": point " + std::to_string(i) + " has coordinate " + std::to_string(k) + " " +
                           std::to_string(v) + ", not a finite float");
        points[i][k] = float(v);
      }
  } else {
    // N^3 cell centres over the box grown by the margin on every side,
    // indexed [x][y][z].
    shape = {a.grid, a.grid, a.grid};
    float lo[3], step[3];
    for (int k = 0; k < 3; ++k) {
      const double extent = double(h.bounds_max[k]) - h.bounds_min[k];
      const double grow = a.margin * std::fmax(extent, 1e-30);
      lo[k] = float(h.bounds_min[k] - grow);
      step[k] = float((extent + 2 * grow) / a.grid);
    }
    points.resize(size_t(a.grid) * a.grid * a.grid);
    for (uint32_t x = 0; x < a.grid; ++x)
      for (uint32_t y = 0; y < a.grid; ++y)
        for (uint32_t z = 0; z < a.grid; ++z)
          points[(size_t(x) * a.grid + y) * a.grid + z] = {lo[0] + (float(x) + 0.5f) * step[0],
                                                           lo[1] + (float(y) + 0.5f) * step[1],
                                                           lo[2] + (float(z) + 0.5f) * step[2]};
  }
  const double setup_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  std::vector<ClosestPoint> found(points.size());
  const bool by_winding = a.signed_distance && a.sign == "winding";
  std::vector<uint32_t> crossings(a.signed_distance && !by_winding ? points.size() : 0);
  std::vector<uint8_t> enclosed(by_winding ? points.size() : 0);
  const TriangleCorners corners(view.bytes());  // one table for every chunk's inside test
  std::optional<WindingNumbers> winding;  // the clusters, made once for every chunk
  if (by_winding) winding.emplace(view);
  host::WorkerPool pool(a.threads);
  const host::Chunks plan = host::plan_chunks(points.size(), pool.threads());
  host::for_each_chunk(plan, &pool, [&](size_t c) {
    const size_t begin = plan.begin(c), n = plan.end(c) - begin;
    view.closest_points(std::span(points).subspan(begin, n), std::span(found).subspan(begin, n), a.max_distance);
    if (!a.signed_distance) return;
    if (by_winding) {
      winding->inside(std::span(points).subspan(begin, n), std::span(enclosed).subspan(begin, n));
      return;
    }
    std::vector<Ray> rays(n);
    for (size_t i = 0; i < n; ++i)
      rays[i] = Ray{{points[begin + i].x, points[begin + i].y, points[begin + i].z},
                    {kInsideDirection[0], kInsideDirection[1], kInsideDirection[2]}, INFINITY};
    count_crossings(view, rays, std::span(crossings).subspan(begin, n), &corners);
  });
  const double query_ms = ms_since(t0);
  std::vector<float> distance(points.size());
  std::vector<uint32_t> triangle(points.size());
  size_t inside = 0, none = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const bool in_mesh = by_winding ? enclosed[i] != 0 : a.signed_distance && crossings[i] % 2 == 1;
    inside += in_mesh;
    none += found[i].triangle == kNoHit;
    distance[i] = in_mesh ? -found[i].distance : found[i].distance;
    triangle[i] = found[i].triangle;
  }
  write_npy(a.out, shape, distance);
  if (!a.triangles_out.empty()) write_npy(a.triangles_out, shape, triangle);
  const double ns = points.empty() ? 0 : query_ms * 1e6 / double(points.size());
  if (a.json) {
    print_json({{"input", a.input}, {"layout", layout_name(view.layout())}, {"points", points.size()},
                {"signed", a.signed_distance}, {"sign", a.sign}, {"inside", inside}, {"none_within_limit", none},
                {"threads", pool.threads()}, {"ns_per_point", ns}, {"out", a.out}});
    return;
  }
  std::printf("%zu points (%s), %s, %u thread%s: %.0f ns a point (wall clock), set up in %.0f ms\n", points.size(),
              a.points.empty() ? ("a " + std::to_string(a.grid) + "^3 grid").c_str() : a.points.c_str(),
              layout_name(view.layout()).c_str(), pool.threads(), pool.threads() == 1 ? "" : "s", ns, setup_ms);
  if (a.signed_distance) std::printf("%zu inside (negative), %zu outside\n", inside, points.size() - inside);
  if (none) std::printf("%zu with nothing within --max-distance (inf)\n", none);
  std::printf("distances -> %s%s\n", a.out.c_str(), a.triangles_out.empty() ? "" : (", triangles -> " + a.triangles_out).c_str());
}

}  // namespace

void add_distance(CLI::App& app) {
  auto args = std::make_shared<DistanceArgs>();
  CLI::App* cmd = app.add_subcommand(
      "distance", "distances (or signed distances) from points or a grid to a mesh's nearest point, as .npy files");
  cmd->add_option("input", args->input, "mesh file (OFF, OBJ, PLY, STL), generated mesh or blob file")->required();
  cmd->add_option("--points", args->points, "query points: a .npy file of shape (..., 3), float32 or float64");
  cmd->add_option("--grid", args->grid,
                  "or an N x N x N grid of cell centres over the mesh's box (grown by --margin), N up to 512")
      ->check(integer_in(1, 512));
  cmd->add_option("--margin", args->margin, "--grid: the box grown by this fraction of its extent on every side")
      ->check(number_in(0, 1000));
  cmd->add_option("--out", args->out, "the distances (float32 .npy, the points' shape; a grid's [x][y][z])")->required();
  cmd->add_option("--triangles", args->triangles_out, "also the nearest triangle of each point (uint32 .npy)");
  cmd->add_option("--max-distance", args->max_distance,
                  "points with nothing this near get inf (and triangle 4294967295); default: no limit")
      ->check(number_in(0, INFINITY, true));
  cmd->add_flag("--signed", args->signed_distance,
                "negative inside: an odd number of crossings of a ray from the point (a crossing through an edge "
                "or vertex counts once), exact on a closed mesh wound either way");
  cmd->add_option("--sign", args->sign,
                  "--signed's inside test: parity (a ray's crossings, the default) or winding (the generalized "
                  "winding number above 1/2 in magnitude: right on meshes with holes, gaps and self-intersections)")
      ->check(CLI::IsMember({"parity", "winding"}));
  cmd->add_option("--threads", args->threads, "threads (0: every core, the default)")->check(integer_in(0, 1024));
  cmd->add_flag("--json", args->json, "print the figures as one JSON object");
  add_layout_options(cmd, args->layout);
  cmd->callback([args] { run(*args); });
}

}  // namespace meshcast::tools
