#include "layout/triangles/cluster.h"

#include <algorithm>
#include <cmath>

namespace meshcast::layout {

template <ClusterVertices kVertices>
auto Cluster<kVertices>::plan(const TriCorners* tris, uint32_t count) -> std::vector<Plan> {
  std::vector<Plan> plans;
  for (uint32_t i = 0; i < count; ++i) {
    const TriCorners& t = tris[i];
    const Key key[3] = {key_of(t, 0), key_of(t, 1), key_of(t, 2)};
    // Each corner's vertex number in the open cluster (or the fresh ones it
    // would take), looked up once.
    auto place = [&](const Plan& p, int at[3]) {
      uint32_t fresh = 0;
      for (int c = 0; c < 3; ++c) {
        at[c] = int(std::find(p.vertices.begin(), p.vertices.end(), key[c]) - p.vertices.begin());
        if (at[c] < int(p.vertices.size())) continue;
        const int same = int(std::find(key, key + c, key[c]) - key);  // an earlier corner's vertex
        at[c] = same < c ? at[same] : int(p.vertices.size() + fresh++);
      }
      return p.vertices.size() + fresh;
    };
    int at[3];
    if (plans.empty() || plans.back().count >= MC_CLUSTER_MAX_TRIANGLES ||
        place(plans.back(), at) > MC_CLUSTER_MAX_VERTICES) {
      plans.push_back({i, 0, {}, {}, 0, false});
      place(plans.back(), at);
    }
    Plan& p = plans.back();
    for (int c = 0; c < 3; ++c) {
      if (at[c] == int(p.vertices.size())) p.vertices.push_back(key[c]);
      p.corner.push_back(uint8_t(at[c]));
    }
    ++p.count;
  }
  if constexpr (!kExact) {
    for (Plan& p : plans) {
      uint32_t lo[3] = {MC_BITPACK_MAX, MC_BITPACK_MAX, MC_BITPACK_MAX}, hi[3] = {0, 0, 0};
      for (uint64_t w : p.vertices)
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], bitpack_component(w, a)), hi[a] = std::max(hi[a], bitpack_component(w, a));
      for (int a = 0; a < 3; ++a) {
        p.origin |= uint64_t(lo[a]) << (MC_BITPACK_BITS * a);
        p.wide = p.wide || hi[a] - lo[a] > 0xFFFF;
      }
    }
  }
  return plans;
}

template <ClusterVertices kVertices>
uint32_t Cluster<kVertices>::measure(TriCorners* tris, uint32_t count) {
  uint32_t bytes = 0;
  for (const Plan& p : plan(tris, count)) bytes += cluster_bytes(uint32_t(p.vertices.size()), p.count, p.wide);
  return (bytes + 3) / 4 * 4;
}

template <ClusterVertices kVertices>
void Cluster<kVertices>::encode(TriCorners* tris, uint32_t count, BlockContext&, uint8_t* out) {
  uint32_t at = 0;
  for (const Plan& p : plan(tris, count)) {
    uint8_t* c = out + at;
    const uint32_t v = uint32_t(p.vertices.size());
    const uint32_t bytes = cluster_bytes(v, p.count, p.wide);
    std::memset(c, 0, bytes);
    if constexpr (!kExact) std::memcpy(c, &p.origin, 8);
    c[kCountsAt] = uint8_t(v | (p.wide ? MC_CLUSTER_WIDE : 0u));
    c[kCountsAt + 1] = uint8_t(p.count);
    for (uint32_t b = 0; b < (p.count + 7) / 8; ++b)
      for (int k = 0; k < 3; ++k) {
        uint32_t word = 0;
        for (uint32_t lane = 0; lane < 8; ++lane) {
          const uint32_t i = std::min(b * 8 + lane, p.count - 1);  // padding repeats the last triangle
          word |= uint32_t(p.corner[3 * i + uint32_t(k)]) << (4 * lane);
        }
        std::memcpy(c + kHeaderBytes + b * MC_CLUSTER_INDEX_BLOCK_BYTES + 4 * uint32_t(k), &word, 4);
      }
    uint8_t* rows = c + kHeaderBytes + (p.count + 7) / 8 * MC_CLUSTER_INDEX_BLOCK_BYTES;
    for (int a = 0; a < 3; ++a)
      for (uint32_t k = 0; k < v; ++k) {
        uint8_t* to = rows + row_bytes(v, p.wide) * uint32_t(a) + (row_bytes(v, p.wide) / v) * k;
        if constexpr (kExact) {
          std::memcpy(to, &p.vertices[k][uint32_t(a)], 4);
        } else {
          const uint32_t offset = bitpack_component(p.vertices[k], a) - bitpack_component(p.origin, a);
          if (p.wide) std::memcpy(to, &offset, 4);
          else {
            const uint16_t o16 = uint16_t(offset);
            std::memcpy(to, &o16, 2);
          }
        }
      }
    at += bytes;
  }
  while (at % 4) out[at++] = 0;
  // The triangles keep their order and their corners are already what the
  // walker decodes (floats as given, or grid points the writer decoded
  // with bitpack_decode): nothing to hand back.
}

