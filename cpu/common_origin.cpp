// Common-origin batches (cpu/common_origin.h).
#include "cpu/common_origin.h"

#include <cmath>
#include <cstring>

namespace meshcast {

bool share_one_origin(std::span<const Ray> rays) {
  if (rays.empty()) return false;
  for (const Ray& r : rays)
    if (std::memcmp(r.org, rays[0].org, sizeof r.org) != 0) return false;
  return true;
}

namespace {

// Bits 0..7 of v spread to the even bits of a 16-bit word.
uint32_t spread8(uint32_t v) {
  v = (v | (v << 4)) & 0x0F0F;
  v = (v | (v << 2)) & 0x3333;
  v = (v | (v << 1)) & 0x5555;
  return v;
}

uint32_t direction_key(const Ray& r) {
  const float x = r.dir[0], y = r.dir[1], z = r.dir[2];
  const float l1 = std::fabs(x) + std::fabs(y) + std::fabs(z);
  if (!(l1 > 0) || !std::isfinite(l1)) return 0;
  float u = x / l1, v = y / l1;
  if (z < 0) {  // the lower half folded out over the square's corners
    const float fu = (1 - std::fabs(v)) * (u < 0 ? -1.0f : 1.0f);
    const float fv = (1 - std::fabs(u)) * (v < 0 ? -1.0f : 1.0f);
    u = fu, v = fv;
  }
  auto cell = [](float w) {
    const float c = std::floor((w * 0.5f + 0.5f) * 256.0f);
    return uint32_t(std::fmin(std::fmax(c, 0.0f), 255.0f));
  };
  return spread8(cell(u)) | spread8(cell(v)) << 1;
}

}  // namespace

void order_by_direction(std::span<const Ray> rays, std::span<uint32_t> order, std::span<uint16_t> keys,
                        std::span<uint32_t> scratch) {
  const size_t n = rays.size();
  for (size_t i = 0; i < n; ++i) keys[i] = uint16_t(direction_key(rays[i]));
  const std::span<uint32_t> low = scratch;  // the order by the low byte
  // Low byte first, then the high byte, each pass stable.
  for (int pass = 0; pass < 2; ++pass) {
    const int shift = 8 * pass;
    uint32_t start[257] = {};
    for (size_t i = 0; i < n; ++i) ++start[(keys[i] >> shift & 0xFF) + 1];
    for (int b = 0; b < 256; ++b) start[b + 1] += start[b];
    if (pass == 0) {
      for (size_t i = 0; i < n; ++i) low[start[keys[i] & 0xFF]++] = uint32_t(i);
    } else {
      for (size_t k = 0; k < n; ++k) {
        const uint32_t i = low[k];
        order[start[keys[i] >> 8]++] = i;
      }
    }
  }
}

}  // namespace meshcast
