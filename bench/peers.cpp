#include "bench/peers.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <thread>

#include "bench/peak_memory.h"
#include "bench/timing.h"
#include "bench/peer.h"
#include "builder/layout_names.h"
#include "builder/ray_sets.h"
#include "cpu/common_origin.h"
#include "cpu/counters.h"
#include "layout/queries.h"
#include "meshcast/blob.h"
#include "meshcast/build.h"
#include "meshcast/caster.h"

namespace meshcast::bench {

std::vector<std::string> default_peer_layouts() {
  return {"OctTreeCompressed/ClusterBitPackSOA8", "OctTreeCompressed/ClusterBitPackSOA8@8", "OctTreeCompressed/Float3SOA8",
          "QuadTreeHalfFloat/Indexed8BitPackSOA4", "QuadTree/Float3SOA8"};
}

namespace {

using layout::QuerySpec;

// Embree's builds by the names --peers takes.
constexpr std::pair<const char*, EmbreeMode> kEmbreeBuilds[] = {
    {"default", EmbreeMode::Default}, {"high", EmbreeMode::High}, {"robust", EmbreeMode::Robust}, {"compact", EmbreeMode::Compact}};

struct Contender {
  std::string name;
  bool is_peer;
  double bytes, build_one, build_all;
  double build_peak = 0;  // bytes a triangle (PeerRow::build_peak_bytes_per_triangle)
  // False for a query the contender has no answer to (Embree: all hits,
  // culling, which its build takes only at compile time).
  // `sorted`: a set of one origin's rays sorted by direction, which
  // meshcast walks as packets; every other set one ray at a time.
  std::function<bool(const std::vector<Ray>&, std::vector<Hit>&, QuerySpec, bool sorted)> trace;
  std::vector<std::vector<double>> ns;  // per set (ray kind and query), one a round
  bool packets_peer = false;  // Embree's 16-wide packets, on the sorted sets alone
};

}  // namespace

const std::vector<std::string>& embree_build_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& build : kEmbreeBuilds) out.push_back(build.first);
    return out;
  }();
  return names;
}

