// The one mechanism every cast of the package goes through: the caller's
// rays read in chunks (parallel.h), each chunk packed into the library's
// ray records, walked by a blob or a scene, and its answers handed to a
// writer that puts them where the API's arrays want them. Called without
// the GIL.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/scene.h"
#include "python/src/arrays.h"
#include "python/src/parallel.h"

namespace meshcast::python {

// A blob walks float rays in its own frame (the origin rounded to float).
struct BlobTarget {
  using RayRecord = Ray;
  using Record = Hit;
  const BlobView& view;
  const double* offset = nullptr;  // subtracted from every origin first (a geometry's centre)
  Packets packets = Packets::Auto;  // rays of one origin as packets (meshcast/ray.h)
  void pack(const RayArrays& rays, size_t begin, size_t n, Ray* out) const { rays.pack(begin, n, out, offset); }
  uint64_t trace(std::span<const Ray> r, std::span<Hit> h, HitOutputs o, Query q, Cull c) const {
    return view.trace(r, h, o, q, c, packets);
  }
  uint64_t trace_all(std::span<const Ray> r, HitLists& lists, HitOutputs o, Cull c) const {
    return view.trace_all_hits(r, lists, o, c);
  }
};

// A scene walks double-origin rays (a float32 origin widened exactly), on
// the frame committed when the cast began: every chunk of the cast sees
// that one, whatever another thread commits meanwhile.
struct SceneTarget {
  using RayRecord = RayD;
  using Record = SceneHit;
  std::shared_ptr<const SceneSnapshot> frame;
  uint8_t mask = 0xFF;
  SceneTarget(const Scene& scene, uint8_t mask) : frame(scene.snapshot()), mask(mask) {}
  static void pack(const RayArrays& rays, size_t begin, size_t n, RayD* out) { rays.pack(begin, n, out); }
  uint64_t trace(std::span<const RayD> r, std::span<SceneHit> h, HitOutputs o, Query q, Cull c) const {
    return trace_snapshot(*frame, r, h, o, q, c, mask);
  }
  uint64_t trace_all(std::span<const RayD> r, SceneHitLists& lists, HitOutputs o, Cull c) const {
    return trace_all_hits_snapshot(*frame, r, lists, o, c, mask);
  }
};

// Tallies a cast's refusals from its chunks, on any thread.
class RefusedTally {
 public:
  // A chunk of rays from `begin` refused `count`; refuses(i) says whether
  // ray begin + i alone is refused.
  template <class Refuses>
  void add(uint64_t count, size_t begin, size_t n, const Refuses& refuses) {
    if (count == 0) return;
    count_ += count;
    for (size_t i = 0; i < n; ++i)
      if (refuses(i)) {
        size_t seen = first_.load();
        while (begin + i < seen && !first_.compare_exchange_weak(seen, begin + i)) {
        }
        return;
      }
  }
  Refused result() const { return {count_.load(), first_.load()}; }

 private:
  std::atomic<uint64_t> count_{0};
  std::atomic<size_t> first_{SIZE_MAX};
};

// Closest or any hit: write(i, hit) for every ray i. Returns the rays the
// walk refused (raise_for_refused names the first).
template <class Target, class Write>
Refused cast_hits(const Target& target, const RayArrays& rays, Query query, Cull cull, HitOutputs outputs,
                   uint32_t threads, const Write& write) {
  using RayRecord = typename Target::RayRecord;
  using Record = typename Target::Record;
  const Chunks plan = plan_chunks(rays.count, threads);
  RefusedTally refused;
  for_each_chunk(plan, threads, [&](size_t chunk) {
    // A thread's buffers, kept from chunk to chunk and call to call.
    static thread_local std::vector<RayRecord> packed;
    static thread_local std::vector<Record> hits;
    const size_t begin = plan.begin(chunk), n = plan.end(chunk) - begin;
    packed.resize(n);
    hits.resize(n);
    target.pack(rays, begin, n, packed.data());
    const uint64_t r = target.trace(std::span<const RayRecord>(packed.data(), n), std::span<Record>(hits.data(), n),
                                    outputs, query, cull);
    refused.add(r, begin, n, [&](size_t i) {
      Record alone;
      return target.trace(std::span<const RayRecord>(&packed[i], 1), std::span<Record>(&alone, 1), outputs, query,
                          cull) != 0;
    });
    for (size_t i = 0; i < n; ++i) write(begin + i, hits[i]);
  });
  return refused.result();
}

// Every hit: the rows of each chunk, in ray order, for the caller to
// gather into arrays once their total is known.
template <class Target>
struct AllHits {
  std::vector<HitRows<typename Target::Record>> parts;
  Refused refused;
  size_t hits() const {
    size_t total = 0;
    for (const auto& p : parts) total += p.hits.size();
    return total;
  }
  // Calls row(i, found, hits) for every ray i, its kept hits in order.
  template <class Row>
  void for_each_row(const Row& row) const {
    size_t i = 0;
    for (const auto& p : parts)
      for (size_t r = 0; r < p.rays(); ++r, ++i) row(i, p.found[r], p.row(r));
  }
  // Calls ray(i, found, offset) for every ray i (its row starts at
  // `offset` of the gathered hits) and hit(j, record) for every kept hit j.
  template <class Ray, class Hit>
  void gather(const Ray& ray, const Hit& hit) const {
    size_t i = 0, offset = 0;
    for (const auto& p : parts) {
      for (size_t r = 0; r < p.rays(); ++r, ++i) ray(i, p.found[r], offset + p.offsets[r]);
      for (size_t h = 0; h < p.hits.size(); ++h) hit(offset + h, p.hits[h]);
      offset += p.hits.size();
    }
  }
};

template <class Target>
AllHits<Target> cast_all(const Target& target, const RayArrays& rays, Cull cull, HitOutputs outputs,
                         uint32_t max_hits, uint32_t threads) {
  using RayRecord = typename Target::RayRecord;
  const Chunks plan = plan_chunks(rays.count, threads);
  AllHits<Target> all;
  all.parts.resize(plan.chunks);
  RefusedTally refused;
  for_each_chunk(plan, threads, [&](size_t chunk) {
    static thread_local std::vector<RayRecord> packed;
    const size_t begin = plan.begin(chunk), n = plan.end(chunk) - begin;
    packed.resize(n);
    target.pack(rays, begin, n, packed.data());
    auto& rows = all.parts[chunk];
    rows.max_hits = max_hits;
    const uint64_t r = target.trace_all(std::span<const RayRecord>(packed.data(), n), rows, outputs, cull);
    refused.add(r, begin, n, [&](size_t i) {
      HitRows<typename Target::Record> alone;
      alone.max_hits = 1;
      return target.trace_all(std::span<const RayRecord>(&packed[i], 1), alone, outputs, cull) != 0;
    });
  });
  all.refused = refused.result();
  return all;
}

// max_hits as the library takes it (1 to kMaxHitsLimit), ValueError otherwise.
uint32_t checked_max_hits(long long max_hits);

}  // namespace meshcast::python
