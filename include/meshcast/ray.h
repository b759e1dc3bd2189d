// Rays and the hits they get: the records every walker, shader and file
// (RAYS, HITS, HITN) shares. A ray is o + t d for t in [tmin, tmax]; d need
// not be normalized and t is in units of d. Triangles are two-sided (unless a
// query culls, see Cull) and the test is watertight: a ray through a shared
// edge or vertex hits one of its triangles.
#pragma once
#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast {

// A hit needs tmin <= t <= tmax, both ends included, compared on the
// float t the hit reports, by every walker, query and Vulkan method alike.
// tmin comes last so that every initialisation written before it existed,
// Ray{{ox, oy, oz}, {dx, dy, dz}, tmax}, keeps its meaning (tmin 0), as
// does a Ray declared and then filled field by field. 32 bytes: two
// 16-byte loads (origin and dir x; dir y, z, tmax, tmin). A RAYS file's
// record is the first 7 floats (tmin is read as 0).
//
// A secondary ray (a shadow or a reflection) from a hit: the hit point
// p = org + t dir (HitOutputs::Point) is rounded, so it lies off the hit
// triangle's plane by some h, and a ray from p along d meets that plane
// again at t' = h / |dot(d, n)| (n the unit normal; t' in units of d), on
// either side: with tmin 0 about half of such rays hit their own triangle.
// h comes from roundings of numbers no larger than m, the largest
// coordinate of p and of the primary origin: the primary t (a few ulps,
// times |t dir| <= 2m), org + t dir (half an ulp of m an axis) and the
// secondary test's corners taken relative to p (a few ulps of m); each is
// k 2^-24 m for a small k. Hence
//   tmin = 0x1p-16f * m / |dot(d, n)|
// (d of any length), 256 ulps of m: a margin of tens over their sum (the
// tests measure self-hits at most 2% of it, every layout, a mesh at the
// origin and 10^4 units out). It is relative, as rounding is: 1.5e-5 for a
// hit 1 unit from the origin, 0.15 for one 10^4 out. A d grazing the
// surface (small |dot(d, n)|) gets a long tmin and may pass geometry that
// close: no offset avoids both.
struct Ray {
  float org[3];
  float dir[3];
  float tmax;
  float tmin = 0;
};
static_assert(sizeof(Ray) == 32, "Ray is two 16-byte words (a rays-file record is its first 7 floats)");

// How every walker, shader and the oracle read a direction component: one
// below FLT_MIN in magnitude (a denormal) as 0, its sign kept. Its
// reciprocal would overflow float, which the box test cannot take (a box
// the ray crosses within t = 1 was culled), and a GPU flushes it to 0
// anyway. The ray then moves less than 2^-126 a unit of t off its course.
inline float walked_direction(float d) { return std::fabs(d) < FLT_MIN ? std::copysign(0.0f, d) : d; }

// A miss's triangle number.
constexpr uint32_t kNoHit = 0xFFFFFFFFu;

struct Hit {
  float t = INFINITY;        // INFINITY on a miss
  uint32_t triangle = kNoHit;  // the index in the caller's mesh (the input order)
  // Only when asked for (HitOutputs::Uv): barycentrics of corners 1 and 2
  // (strips: of a rotation of the triangle's corners, the winding kept).
  float u = 0, v = 0;
  float point[3] = {0, 0, 0};  // only when asked for (HitOutputs::Point): org + t * dir
};
static_assert(sizeof(Hit) == 28, "the Vulkan methods' hit record (shaders/hits.glsl) is the same 7 words");

// What a hit carries besides t and the triangle, computed only when asked
// for (on either backend): flags, combined with |.
enum class HitOutputs : uint32_t { None = 0, Uv = 1, Point = 2 };
constexpr HitOutputs operator|(HitOutputs a, HitOutputs b) { return HitOutputs(uint32_t(a) | uint32_t(b)); }
constexpr bool has(HitOutputs set, HitOutputs flag) { return (uint32_t(set) & uint32_t(flag)) != 0; }

// The question a trace answers: the closest hit along [tmin, tmax] (the
// default), or any hit there ("is anything in the way?": line of sight,
// shadow and audio probes), where the walk ends at the first triangle it
// takes and the hit names that triangle and its t, not the nearest.
// Query::All answers every hit along the segment (BlobView::trace_all_hits,
// what a bullet or a sound passes through).
enum class Query : uint32_t { Closest = 0, Any = 1, All = 2 };