std::vector<PeerRow> bench_peers(const Mesh& mesh, const std::string& name, const PeersOptions& o,
                                 std::vector<CoreRow>* cores, std::vector<CountRow>* counts) {
  const double triangles = double(mesh.triangles.size());
  std::vector<RayKind> kinds;
  for (const std::string& k : o.kinds) kinds.push_back(parse_ray_kind(k));
  std::vector<std::vector<Ray>> rays;
  for (RayKind k : kinds) rays.push_back(make_rays(mesh, k, o.rays, 19));
  // A kind whose rays share one origin (radial) again, sorted by direction:
  // a set of its own (KIND sorted), on which meshcast walks packets and
  // Embree is timed both one ray at a time and in 16-wide packets, so that
  // a packet's gain is never read as a single ray's.
  std::vector<std::string> set_names = o.kinds;
  std::vector<bool> sorted(kinds.size(), false);
  for (size_t k = 0; k < kinds.size(); ++k) {
    if (!o.packets || !share_one_origin(rays[k])) continue;
    std::vector<uint32_t> order(rays[k].size()), scratch(rays[k].size());
    std::vector<uint16_t> keys(rays[k].size());
    order_by_direction(rays[k], order, keys, scratch);
    std::vector<Ray> by_direction;
    for (uint32_t i : order) by_direction.push_back(rays[k][i]);
    rays.push_back(std::move(by_direction));
    set_names.push_back(o.kinds[k] + " sorted");
    sorted.push_back(true);
  }

  std::vector<Contender> all;
  std::vector<std::vector<uint8_t>> blobs;  // kept alive for the views
  std::vector<std::unique_ptr<uint8_t[], void (*)(void*)>> aligned;  // the blobs the views read
  std::vector<std::unique_ptr<BlobView>> views;
  blobs.reserve(o.layouts.size());
  // "TREE/TRIANGLES@LEAF": a leaf size other than the default;
  // "...:embree": laid out over Embree's binary tree (embree_tree_source),
  // not meshcast's own.
  auto build_of = [&](const std::string& layout, uint32_t threads) {
    const size_t colon = layout.find(':');
    const std::string named = layout.substr(0, colon);
    const size_t at = named.find('@');
    BuildOptions bo = parse_layout(named.substr(0, at));
    if (at != std::string::npos) bo.leaf_size = uint32_t(std::stoul(named.substr(at + 1)));
    bo.threads = threads;
    if (colon == std::string::npos) return build_blob(mesh, bo, name);
    if (layout.substr(colon) != ":embree") throw InputError(layout + ": the tree's source after ':' is embree or nothing");
    const TreeSource source = embree_tree_source();
    if (!source) throw InputError(layout + ": meshcast was built without Embree, whose tree it names");
    return build_blob_over(mesh, bo, name, source);
  };
  for (const std::string& layout : o.layouts) {
    std::fprintf(stderr, "  %s: building %s\n", name.c_str(), layout.c_str());
    const double peak = peak_added_bytes([&] { blobs.push_back(build_of(layout, 1)); });
    // 64-byte aligned, as Embree aligns its nodes and as a mapped blob file
    // is: a heap vector is aligned to 16 only, and a 96-byte node off a cache
    // line costs a third line half the time (about 8% a ray, measured).
    aligned.emplace_back(static_cast<uint8_t*>(std::aligned_alloc(64, (blobs.back().size() + 63) / 64 * 64)), std::free);
    std::memcpy(aligned.back().get(), blobs.back().data(), blobs.back().size());
    views.push_back(std::make_unique<BlobView>(std::span<const uint8_t>(aligned.back().get(), blobs.back().size()), name));
    const BlobView* view = views.back().get();
    auto lists = std::make_shared<HitLists>();  // Query::All's rows, kept from pass to pass as a game would
    all.push_back({layout, false, double(blobs.back().size()) / triangles, 0, 0, peak / triangles,
                   [view, lists](const std::vector<Ray>& r, std::vector<Hit>& h, QuerySpec q, bool) {
                     if (q.query == Query::All) view->trace_all_hits(r, *lists, HitOutputs::None, q.cull);
                     else view->trace(r, h, HitOutputs::None, q.query, q.cull, Packets::Off);
                     return true;
                   },
                   {}});
    // The same layout's packets, on the sorted sets alone (where the
    // layout's walker has none, its single rays again).
    if (o.packets)
      all.push_back({layout + ", packets", false, double(blobs.back().size()) / triangles, 0, 0, peak / triangles,
                     [view](const std::vector<Ray>& r, std::vector<Hit>& h, QuerySpec q, bool sorted) {
                       if (!sorted || q.query == Query::All) return false;
                       view->trace(r, h, HitOutputs::None, q.query, q.cull, Packets::Auto);
                       return true;
                     },
                     {}});
  }
  std::vector<std::unique_ptr<Peer>> peers;
  std::vector<EmbreeMode> modes;
  for (const auto& [mode_name, mode] : kEmbreeBuilds) {
    if (std::find(o.peers.begin(), o.peers.end(), mode_name) == o.peers.end()) continue;
    std::unique_ptr<Peer> peer;
    const double peak = peak_added_bytes([&] { peer = make_embree(mesh, mode, 1); });
    if (peer) std::fprintf(stderr, "  %s: built %s\n", name.c_str(), peer->name().c_str());
    if (!peer) break;  // built without Embree
    const Peer* p = peer.get();
    all.push_back({peer->name(), true, double(peer->bytes()) / triangles, 0, 0, peak / triangles,
                   [p](const std::vector<Ray>& r, std::vector<Hit>& h, QuerySpec q, bool) {
                     if (q.query == Query::All || q.cull != Cull::None) return false;
                     p->trace(r, h, q.query);
                     return true;
                   },
                   {}});
    peers.push_back(std::move(peer));
    modes.push_back(mode);
  }
  // Embree default's 16-wide packets (rtcIntersect16 / rtcOccluded16) on
  // the sorted sets: the peer's own packets on the rays meshcast packs.
  if (!peers.empty() && modes[0] == EmbreeMode::Default && o.packets) {
    const Peer* p = peers[0].get();
    const double peak = all[o.layouts.size() * 2].build_peak;  // Embree default's, after each layout and its packets
    all.push_back({p->name() + ", 16-wide packets", true, double(p->bytes()) / triangles, 0, 0, peak,
                   [p](const std::vector<Ray>& r, std::vector<Hit>& h, QuerySpec q, bool sorted) {
                     if (!sorted || q.query == Query::All || q.cull != Cull::None) return false;
                     p->trace_packets(r, h, q.query);
                     return true;
                   },
                   {}, true});
  }

  // Build times: every contender built again in interleaved rounds, on one
  // thread and on every core, the median of each (a first build pays for
  // page faults and thread starts that later ones do not).
  if (o.build_times) {
    const uint32_t build_rounds = std::max(3u, o.rounds);
    std::vector<std::vector<double>> one(all.size()), every(all.size());
    // A layout's packets and Embree's 16-wide packets walk the build
    // before them in `all` (the layout's own, Embree default's).
    const size_t layout_twins = o.packets ? 2 : 1;
    for (uint32_t round = 0; round < build_rounds; ++round) {
      size_t c = 0;
      for (size_t l = 0; l < o.layouts.size(); ++l, c += layout_twins) {
        for (uint32_t threads : {1u, 0u}) {
          const auto t0 = std::chrono::steady_clock::now();
          const std::vector<uint8_t> again = build_of(o.layouts[l], threads);
          (threads == 1 ? one : every)[c].push_back(ms_since(t0));
          if (again != blobs[l])
            throw std::runtime_error(name + ": " + o.layouts[l] + " built to other bytes on " +
                                     (threads == 1 ? "one thread" : "every core") + " than on one thread before");
        }
      }
      for (EmbreeMode mode : modes) {
        one[c].push_back(make_embree(mesh, mode, 1)->build_ms());
        every[c].push_back(make_embree(mesh, mode, 0)->build_ms());
        ++c;
      }
    }
    for (size_t c = 0; c < all.size(); ++c)
      if (one[c].empty()) {  // a twin: the build it walks
        const size_t of = all[c].packets_peer ? o.layouts.size() * layout_twins : c - 1;
        one[c] = one[of], every[c] = every[of];
      }
    for (size_t c = 0; c < all.size(); ++c) all[c].build_one = median(one[c]), all[c].build_all = median(every[c]);
  }

  // The sets timed: each ray kind under each query asked for.
  std::vector<QuerySpec> queries;
  for (const std::string& q : o.queries) queries.push_back(layout::query_spec_named(q, "--queries"));
  struct Set { size_t kind; size_t query; };
  std::vector<Set> sets;
  for (size_t k = 0; k < rays.size(); ++k)
    for (size_t q = 0; q < queries.size(); ++q) sets.push_back({k, q});

  // Rounds: every contender on every set once a round, so a slow spell of
  // the machine falls on all of them alike.
  std::vector<Hit> hits(o.rays);
  for (Contender& c : all) c.ns.resize(sets.size());
  for (uint32_t round = 0; round < o.rounds + 1; ++round)
    for (Contender& c : all)
      for (size_t s = 0; s < sets.size(); ++s) {
        const auto t0 = std::chrono::steady_clock::now();
        if (!c.trace(rays[sets[s].kind], hits, queries[sets[s].query], sorted[sets[s].kind])) continue;  // no row
        const double ns = ms_since(t0) * 1e6 / double(o.rays);
        if (round > 0) c.ns[s].push_back(ns);  // round 0 warms the caches
      }

  // The multi-core rows: the first layout through a Caster's CPU pool and
  // Embree default through TBB, each on one thread and on every core, in
  // interleaved rounds of their own; closest and any only (Embree answers
  // no others).
  if (cores && o.cores && !o.layouts.empty()) {
    constexpr size_t kCoreBatch = 100000;
    const uint32_t every = std::max(1u, std::thread::hardware_concurrency());
    struct Runner {  // one thread, then every core, for each contender
      std::string contender;
      std::function<void(const std::vector<Ray>&, std::vector<Hit>&, Query)> trace;
    };
    std::vector<std::unique_ptr<host::Caster>> casters;
    std::vector<Runner> runners;
    for (uint32_t threads : {1u, every}) {
      host::CasterOptions co;
      co.backend = host::Backend::Cpu, co.threads = threads;
      casters.push_back(std::make_unique<host::Caster>(std::span<const uint8_t>(aligned[0].get(), blobs[0].size()), name, co));
      host::Caster* c = casters.back().get();
      runners.push_back({o.layouts[0] + " (Caster, CPU)", [c](const std::vector<Ray>& r, std::vector<Hit>& h, Query q) {
                           host::BatchQuery query{q};
                           query.packets = Packets::Off;  // rays one at a time, as the single-thread rows
                           c->wait(c->submit(r, query), h);
                         }});
    }
    // Embree on a device of every core: a device of one thread (the
    // single-thread rows') caps TBB's parallelism for the whole process
    // while it lives, so those go first. (Their rows are measured.)
    std::unique_ptr<Peer> embree_all;
    if (!peers.empty()) {
      for (Contender& c : all)
        if (c.is_peer) c.trace = nullptr;
      peers.clear();
      embree_all = make_embree(mesh, EmbreeMode::Default, 0);
    }
    if (embree_all)
      for (uint32_t threads : {1u, every}) {
        const Peer* p = embree_all.get();
        runners.push_back({p->name() + " (TBB)", [p, threads](const std::vector<Ray>& r, std::vector<Hit>& h, Query q) {
                             p->trace_on_cores(r, h, q, threads);
                           }});
      }
    for (size_t k = 0; k < kinds.size(); ++k)
      for (size_t q = 0; q < queries.size(); ++q) {
        const Query query = queries[q].query;
        if ((query != Query::Closest && query != Query::Any) || queries[q].cull != Cull::None) continue;
        // A batch of at least kCoreBatch rays (the set repeated): a few
        // milliseconds of work on two cores is within a thread's wake-up.
        if (rays[k].empty()) continue;
        std::vector<Ray> batch;
        while (batch.size() < kCoreBatch) batch.insert(batch.end(), rays[k].begin(), rays[k].end());
        std::vector<Hit> batch_hits(batch.size());
        std::vector<std::vector<double>> seconds(runners.size());
        for (uint32_t round = 0; round < o.rounds + 1; ++round)
          for (size_t i = 0; i < runners.size(); ++i) {
            const auto t0 = std::chrono::steady_clock::now();
            runners[i].trace(batch, batch_hits, query);
            if (round > 0) seconds[i].push_back(ms_since(t0) / 1e3);
          }
        std::vector<CoreRow> set_rows;
        for (size_t i = 0; i < runners.size(); i += 2) {
          CoreRow r{name, o.kinds[k], o.queries[q], runners[i].contender, every};
          r.rays_per_s_one = double(batch.size()) / median(seconds[i]);
          r.rays_per_s_all = double(batch.size()) / median(seconds[i + 1]);
          set_rows.push_back(r);
        }
        if (embree_all)  // the last pair is Embree default
          for (CoreRow& r : set_rows) r.ratio_all = set_rows.back().rays_per_s_all / r.rays_per_s_all;
        cores->insert(cores->end(), set_rows.begin(), set_rows.end());
      }
  }

  // A counting build (MESHCAST_COUNT_TESTS) also reports each meshcast
  // layout's box and triangle tests a ray, from one more pass (its times are
  // not for comparison).
  if constexpr (kCountTests)
    for (Contender& c : all)
      for (size_t s = 0; s < sets.size() && !c.is_peer && counts; ++s) {
        test_counts = {};
        if (!c.trace(rays[sets[s].kind], hits, queries[sets[s].query], sorted[sets[s].kind])) continue;
        const double n = double(o.rays);
        counts->push_back({name, set_names[sets[s].kind], o.queries[sets[s].query], c.name,
                           double(test_counts.nodes) / n, double(test_counts.leaves) / n,
                           double(test_counts.triangles) / n});
      }

  std::vector<PeerRow> rows;
  for (size_t s = 0; s < sets.size(); ++s) {
    double embree_default = 0, embree_high = 0, embree_packets = 0;
    std::vector<PeerRow> set_rows;
    for (Contender& c : all) {
      if (c.ns[s].empty()) continue;  // a query the contender does not answer
      PeerRow r{name, set_names[sets[s].kind], c.name, c.is_peer, median(c.ns[s]), 0, c.bytes, c.build_one, c.build_all,
                c.build_peak};
      r.query = o.queries[sets[s].query];
      // The same contender's closest hit on the same rays, when measured.
      for (size_t t = 0; t < sets.size(); ++t)
        if (sets[t].kind == sets[s].kind && o.queries[sets[t].query] == "closest")
          r.to_closest = r.ns_per_ray / median(c.ns[t]);
      // The ratios' peers: Embree's default and high-quality builds (by the
      // names make_embree gives them), its 16-wide packets.
      if (c.packets_peer) embree_packets = r.ns_per_ray;
      else if (c.is_peer && c.name.ends_with(" default")) embree_default = r.ns_per_ray;
      else if (c.is_peer && c.name.ends_with(" high quality")) embree_high = r.ns_per_ray;
      set_rows.push_back(r);
    }
    for (PeerRow& r : set_rows) {
      r.ratio = embree_default > 0 ? r.ns_per_ray / embree_default : 0;
      r.ratio_high = embree_high > 0 ? r.ns_per_ray / embree_high : 0;
      r.ratio_packets = embree_packets > 0 ? r.ns_per_ray / embree_packets : 0;
      rows.push_back(r);
    }
  }
  return rows;
}

}  // namespace meshcast::bench
