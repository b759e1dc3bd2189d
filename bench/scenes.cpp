#include "bench/scenes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "bench/timing.h"
#include "bench/peer.h"
#include "builder/layout_names.h"
#include "check/generate.h"
#include "scene/snapshot.h"
#include "meshcast/build.h"
#include "meshcast/scene.h"

namespace meshcast::bench {

namespace {

// A level: instance i is a copy of mesh i % meshes, 2 to 20 m across,
// turned at random; every 4th scaled unevenly (0.7 to 1.4 an axis), every
// 3rd mirrored; placed over 10 km by 10 km (x, z) and 20 m of height (y),
// every coordinate moved by `offset`.
std::vector<PeerInstance> plan_level(const std::vector<Mesh>& meshes, size_t count, double offset, uint32_t seed) {
  std::vector<double> diagonal;
  for (const Mesh& m : meshes) diagonal.push_back(m.bounds().diagonal());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> size(2, 20), uneven(0.7, 1.4), ground(-5000, 5000), height(0, 20);
  std::vector<PeerInstance> out;
  for (size_t i = 0; i < count; ++i) {
    PeerInstance p;
    p.mesh = uint32_t(i % meshes.size());
    const std::array<double, 9> r = random_rotation(rng);
    const double base = size(rng) / diagonal[p.mesh];
    double scale[3] = {base, base, base};
    if (i % 4 == 0)
      for (double& s : scale) s *= uneven(rng);
    if (i % 3 == 0) scale[0] = -scale[0];
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) p.transform.rotation_scale[3 * row + col] = float(r[3 * row + col] * scale[col]);
    p.transform.translation[0] = offset + ground(rng);
    p.transform.translation[1] = offset + height(rng);
    p.transform.translation[2] = offset + ground(rng);
    out.push_back(p);
  }
  return out;
}

// Rays a game casts about its level: from 10 to 300 m away from a random
// instance (1 to 30 m above the ground), at a point of it; incoherent.
std::vector<RayD> level_rays(const std::vector<PeerInstance>& level, size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> away(10, 300), angle(0, 2 * M_PI), up(1, 30), jitter(-1, 1);
  std::vector<RayD> rays(count);
  for (RayD& r : rays) {
    const Transform& t = level[rng() % level.size()].transform;
    const double a = angle(rng), d = away(rng);
    r.org[0] = t.translation[0] + d * std::cos(a), r.org[1] = t.translation[1] + up(rng),
    r.org[2] = t.translation[2] + d * std::sin(a);
    for (int k = 0; k < 3; ++k) r.dir[k] = float(t.translation[k] + jitter(rng) - r.org[k]);
    r.tmax = INFINITY;
  }
  return rays;
}

// A contender: meshcast's scene or Embree's, behind the same calls.
struct Contender {
  std::string name;
  std::function<double()> bytes;  // read after the updates: the steady state
  std::function<void(const std::vector<RayD>&, std::vector<SceneHit>&)> trace;
  std::function<void(uint32_t, const Transform&)> move;
  std::function<void()> commit;
  std::vector<double> ns = {};
  std::vector<SceneHit> hits = {};
};

}  // namespace

