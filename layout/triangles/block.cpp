#include <algorithm>
#include <cmath>

#include "layout/triangles/indexed8bitpacksoa4.h"

namespace meshcast::layout {

void bitpack_decode(uint64_t w, const float offset[3], const float scale[3], float out[3]) {
  for (int a = 0; a < 3; ++a) out[a] = std::fma(float(bitpack_component(w, a)), scale[a], offset[a]);
}

uint32_t quantize(float v, float offset, float scale, uint32_t max) {
  if (!(scale > 0)) return 0;
  double guess = std::clamp(std::round((double(v) - offset) / scale), 0.0, double(max));
  // Of the grid points around the guess, keep the one whose decode (the
  // walker's own fma) lands nearest the original.
  uint32_t q = uint32_t(guess);
  float best = std::fabs(std::fma(float(q), scale, offset) - v);
  for (int64_t c = int64_t(guess) - 1; c <= int64_t(guess) + 1; ++c) {
    if (c < 0 || c > int64_t(max)) continue;
    float err = std::fabs(std::fma(float(c), scale, offset) - v);
    if (err < best) best = err, q = uint32_t(c);
  }
  return q;
}

uint64_t bitpack_encode(const float v[3], const float offset[3], const float scale[3]) {
  uint64_t w = 0;
  for (int a = 0; a < 3; ++a) w |= uint64_t(quantize(v[a], offset[a], scale[a], MC_BITPACK_MAX)) << (MC_BITPACK_BITS * a);
  return w;
}

void Indexed8BitPackSOA4::encode(TriCorners* tris, uint32_t count, BlockContext& ctx, uint8_t* out) {
  std::vector<uint8_t>& pool = *ctx.pool;
  // Window [base, base + 256): ends 3*count past the pool's current end.
  uint64_t end = pool.size() / 8 + 3ull * count;
  uint32_t base = end > MC_I8_WINDOW ? uint32_t(end - MC_I8_WINDOW) : 0u;
  constexpr uint32_t kMaxLanes = (MC_QUAD_MAX_COUNT + 3) / 4 * 4;
  if (count == 0 || count > MC_QUAD_MAX_COUNT) return;  // the writer never asks for this
  uint8_t idx[3][kMaxLanes];
  for (uint32_t i = 0; i < count; ++i)
    for (int c = 0; c < 3; ++c) {
      uint64_t w = tris[i].packed[c];
      auto it = ctx.last_index->find(w);
      uint32_t at;
      if (it != ctx.last_index->end() && it->second >= base) {
        at = it->second;
      } else {
        at = pool_append(pool, &w, 8);
        (*ctx.last_index)[w] = at;
      }
      idx[c][i] = uint8_t(at - base);
    }
  // Padding lanes repeat the last triangle.
  for (uint32_t i = count; i < blocks(count) * 4; ++i)
    for (int c = 0; c < 3; ++c) idx[c][i] = idx[c][count - 1];
  uint32_t offset = ctx.vertex_section + 8 * base - ctx.block_address;
  std::memcpy(out, &offset, 4);
  for (uint32_t b = 0; b < blocks(count); ++b)
    for (int c = 0; c < 3; ++c)
      for (uint32_t lane = 0; lane < 4; ++lane)
        out[MC_I8_HEADER_BYTES + b * MC_I8_BLOCK_BYTES + c * 4 + lane] = idx[c][b * 4 + lane];
}

bool Indexed8BitPackSOA4::check(const uint8_t* blob, uint32_t block, uint32_t count, std::string* why) {
  const BlobHeader& h = header_of(blob);
  uint64_t first = uint64_t(block) + load<uint32_t>(blob + block);
  for (uint32_t i = 0; i < blocks(count) * 4; ++i)
    for (int c = 0; c < 3; ++c) {
      uint64_t at = first + 8ull * index(blob, block, i, c);
      if (at < h.vertex_offset || at + 8 > uint64_t(h.vertex_offset) + h.vertex_size) {
        *why = "Indexed8BitPackSOA4 block at " + std::to_string(block) + " indexes a vertex at byte " +
               std::to_string(at) + ", outside the vertex section [" + std::to_string(h.vertex_offset) + ", " +
               std::to_string(h.vertex_offset + h.vertex_size) + ")";
        return false;
      }
    }
  return true;
}

}  // namespace meshcast::layout

#include "layout/triangles/strip.h"

namespace meshcast::layout {

std::vector<StripVertex> stripify(TriCorners* tris, uint32_t count) {
  std::vector<StripVertex> seq;
  std::vector<TriCorners> order;
  std::vector<bool> used(count, false);
  auto vertex = [](const TriCorners& t, int c, uint32_t flag) {
    return StripVertex{{t.v[c][0], t.v[c][1], t.v[c][2]}, t.vertex[c], flag};
  };
  for (uint32_t start = 0; start < count; ++start) {
    if (used[start]) continue;
    used[start] = true;
    TriCorners prev = tris[start];
    seq.push_back(vertex(prev, 0, kStartV1));
    seq.push_back(vertex(prev, 1, kStartV2));
    seq.push_back(vertex(prev, 2, 0));
    order.push_back(prev);
    // Extend through any unused triangle sharing an edge with `prev`.
    for (bool grew = true; grew;) {
      grew = false;
      for (uint32_t u = 0; u < count && !grew; ++u) {
        if (used[u]) continue;
        // Of the flags that reach u through a shared edge, prefer one that
        // keeps u's winding (A, B, C a rotation of u's corners): both orders
        // of every edge are available (flags 0/5, 1/6, 2/4).
        uint32_t flags[6] = {0u, 1u, 2u, 4u, 5u, 6u};
        std::stable_sort(flags, flags + 6, [&](uint32_t x, uint32_t y) {
          auto keeps = [&](uint32_t f) {
            int a = int(f & 3), b = (a + 1 + int(f >> 2)) % 3;
            for (int k = 0; k < 3; ++k)
              if (tris[u].vertex[k] == prev.vertex[a] && tris[u].vertex[(k + 1) % 3] == prev.vertex[b]) return true;
            return false;
          };
          return keeps(x) && !keeps(y);
        });
        for (uint32_t flag : flags) {
          int a = int(flag & 3), b = (a + 1 + int(flag >> 2)) % 3;
          // Take A and B out of u's corners; the one left is C.
          int left[3] = {0, 1, 2}, n = 3;
          auto take = [&](uint32_t id) {
            for (int k = 0; k < n; ++k)
              if (tris[u].vertex[left[k]] == id) return left[k] = left[--n], true;
            return false;
          };
          if (!take(prev.vertex[a]) || !take(prev.vertex[b])) continue;
          TriCorners next = tris[u];
          int c = left[0];
          for (int k = 0; k < 3; ++k) next.v[0][k] = prev.v[a][k], next.v[1][k] = prev.v[b][k], next.v[2][k] = tris[u].v[c][k];
          next.vertex[0] = prev.vertex[a], next.vertex[1] = prev.vertex[b], next.vertex[2] = tris[u].vertex[c];
          seq.push_back(vertex(next, 2, flag));
          order.push_back(next);
          used[u] = true;
          prev = next;
          grew = true;
          break;
        }
      }
    }
  }
  std::copy(order.begin(), order.end(), tris);
  return seq;
}

}  // namespace meshcast::layout
