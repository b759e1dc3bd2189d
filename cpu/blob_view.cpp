// BlobView (meshcast/blob.h): a validated blob and its walker, and the
// batches it walks.
#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "cpu/common_origin.h"
#include "cpu/scratch.h"
#include "cpu/walk_table.h"
#include "layout/blob_format.h"
#include "layout/queries.h"
#include "meshcast/blob.h"

namespace meshcast {

BlobView::BlobView(std::span<const uint8_t> bytes, const std::string& name) : bytes_(bytes) {
  std::string why = layout::validate(bytes);
  if (!why.empty()) throw InputError(name + ": " + why);
  const layout::BlobHeader& h = layout::header_of(bytes.data());
  walk_ = walker_for(h.tree_format, h.triangle_format);
  if (!walk_) throw InputError(name + ": no walker for this layout");
  walks_packets_ = h.tree_format == uint32_t(TreeFormat::OctTreeCompressed);
}

namespace {

// The walkers' flags word: only the outputs' own bits (the query's and the
// culling's share the word), checked names for the rest.
uint32_t flags_of(const char* who, HitOutputs outputs, Query query, Cull cull) {
  layout::check_query(who, query, cull);
  return (uint32_t(outputs) & (MC_HIT_UV | MC_HIT_POINT)) | layout::query_bits(query, cull);
}

// The fewest rays of one origin worth sorting into packets.
constexpr size_t kLeastPacketBatch = 32;
constexpr size_t kPacketPiece = 65536;

}  // namespace

uint64_t BlobView::trace(std::span<const Ray> rays, std::span<Hit> hits, HitOutputs outputs, Query query,
                         Cull cull, Packets packets) const {
  if (hits.size() < rays.size())
    throw UsageError("BlobView::trace: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(hits.size()) + " hits; the hits span must hold one hit a ray");
  if (query == Query::All)
    throw UsageError("BlobView::trace: Query::All has a list of hits a ray: BlobView::trace_all_hits answers it");
  if (packets != Packets::Auto && packets != Packets::Off)
    throw UsageError("BlobView::trace: packets " + std::to_string(uint32_t(packets)) + " is neither Auto nor Off");
  WalkRequest request{flags_of("BlobView::trace", outputs, query, cull)};
  uint64_t skipped = 0;
  const size_t n = rays.size();
  if (packets == Packets::Auto && walks_packets_ && n >= kLeastPacketBatch && share_one_origin(rays)) {
    // The rays by direction, walked as packets, the hits put back in place;
    // a piece of the batch at a time, so the thread's scratch stays small
    // (a piece of 65,536 rays of one origin is dense enough in directions).
    request.packets = true;
    for (size_t begin = 0; begin < n; begin += kPacketPiece) {
      const size_t m = std::min(kPacketPiece, n - begin);
      const std::span<uint32_t> orders = thread_scratch<uint32_t>(2 * m);  // the order, and the sort's own
      const std::span<uint32_t> order = orders.first(m);
      const std::span<Ray> sorted = thread_scratch<Ray>(m);
      const std::span<Hit> sorted_hits = thread_scratch<Hit>(m);
      order_by_direction(rays.subspan(begin, m), order, thread_scratch<uint16_t>(m), orders.subspan(m));
      for (size_t k = 0; k < m; ++k) sorted[k] = rays[begin + order[k]];
      walk_(bytes_.data(), sorted.data(), sorted_hits.data(), m, &skipped, request);
      for (size_t k = 0; k < m; ++k) hits[begin + order[k]] = sorted_hits[k];
    }
    return skipped;
  }
  walk_(bytes_.data(), rays.data(), hits.data(), n, &skipped, request);
  return skipped;
}

namespace {

// Query::All walks a few rays at a time into a thread's scratch rows
// (cpu/scratch.h), at most kScratchRecords records (448 KiB) whatever
// max_hits, and copies each ray's kept hits out: the answers' memory and
// time follow the hits found, not rays x max_hits.
constexpr size_t kScratchRecords = 16384;
constexpr size_t kMostRaysAWalk = 64;

}  // namespace

uint64_t BlobView::trace_all_hits(std::span<const Ray> rays, HitLists& lists, HitOutputs outputs, Cull cull) const {
  const uint32_t max_hits = lists.max_hits;
  if (max_hits < 1 || max_hits > kMaxHitsLimit)
    throw UsageError("BlobView::trace_all_hits: max_hits " + std::to_string(max_hits) + " is not in 1.." +
                     std::to_string(kMaxHitsLimit));
  const uint32_t flags = flags_of("BlobView::trace_all_hits", outputs, Query::All, cull);
  lists.clear();
  lists.found.reserve(rays.size());
  lists.offsets.reserve(rays.size() + 1);
  const size_t per_walk = std::clamp<size_t>(kScratchRecords / max_hits, 1, kMostRaysAWalk);
  const std::span<Hit> rows = thread_scratch<Hit>(per_walk * max_hits);
  uint32_t found[kMostRaysAWalk];
  const WalkRequest request{flags, max_hits, found, rows.data()};
  uint64_t skipped = 0;
  for (size_t begin = 0; begin < rays.size(); begin += per_walk) {
    const size_t n = std::min(per_walk, rays.size() - begin);
    walk_(bytes_.data(), rays.data() + begin, nullptr, n, &skipped, request);
    for (size_t i = 0; i < n; ++i)
      lists.add_row(found[i], rows.subspan(i * max_hits, std::min(found[i], max_hits)));
  }
  return skipped;
}

Layout BlobView::layout() const {
  const layout::BlobHeader& h = layout::header_of(bytes_.data());
  return {TreeFormat(h.tree_format), TriangleFormat(h.triangle_format)};
}

uint32_t BlobView::triangle_count() const { return layout::header_of(bytes_.data()).triangle_count; }

}  // namespace meshcast