std::vector<SceneRow> bench_scenes(const std::vector<Mesh>& meshes, const ScenesOptions& o) {
  std::vector<std::vector<uint8_t>> blobs;
  std::vector<const Mesh*> mesh_pointers;
  double blob_bytes = 0;
  for (const Mesh& m : meshes) {
    blobs.push_back(build_blob(m, parse_layout(o.layout), "bench scenes mesh"));
    blob_bytes += double(blobs.back().size());
    mesh_pointers.push_back(&m);
  }
  std::vector<SceneRow> rows;
  for (size_t count : o.counts) {
    std::vector<std::vector<SceneHit>> origin_hits(2);  // a contender's answers at the first offset
    for (size_t at = 0; at < o.offsets.size(); ++at) {
      const double offset = o.offsets[at];
      const std::vector<PeerInstance> level = plan_level(meshes, count, offset, 17);
      const std::vector<RayD> rays = level_rays(level, o.rays, 29);
      Scene scene;
      std::vector<MeshId> mesh_ids;
      std::vector<InstanceId> instance_ids;
      for (size_t m = 0; m < blobs.size(); ++m) mesh_ids.push_back(scene.add_mesh(blobs[m], "mesh " + std::to_string(m)));
      for (const PeerInstance& p : level) instance_ids.push_back(scene.add_instance(mesh_ids[p.mesh], p.transform));
      scene.commit();
      std::vector<Contender> all;
      // Everything the scene holds besides the blobs: its records of the
      // instances, the tree it refits, the two snapshots it keeps.
      all.push_back({"meshcast " + o.layout, [&] { return blob_bytes + double(scene.top_level_bytes()); },
                     [&](const std::vector<RayD>& r, std::vector<SceneHit>& h) { scene.trace(r, h); },
                     [&](uint32_t i, const Transform& t) { scene.set_transform(instance_ids[i], t); }, [&] { scene.commit(); }});
      std::unique_ptr<ScenePeer> embree = make_embree_scene(mesh_pointers, level);
      if (embree)
        all.push_back({embree->name(), [&] { return double(embree->bytes()); },
                       [&](const std::vector<RayD>& r, std::vector<SceneHit>& h) { embree->trace(r, h); },
                       [&](uint32_t i, const Transform& t) { embree->set_transform(i, t); }, [&] { embree->commit(); }});
      for (Contender& c : all) c.hits.resize(rays.size());
      for (uint32_t round = 0; round < o.rounds + 1; ++round)
        for (Contender& c : all) {
          const auto t0 = std::chrono::steady_clock::now();
          c.trace(rays, c.hits);
          if (round > 0) c.ns.push_back(ms_since(t0) * 1e6 / double(rays.size()));  // round 0 warms the caches
        }
      // Updates: a tenth of the instances moved half a metre and back, or
      // every instance, each followed by a commit; an even number of frames
      // leaves the level as it was.
      for (size_t k = 0; k < all.size(); ++k) {
        Contender& c = all[k];
        std::vector<double> tenth, every;
        for (int frame = 0; frame < 8; ++frame)
          for (int whole = 0; whole < 2; ++whole) {
            const auto t0 = std::chrono::steady_clock::now();
            for (size_t i = 0; i < level.size(); i += whole ? 1 : 10) {
              Transform t = level[i].transform;
              if (frame % 2 == 0) t.translation[0] += 0.5;  // odd frames put it back
              c.move(uint32_t(i), t);
            }
            c.commit();
            (whole ? every : tenth).push_back(ms_since(t0));
          }
        SceneRow r{count, offset, c.name, median(c.ns), c.bytes(), median(tenth), median(every)};
        size_t hit = 0, same = 0;
        if (at == 0) origin_hits[k] = c.hits;
        for (size_t i = 0; i < rays.size(); ++i) {
          hit += c.hits[i].instance != kNoHit;
          same += c.hits[i].instance == origin_hits[k][i].instance && c.hits[i].triangle == origin_hits[k][i].triangle;
        }
        r.hits = double(hit) / double(rays.size());
        r.same_as_origin = double(same) / double(rays.size());
        rows.push_back(r);
        std::fprintf(stderr, "  %zu instances at %g: %s %.0f ns/ray, %.1f MB, update %.2f / %.2f ms, %.1f%% hit, %.2f%% as at %g\n",
                     count, offset, c.name.c_str(), r.ns_per_ray, r.bytes / 1e6, r.update_ms, r.update_all_ms,
                     100 * r.hits, 100 * r.same_as_origin, o.offsets[0]);
      }
    }
  }
  return rows;
}

}  // namespace meshcast::bench
