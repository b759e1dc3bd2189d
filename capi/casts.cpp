#include "capi/casts.h"

#include <string>

namespace meshcast::capi {

namespace {
constexpr size_t kQueryV1 = sizeof(meshcast_query);
}

meshcast_query query_defaults() {
  meshcast_query q{};
  q.struct_size = sizeof q;
  q.kind = MESHCAST_CLOSEST;
  q.cull = MESHCAST_CULL_NONE;
  q.mask = 0xFF;
  q.threads = 1;
  return q;
}

CastQuery cast_query(const meshcast_query* query) {
  const meshcast_query q = sized(query, query_defaults(), kQueryV1, "query");
  CastQuery c;
  if (q.kind > MESHCAST_ANY)
    throw UsageError("query->kind " + std::to_string(q.kind) + ": MESHCAST_CLOSEST (0) or MESHCAST_ANY (1)");
  c.query = q.kind == MESHCAST_ANY ? Query::Any : Query::Closest;
  if (q.cull > MESHCAST_CULL_FRONT)
    throw UsageError("query->cull " + std::to_string(q.cull) + ": MESHCAST_CULL_NONE, _BACK or _FRONT (0, 1, 2)");
  c.cull = q.cull == MESHCAST_CULL_BACK ? Cull::Back : q.cull == MESHCAST_CULL_FRONT ? Cull::Front : Cull::None;
  if (q.outputs & ~(MESHCAST_HIT_UV | MESHCAST_HIT_POINT))
    throw UsageError("query->outputs " + std::to_string(q.outputs) + ": MESHCAST_HIT_UV and MESHCAST_HIT_POINT alone");
  c.outputs = HitOutputs(q.outputs);
  if (q.mask > 0xFF) throw UsageError("query->mask " + std::to_string(q.mask) + ": 8 bits (0..255)");
  c.mask = uint8_t(q.mask);
  c.threads = threads_of(q.threads);
  return c;
}

void check_max_hits(uint32_t max_hits) {
  if (max_hits < 1 || max_hits > kMaxHitsLimit)
    throw UsageError("max_hits " + std::to_string(max_hits) + ": from 1 to " + std::to_string(kMaxHitsLimit));
}

uint64_t row_records(uint64_t rays, uint32_t max_hits) {
  uint64_t records;
  if (__builtin_mul_overflow(rays, uint64_t(max_hits), &records))
    throw UsageError(std::to_string(rays) + " rows of " + std::to_string(max_hits) + " hits overflow 64 bits");
  return records;
}

}  // namespace meshcast::capi

extern "C" void meshcast_query_init(meshcast_query* query) {
  if (query) *query = meshcast::capi::query_defaults();
}
