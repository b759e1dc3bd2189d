#include "bench/peers.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <thread>

#include "bench/peer.h"
#include "builder/layout_names.h"
#include "builder/ray_sets.h"
#include "cpu/counters.h"
#include "meshcast/blob.h"
#include "meshcast/build.h"

namespace meshcast::bench {

std::vector<std::string> default_peer_layouts() {
  return {"OctTreeCompressed/ClusterBitPackSOA8", "OctTreeCompressed/ClusterBitPackSOA8@8", "OctTreeCompressed/Float3SOA8",
          "QuadTreeHalfFloat/Indexed8BitPackSOA4", "QuadTree/Float3SOA8"};
}

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

struct Contender {
  std::string name;
  bool is_peer;
  double bytes, build_one, build_all;
  std::function<void(const std::vector<Ray>&, std::vector<Hit>&)> trace;
  std::vector<std::vector<double>> ns;  // per ray kind, one a round
};

}  // namespace

std::vector<PeerRow> bench_peers(const Mesh& mesh, const std::string& name, const PeersOptions& o) {
  const double triangles = double(mesh.triangles.size());
  std::vector<RayKind> kinds;
  for (const std::string& k : o.kinds) kinds.push_back(parse_ray_kind(k));
  std::vector<std::vector<Ray>> rays;
  for (RayKind k : kinds) rays.push_back(make_rays(mesh, k, o.rays, 19));

  std::vector<Contender> all;
  std::vector<std::vector<uint8_t>> blobs;  // kept alive for the views
  std::vector<std::unique_ptr<uint8_t[], void (*)(void*)>> aligned;  // the blobs the views read
  std::vector<std::unique_ptr<BlobView>> views;
  blobs.reserve(o.layouts.size());
  for (const std::string& layout : o.layouts) {
    std::fprintf(stderr, "  %s: building %s\n", name.c_str(), layout.c_str());
    const auto t0 = std::chrono::steady_clock::now();
    // "TREE/TRIANGLES@LEAF": a leaf size other than the default.
    const size_t at = layout.find('@');
    BuildOptions bo = parse_layout(layout.substr(0, at));
    if (at != std::string::npos) bo.leaf_size = uint32_t(std::stoul(layout.substr(at + 1)));
    blobs.push_back(build_blob(mesh, bo, name));
    const double build = ms_since(t0);
    // 64-byte aligned, as Embree aligns its nodes and as a mapped blob file
    // is: a heap vector is aligned to 16 only, and a 96-byte node off a cache
    // line costs a third line half the time (about 8% a ray, measured).
    aligned.emplace_back(static_cast<uint8_t*>(std::aligned_alloc(64, (blobs.back().size() + 63) / 64 * 64)), std::free);
    std::memcpy(aligned.back().get(), blobs.back().data(), blobs.back().size());
    views.push_back(std::make_unique<BlobView>(std::span<const uint8_t>(aligned.back().get(), blobs.back().size()), name));
    const BlobView* view = views.back().get();
    all.push_back({layout, false, double(blobs.back().size()) / triangles, build, build,
                   [view](const std::vector<Ray>& r, std::vector<Hit>& h) { view->trace(r, h); }, {}});
  }
  std::vector<std::unique_ptr<Peer>> peers;
  for (EmbreeMode mode : {EmbreeMode::Default, EmbreeMode::Robust, EmbreeMode::Compact}) {
    std::fprintf(stderr, "  %s: building Embree (%s)\n", name.c_str(),
                 mode == EmbreeMode::Default ? "default" : mode == EmbreeMode::Robust ? "robust" : "compact");
    std::unique_ptr<Peer> peer = make_embree(mesh, mode, 1);
    if (!peer) break;  // built without Embree
    const double build_all = make_embree(mesh, mode, 0)->build_ms();
    const Peer* p = peer.get();
    all.push_back({peer->name(), true, double(peer->bytes()) / triangles, peer->build_ms(), build_all,
                   [p](const std::vector<Ray>& r, std::vector<Hit>& h) { p->trace(r, h); }, {}});
    peers.push_back(std::move(peer));
  }

  // Rounds: every contender on every ray kind once a round, so a slow spell
  // of the machine falls on all of them alike.
  std::vector<Hit> hits(o.rays);
  for (Contender& c : all) c.ns.resize(std::size(kinds));
  for (uint32_t round = 0; round < o.rounds + 1; ++round)
    for (Contender& c : all)
      for (size_t k = 0; k < kinds.size(); ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        c.trace(rays[k], hits);
        const double ns = ms_since(t0) * 1e6 / double(o.rays);
        if (round > 0) c.ns[k].push_back(ns);  // round 0 warms the caches
      }

  // A counting build (MESHCAST_COUNT_TESTS) also reports each meshcast
  // layout's box and triangle tests a ray, from one more pass (its times are
  // not for comparison).
  if constexpr (kCountTests)
    for (Contender& c : all)
      for (size_t k = 0; k < kinds.size() && !c.is_peer; ++k) {
        test_counts = {};
        c.trace(rays[k], hits);
        std::fprintf(stderr, "  %s %s %s: %.1f box tests, %.1f triangle tests a ray\n", name.c_str(), o.kinds[k].c_str(),
                     c.name.c_str(), double(test_counts.boxes) / double(o.rays), double(test_counts.triangles) / double(o.rays));
      }

  std::vector<PeerRow> rows;
  for (size_t k = 0; k < kinds.size(); ++k) {
    double embree_default = 0;
    std::vector<PeerRow> kind_rows;
    for (Contender& c : all) {
      std::vector<double>& v = c.ns[k];
      std::sort(v.begin(), v.end());
      PeerRow r{name, o.kinds[k], c.name, c.is_peer, v[v.size() / 2], 0, c.bytes, c.build_one, c.build_all};
      if (c.is_peer && embree_default == 0) embree_default = r.ns_per_ray;  // the first peer is the default build
      kind_rows.push_back(r);
    }
    for (PeerRow& r : kind_rows) {
      r.ratio = embree_default > 0 ? r.ns_per_ray / embree_default : 0;
      rows.push_back(r);
    }
  }
  return rows;
}

}  // namespace meshcast::bench
