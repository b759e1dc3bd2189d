// Shared test helpers: the test meshes, oracle answers computed once per
// mesh and ray set, and the agreement rules of the foundation issue.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <initializer_list>
#include <functional>
#include <map>
#include <tuple>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "check/agreement.h"
#include "builder/auto_layout.h"
#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "meshcast/mesh.h"
#include "check/oracle.h"
#include "check/ray_files.h"
#include "meshcast/blob.h"

namespace meshcast::testing {

// data/NAME.off under $MESHCAST_DATA, or nullopt if it is not there.
std::optional<Mesh> data_mesh(const std::string& name);

struct NamedMesh {
  std::string name;
  std::shared_ptr<const Mesh> mesh;
};
// Files a test makes: a folder of this process's own under the system's
// temp folder (removed when the process exits), and a file of `bytes` in it.
std::filesystem::path scratch_dir();
std::string make_file(const std::string& name, const std::string& bytes);

// Generated meshes plus the four public ones when present. `large` adds the
// 1M+ triangle terrain. In the quick runs (MESHCAST_TEST_QUICK set: the
// sanitizer builds and the second and third instruction sets, see
// scripts/test.sh) the 64k terrain and every public mesh but the smallest,
// ChineseDragon-10kv (20k triangles), are left out.
std::vector<NamedMesh> test_meshes(bool large);
// The public mesh that suites walking a chosen few meshes take: bunny00, or
// in the quick runs the one public mesh they have.
bool is_chosen_public_mesh(const std::string& name);
// The smallest public mesh (ChineseDragon-10kv, a quarter of bunny00's
// triangles): the quick runs' one, and the one that suites whose time
// grows with rays times triangles (a brute force on lavapipe) take.
bool is_smallest_public_mesh(const std::string& name);
// True when MESHCAST_TEST_QUICK is set: the suites walk fewer rays a set.
bool quick();
// The layouts of `names` a suite runs: all of them, or in the quick runs a
// few that still take every tree format and every triangle format at least
// once, the trees on different formats where the names allow: each
// walker's node code and each codec's leaf code run, not every pairing.
std::vector<std::string> covering_layouts(const std::vector<std::string>& names);
// That covering few whether quick or not.
std::vector<std::string> covering_subset(const std::vector<std::string>& names);

// Oracle answers (tree oracle) for a ray set, cached per (mesh, kind, set
// size, culling): the closest hits, and Query::All's sets.
const std::vector<OracleHit>& oracle_answers(const NamedMesh& m, RayKind kind, const std::vector<Ray>& rays,
                                             Cull cull = Cull::None);
const std::vector<std::vector<OracleHit>>& oracle_all_answers(const NamedMesh& m, RayKind kind,
                                                              const std::vector<Ray>& rays, Cull cull = Cull::None);
const std::vector<Ray>& test_rays(const NamedMesh& m, RayKind kind, size_t count = 10000);

// `outputs`: the per-hit outputs asked for (MC_HIT_*).
std::vector<Hit> trace_all(const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, uint64_t* skipped = nullptr,
                           uint32_t outputs = 0, Query query = Query::Closest, Cull cull = Cull::None);
// The same through a view validated once (validation reads the whole
// blob: several queries on one blob pay it once).
std::vector<Hit> trace_all(const BlobView& view, const std::vector<Ray>& rays, Query query = Query::Closest,
                           Cull cull = Cull::None);
// Query::All on every ray, rows of `max_hits`.
HitLists trace_lists(const BlobView& view, const std::vector<Ray>& rays, uint32_t max_hits, Cull cull = Cull::None);

// The rays again with a t_min each, from the oracle's closest hit t of each
// (`closest`, on those rays): half of it (the same first hit), 1.25 and 2
// times it (past the first hit: the next one along, or a miss), in turn;
// a ray that misses gets half its t_max, or 1 where that is infinite.
std::vector<Ray> with_t_min(const std::vector<Ray>& rays, const std::vector<OracleHit>& closest);

// What check_queries traces: hits for a query and culling, or rows of
// `max_hits` for Query::All (a CPU blob view, a Vulkan method).
struct QueryTracer {
  std::function<std::vector<Hit>(const std::vector<Ray>&, Query, Cull)> hits;
  std::function<HitLists(const std::vector<Ray>&, uint32_t max_hits, Cull)> rows;
};
// What check_queries traced, for a caller's own comparisons.
struct QueryAnswers {
  Cull cull, all_cull;  // the culling of `culled` and `any`, of `all`
  std::vector<Hit> culled, any;
  HitLists all;
};
// The queries against the oracle over `reference` (the mesh as the blob
// stores it) on `rays` of `kind`: the closest hit culled (back faces on
// long rays, front faces on the others) and any hit culled alike, each
// with the oracle's answer under the same culling; every hit in rows of
// `max_hits` (front faces culled on long rays) against the oracle's sets.
// A failure names `what`.
QueryAnswers check_queries(const QueryTracer& trace, const NamedMesh& reference, RayKind kind,
                           const std::vector<Ray>& rays, double tolerance, uint32_t max_hits, const std::string& what);
// The three queries on with_t_min(rays) against the oracle on the same
// rays: the closest and any hit unculled, every hit in rows of `max_hits`
// (front faces culled on long rays, as check_queries); some rays keep
// their first hit and some skip it. Returns the rays and their closest hits.
struct TMinAnswers {
  std::vector<Ray> rays;
  std::vector<Hit> closest;
};
TMinAnswers check_t_min_queries(const QueryTracer& trace, const NamedMesh& reference, RayKind kind,
                                const std::vector<Ray>& rays, double tolerance, uint32_t max_hits,
                                const std::string& what);

// `planes` unit squares (two triangles each) stacked at z = 0, 1, ...,
// and `count` rays straight down from above them, each through every plane
// and clear of the squares' diagonals: a ray's hits are one a plane, at t =
// top - z. What truncated rows of every hit are checked on.
Mesh stacked_planes(int planes);
std::vector<Ray> rays_down_through(int planes, size_t count);
// Query::All rows of `max_hits` against the oracle's sets over `mesh` (the
// mesh as the blob stores it): each row the nearest max_hits of its set,
// found[i] the set's size. A failure names `what`.
void expect_nearest_rows(const Mesh& mesh, const std::vector<Ray>& rays, const HitLists& lists, const std::string& what);

// The same surface with every triangle owning its three vertices (as STL
// gives it): a triangle soup, no vertex shared.
Mesh unwelded(const Mesh& m);

// `hits` against the double-precision oracle over the mesh `blob` stores
// (the input mesh, or stored_mesh(blob) for the formats that move
// vertices and for blobs without a remap, whose hits name slots): same
// triangle, t within 1e-5 of the diagonal. A failure names
// `what` and the first problem. Returns how many rays hit.
size_t expect_oracle(const Mesh& mesh, const std::vector<uint8_t>& blob, const std::vector<Ray>& rays,
                     const std::vector<Hit>& hits, const std::string& what);

// The automatic layout's settings the suites run (auto_test, the stiff
// suite), as parse_auto_setting reads them: speed first, with a 256-ray
// trial, memory first, memory under a 2e-6 error bound, and speed under 20
// bytes a triangle (past the fast layouts).
std::vector<std::string> auto_settings();

// `call` must throw E whose message holds every one of `words`.
template <class E, class F>
void expect_throws(F&& call, std::initializer_list<std::string> words) {
  try {
    call();
    ADD_FAILURE() << "no error; expected one naming '" << *words.begin() << "'";
  } catch (const E& e) {
    const std::string message = e.what();
    for (const std::string& w : words) EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' not in: " << message;
  }
}

}  // namespace meshcast::testing
