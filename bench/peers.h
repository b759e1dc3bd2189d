// `meshcast bench peers`: meshcast's layouts beside Embree's
// default, robust and compact builds on the same rays in one run: rounds
// interleave every contender and ray kind, the median of the rounds is
// reported, tracing on one thread.
#pragma once
#include <string>
#include <vector>

#include "builder/ray_sets.h"
#include "meshcast/mesh.h"

namespace meshcast::bench {

struct PeerRow {
  std::string mesh, kind, contender;
  bool is_peer = false;       // an Embree build
  double ns_per_ray = 0;      // median of the rounds
  double ratio = 0;           // to Embree default on the same mesh and rays (0 without Embree)
  double bytes_per_triangle;  // all included: the blob with its remap; Embree's scene and the mesh it keeps
  double build_ms_one = 0;    // one thread
  double build_ms_all = 0;    // every core (BuildOptions::threads 0; Embree's threads)
  // The resident memory the first build (one thread) added at its peak, the
  // structure it keeps included, a triangle (bench/peak_memory.h; 0 where
  // it cannot be read).
  double build_peak_bytes_per_triangle = 0;
  // closest, any (Embree: rtcOccluded1), all (every hit, rows of 16) or
  // closest-back (back faces culled): Embree rows for the first two only
  // (its culling is a compile-time option), so `ratio` is 0 for the others.
  std::string query = "closest";
  double to_closest = 0;          // time / the same contender's closest-hit time on the same rays (0: not measured)
  double ratio_high = 0;          // to Embree's high-quality build (RTC_BUILD_QUALITY_HIGH), as `ratio`
  // A sorted set (KIND sorted: one origin's rays by direction): to Embree
  // default's 16-wide packets on the same rays (0 elsewhere).
  double ratio_packets = 0;
};

// A multi-core row: rays a second on one thread and on every core, the
// same rays and query. meshcast: the Caster's CPU batch (its own pool of
// `threads` workers); Embree: a TBB loop over rtcIntersect1 or
// rtcOccluded1 in an arena of that many threads.
struct CoreRow {
  std::string mesh, kind, query, contender;
  uint32_t cores = 0;             // "every core": the hardware threads
  double rays_per_s_one = 0;      // median of the rounds
  double rays_per_s_all = 0;
  double scaling() const { return rays_per_s_one > 0 ? rays_per_s_all / rays_per_s_one : 0; }
  double ratio_all = 0;           // time on every core / Embree default's on every core (0 without Embree)
};

// A counting build's (MESHCAST_COUNT_TESTS) one more walk of each meshcast
// layout on each set: inner nodes (a node's children tested together),
// leaves and triangle lanes tested, a ray. Its times are not for comparison.
struct CountRow {
  std::string mesh, kind, query, contender;
  double nodes = 0, leaves = 0, triangles = 0;
};

// The names PeersOptions::peers takes, in the order the builds are measured.
const std::vector<std::string>& embree_build_names();

struct PeersOptions {
  std::vector<std::string> layouts;  // meshcast layouts to measure
  std::vector<std::string> kinds = ray_kind_names();  // ray kinds measured
  std::vector<std::string> queries = {"closest", "any"};          // each kind under each query (see PeerRow)
  size_t rays = 10000;               // a set, for each kind
  uint32_t rounds = 7;
  bool cores = true;                 // the multi-core rows (the first layout and Embree default)
  // A kind whose rays share one origin (radial) timed again sorted by
  // direction: meshcast's packets, Embree's single rays and 16-wide packets.
  bool packets = true;
  // Embree's builds measured (a counting Embree's counters then name one):
  // default, high, robust, compact.
  std::vector<std::string> peers = embree_build_names();
  // The build times (every contender built again in rounds); without them
  // the rows' build columns are 0.
  bool build_times = true;
};

// The meshcast layouts `bench peers` measures unless told otherwise.
std::vector<std::string> default_peer_layouts();

// `cores`: the multi-core rows are appended there (when options.cores);
// `counts`: a counting build's rows (nothing in a timed build).
std::vector<PeerRow> bench_peers(const Mesh& mesh, const std::string& name, const PeersOptions& options,
                                 std::vector<CoreRow>* cores = nullptr, std::vector<CountRow>* counts = nullptr);

}  // namespace meshcast::bench