// Query::All's answers for a batch of rays, compact: memory follows the
// hits found, not rays x max_hits. Ray i found found[i] hits along its
// segment; the nearest min(found[i], max_hits) of them are row(i), the
// records hits[offsets[i], offsets[i + 1]), in order of t, then triangle;
// `hits` holds nothing else (no padding, no misses). offsets has one entry
// more than the rays, offsets[0] = 0 and the last = hits.size(). A found[i]
// above max_hits means found[i] - max_hits of the farthest were dropped
// (among hits of one t at the cut, which are kept depends on the walk). A
// triangle the ray meets exactly on an edge or vertex shared with others
// is one hit each of them. u and v only when asked for (on the CPU; the
// Vulkan rows carry t, the triangle and the point). The same rows hold a
// scene's hits (SceneHitLists, meshcast/scene.h).
//
// A trace clears the rows and appends a row a ray (clear(), add_row());
// the vectors keep their capacity, so rows reused from frame to frame stop
// allocating once they have held a frame's hits.
template <class Record>
struct HitRows {
  uint32_t max_hits = 16;
  std::vector<uint32_t> found;
  std::vector<size_t> offsets{0};
  std::vector<Record> hits;

  size_t rays() const { return found.size(); }
  std::span<const Record> row(size_t ray) const {
    return {hits.data() + offsets[ray], offsets[ray + 1] - offsets[ray]};
  }
  // No rays, max_hits kept, the capacity kept.
  void clear() {
    found.clear();
    hits.clear();
    offsets.assign(1, 0);
  }
  // The next ray's row: the records appended to `hits` since the last row
  // (its kept hits, at most max_hits), `found_hits` found in all.
  void end_row(uint32_t found_hits) {
    found.push_back(found_hits);
    offsets.push_back(hits.size());
  }
  void add_row(uint32_t found_hits, std::span<const Record> kept) {
    hits.insert(hits.end(), kept.begin(), kept.end());
    end_row(found_hits);
  }
  // The rays of `more` after these (rows of the same max_hits).
  void append(const HitRows& more) {
    assert(&more != this);  // its vectors would grow under the reads
    const size_t base = hits.size();
    found.insert(found.end(), more.found.begin(), more.found.end());
    hits.insert(hits.end(), more.hits.begin(), more.hits.end());
    for (size_t i = 1; i < more.offsets.size(); ++i) offsets.push_back(base + more.offsets[i]);
  }
};
using HitLists = HitRows<Hit>;
// The most hits a ray's row may keep.
constexpr uint32_t kMaxHitsLimit = 4096;

// Which faces a query sees. A triangle's front face is the one whose
// corners, in the caller's order, run counter-clockwise seen from the ray's
// origin (its normal (b - a) x (c - a) points back at the origin); formats
// that rotate or quantize corners keep that winding. Culling keeps the
// watertight test's promise: a ray through an edge shared by a front and a
// back face hits the one it keeps.
enum class Cull : uint32_t { None = 0, Back = 1, Front = 2 };

// Whether a batch whose rays all start at one point (a sensor, a probe, a
// point's visibility) is walked as packets: the rays sorted by direction
// and walked a few at a time, each node decoded once for them, on the
// layouts whose walker has packets (OctTreeCompressed). Auto finds such a
// batch by itself; Off walks every ray alone. The answers are the same bit
// for bit either way (a tie between triangles at one t goes to the lower
// one in the blob's order, whatever the walk's order); only the time
// differs.
enum class Packets : uint32_t { Auto = 0, Off = 1 };

// The largest direction component a ray may have.
constexpr float kMaxDirection = 0x1p126f;

// A ray the walkers walk: an origin within +-2^100 (kMaxCoordinate, the
// range of meshes), direction components within +-2^126 (so every
// reciprocal the tests use is a normal float: a GPU may flush denormals to
// 0) and not all below FLT_MIN (such a direction counts as zero), tmax not
// NaN and not negative (infinity allowed), tmin not NaN, not negative and
// not above tmax (tmin = tmax is the one point; infinity for both is
// walkable and hits nothing). Any other ray is answered as a miss and
// counted.
bool ray_is_walkable(const Ray& r);  // defined once in the library (cpu/ray_is_walkable.cpp)

}  // namespace meshcast
