// The queries and cullings of meshcast/ray.h as the rest of the code meets
// them: the bits of the flags word the CPU walkers and the Vulkan methods
// read (MC_QUERY_* and MC_CULL_* in layout/formats.h), and the names the
// command line and the benchmarks take. One place for each.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

#include "layout/formats.h"
#include "meshcast/errors.h"
#include "meshcast/ray.h"

namespace meshcast::layout {

// Values outside the enums give no bits; BlobView::trace refuses them first.
constexpr uint32_t query_bits(Query query, Cull cull) {
  return (query == Query::Any ? MC_QUERY_ANY : query == Query::All ? MC_QUERY_ALL : 0u) |
         (cull == Cull::Back ? MC_CULL_BACK : cull == Cull::Front ? MC_CULL_FRONT : 0u);
}

// UsageError naming `who` for a query or a culling outside its enum (an
// integer cast into it): every entry point checks before it walks. A view:
// a check that passes allocates nothing (a warm caster's jobs make it).
inline void check_query(std::string_view who, Query query, Cull cull) {
  if (query != Query::Closest && query != Query::Any && query != Query::All)
    throw UsageError(std::string(who) + ": query " + std::to_string(uint32_t(query)) +
                     " is not Query::Closest, Query::Any or Query::All");
  if (cull != Cull::None && cull != Cull::Back && cull != Cull::Front)
    throw UsageError(std::string(who) + ": cull " + std::to_string(uint32_t(cull)) +
                     " is not Cull::None, Cull::Back or Cull::Front");
}

// closest, any, all; UsageError naming `option` for anything else.
inline Query query_named(const std::string& name, const std::string& option) {
  if (name == "closest") return Query::Closest;
  if (name == "any") return Query::Any;
  if (name == "all") return Query::All;
  throw UsageError(option + ": '" + name + "' is not closest, any or all");
}

// none (two-sided), back, front; UsageError naming `option` otherwise.
inline Cull cull_named(const std::string& name, const std::string& option) {
  if (name == "none") return Cull::None;
  if (name == "back") return Cull::Back;
  if (name == "front") return Cull::Front;
  throw UsageError(option + ": '" + name + "' is not none, back or front");
}

// A query and its culling in one name, QUERY or QUERY-CULL: "any",
// "closest-back" (bench peers' --queries).
struct QuerySpec {
  Query query = Query::Closest;
  Cull cull = Cull::None;
};
inline QuerySpec query_spec_named(const std::string& name, const std::string& option) {
  const size_t dash = name.find('-');
  if (dash == std::string::npos) return {query_named(name, option), Cull::None};
  const std::string whole = option + " '" + name + "'";
  return {query_named(name.substr(0, dash), whole), cull_named(name.substr(dash + 1), whole)};
}

}  // namespace meshcast::layout