template <ClusterVertices kVertices>
uint64_t Cluster<kVertices>::stored_bytes(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit) {
  uint64_t at = 0;
  uint32_t made = 0;
  while (made < count) {
    if (at + kHeaderBytes > limit) return 0;
    const uint32_t c = uint32_t(block + at), v = vertex_count(blob, c), t = triangle_count(blob, c);
    // The count byte's unused bits, and the float header's padding, are 0.
    const bool spare_bits = kExact ? (blob[c] & 0xE0) || blob[c + 2] || blob[c + 3] : (blob[c + 8] & 0x60) != 0;
    if (v == 0 || v > MC_CLUSTER_MAX_VERTICES || spare_bits || t == 0 || t > MC_CLUSTER_MAX_TRIANGLES || made + t > count)
      return 0;
    at += bytes_of(blob, c);
    made += t;
    if (at > limit) return 0;
  }
  at = (at + 3) / 4 * 4;
  return at <= limit ? at : 0;
}

template <ClusterVertices kVertices>
void Cluster<kVertices>::decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
  const BlobHeader& h = header_of(blob);
  uint32_t at = block;
  while (i >= triangle_count(blob, at)) i -= triangle_count(blob, at), at += bytes_of(blob, at);
  for (int c = 0; c < 3; ++c) {
    const uint32_t k = corner(blob, at, i, c);
    for (int a = 0; a < 3; ++a) out[c][a] = vertex(blob, h, at, k, a);
  }
}

template <ClusterVertices kVertices>
void Cluster<kVertices>::decode_leaf(const uint8_t* blob, uint32_t block, uint32_t count, float (*out)[3][3]) {
  const BlobHeader& h = header_of(blob);
  uint32_t at = block, made = 0;
  while (made < count) {
    const uint32_t v = vertex_count(blob, at), t = std::min(triangle_count(blob, at), count - made);
    float decoded[MC_CLUSTER_MAX_VERTICES][3];
    for (uint32_t k = 0; k < v; ++k)
      for (int a = 0; a < 3; ++a) decoded[k][a] = vertex(blob, h, at, k, a);
    for (uint32_t i = 0; i < t; ++i)
      for (int c = 0; c < 3; ++c) {
        const uint32_t k = corner(blob, at, i, c);
        for (int a = 0; a < 3; ++a) out[made + i][c][a] = decoded[k][a];
      }
    made += t;
    at += bytes_of(blob, at);
  }
}

template <ClusterVertices kVertices>
bool Cluster<kVertices>::check(const uint8_t* blob, uint32_t block, uint32_t count, std::string* why) {
  const BlobHeader& h = header_of(blob);
  uint32_t at = block, made = 0;
  while (made < count) {
    const uint32_t v = vertex_count(blob, at), t = triangle_count(blob, at);
    for (uint32_t i = 0; i < (t + 7) / 8 * 8; ++i)
      for (int c = 0; c < 3; ++c)
        if (corner(blob, at, i, c) >= v) {
          *why = "cluster at blob offset " + std::to_string(at) + ": triangle lane " + std::to_string(i) + " names vertex " +
                 std::to_string(corner(blob, at, i, c)) + " of " + std::to_string(v);
          return false;
        }
    for (uint32_t k = 0; k < v; ++k)
      for (int a = 0; a < 3; ++a) {
        if constexpr (kExact) {
          if (!std::isfinite(vertex(blob, h, at, k, a))) {
            *why = "cluster at blob offset " + std::to_string(at) + ": vertex " + std::to_string(k) + " is not finite";
            return false;
          }
        } else if (uint64_t(code(blob, at, k, a)) > MC_BITPACK_MAX) {
          *why = "cluster at blob offset " + std::to_string(at) + ": vertex " + std::to_string(k) +
                 " lies off the 21-bit mesh grid";
          return false;
        }
      }
    made += t;
    at += bytes_of(blob, at);
  }
  return true;
}

template struct Cluster<ClusterVertices::GridOffsets>;
template struct Cluster<ClusterVertices::Floats>;

}  // namespace meshcast::layout
