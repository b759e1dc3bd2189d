#include "layout/triangles/cluster.h"

#include <algorithm>
#include <cmath>

namespace meshcast::layout {

std::vector<ClusterBitPackSOA8::Plan> ClusterBitPackSOA8::plan(const TriCorners* tris, uint32_t count) {
  std::vector<Plan> plans;
  for (uint32_t i = 0; i < count; ++i) {
    const TriCorners& t = tris[i];
    // Each corner's vertex number in the open cluster (or the fresh ones it
    // would take), looked up once.
    auto place = [&](const Plan& p, int at[3]) {
      uint32_t fresh = 0;
      for (int c = 0; c < 3; ++c) {
        at[c] = int(std::find(p.vertices.begin(), p.vertices.end(), t.packed[c]) - p.vertices.begin());
        if (at[c] < int(p.vertices.size())) continue;
        const int same = int(std::find(t.packed, t.packed + c, t.packed[c]) - t.packed);  // an earlier corner's vertex
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
      if (at[c] == int(p.vertices.size())) p.vertices.push_back(t.packed[c]);
      p.corner.push_back(uint8_t(at[c]));
    }
    ++p.count;
  }
  for (Plan& p : plans) {
    uint32_t lo[3] = {MC_BITPACK_MAX, MC_BITPACK_MAX, MC_BITPACK_MAX}, hi[3] = {0, 0, 0};
    for (uint64_t w : p.vertices)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], bitpack_component(w, a)), hi[a] = std::max(hi[a], bitpack_component(w, a));
    p.origin = 0;
    for (int a = 0; a < 3; ++a) {
      p.origin |= uint64_t(lo[a]) << (MC_BITPACK_BITS * a);
      p.wide = p.wide || hi[a] - lo[a] > 0xFFFF;
    }
  }
  return plans;
}

uint32_t ClusterBitPackSOA8::measure(TriCorners* tris, uint32_t count) {
  uint32_t bytes = 0;
  for (const Plan& p : plan(tris, count)) bytes += cluster_bytes(uint32_t(p.vertices.size()), p.count, p.wide);
  return (bytes + 3) / 4 * 4;
}

void ClusterBitPackSOA8::encode(TriCorners* tris, uint32_t count, BlockContext&, uint8_t* out) {
  uint32_t at = 0;
  for (const Plan& p : plan(tris, count)) {
    uint8_t* c = out + at;
    const uint32_t v = uint32_t(p.vertices.size());
    std::memcpy(c, &p.origin, 8);
    c[8] = uint8_t(v | (p.wide ? MC_CLUSTER_WIDE : 0u));
    c[9] = uint8_t(p.count);
    for (uint32_t b = 0; b < (p.count + 7) / 8; ++b)
      for (int k = 0; k < 3; ++k) {
        uint32_t word = 0;
        for (uint32_t lane = 0; lane < 8; ++lane) {
          const uint32_t i = std::min(b * 8 + lane, p.count - 1);  // padding repeats the last triangle
          word |= uint32_t(p.corner[3 * i + uint32_t(k)]) << (4 * lane);
        }
        std::memcpy(c + MC_CLUSTER_HEADER_BYTES + b * MC_CLUSTER_INDEX_BLOCK_BYTES + 4 * uint32_t(k), &word, 4);
      }
    uint8_t* rows = c + MC_CLUSTER_HEADER_BYTES + (p.count + 7) / 8 * MC_CLUSTER_INDEX_BLOCK_BYTES;
    const uint32_t padded = v + (p.wide ? 0 : v & 1);  // Z's padding: rows are read in 4-byte words
    for (int a = 0; a < 3; ++a)
      for (uint32_t k = 0; k < (a == 2 ? padded : v); ++k) {
        const uint32_t offset = k < v ? bitpack_component(p.vertices[k], a) - bitpack_component(p.origin, a) : 0;
        if (p.wide) std::memcpy(rows + 4 * (uint32_t(a) * v + k), &offset, 4);
        else {
          const uint16_t o16 = uint16_t(offset);
          std::memcpy(rows + 2 * (uint32_t(a) * v + k), &o16, 2);
        }
      }
    at += cluster_bytes(v, p.count, p.wide);
  }
  while (at % 4) out[at++] = 0;
  // The triangles keep their order and their corners already lie on the
  // grid (the writer decoded them with bitpack_decode): nothing to hand back.
}

uint64_t ClusterBitPackSOA8::stored_bytes(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit) {
  uint64_t at = 0;
  uint32_t made = 0;
  while (made < count) {
    if (at + MC_CLUSTER_HEADER_BYTES > limit) return 0;
    const uint32_t c = uint32_t(block + at), v = vertex_count(blob, c), t = triangle_count(blob, c);
    if (v == 0 || v > MC_CLUSTER_MAX_VERTICES || (blob[c + 8] & 0x60) || t == 0 || t > MC_CLUSTER_MAX_TRIANGLES ||
        made + t > count)
      return 0;
    at += bytes_of(blob, c);
    made += t;
    if (at > limit) return 0;
  }
  at = (at + 3) / 4 * 4;
  return at <= limit ? at : 0;
}

void ClusterBitPackSOA8::decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
  const BlobHeader& h = header_of(blob);
  uint32_t at = block;
  while (i >= triangle_count(blob, at)) i -= triangle_count(blob, at), at += bytes_of(blob, at);
  for (int c = 0; c < 3; ++c) {
    const uint32_t k = corner(blob, at, i, c);
    for (int a = 0; a < 3; ++a) out[c][a] = std::fma(float(code(blob, at, k, a)), h.quant_scale[a], h.quant_offset[a]);
  }
}

void ClusterBitPackSOA8::decode_leaf(const uint8_t* blob, uint32_t block, uint32_t count, float (*out)[3][3]) {
  const BlobHeader& h = header_of(blob);
  uint32_t at = block, made = 0;
  while (made < count) {
    const uint32_t v = vertex_count(blob, at), t = std::min(triangle_count(blob, at), count - made);
    float vertex[MC_CLUSTER_MAX_VERTICES][3];
    for (uint32_t k = 0; k < v; ++k)
      for (int a = 0; a < 3; ++a) vertex[k][a] = std::fma(float(code(blob, at, k, a)), h.quant_scale[a], h.quant_offset[a]);
    for (uint32_t i = 0; i < t; ++i)
      for (int c = 0; c < 3; ++c) {
        const uint32_t k = corner(blob, at, i, c);
        for (int a = 0; a < 3; ++a) out[made + i][c][a] = vertex[k][a];
      }
    made += t;
    at += bytes_of(blob, at);
  }
}

bool ClusterBitPackSOA8::check(const uint8_t* blob, uint32_t block, uint32_t count, std::string* why) {
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
      for (int a = 0; a < 3; ++a)
        if (uint64_t(code(blob, at, k, a)) > MC_BITPACK_MAX) {
          *why = "cluster at blob offset " + std::to_string(at) + ": vertex " + std::to_string(k) +
                 " lies off the 21-bit mesh grid";
          return false;
        }
    made += t;
    at += bytes_of(blob, at);
  }
  return true;
}

}  // namespace meshcast::layout
