#include "layout/tree/half.h"

#include <bit>
#include <cmath>
#include <limits>

namespace meshcast::layout {

float half_to_float(uint16_t h) {
  uint32_t sign = uint32_t(h & 0x8000u) << 16;
  uint32_t exp = (h >> 10) & 0x1Fu;
  uint32_t man = h & 0x3FFu;
  if (exp == 0x1F) return std::bit_cast<float>(sign | 0x7F800000u | (man << 13));
  if (exp == 0) {  // zero or subnormal: man * 2^-24, exact in float
    float v = std::ldexp(float(man), -24);
    return sign ? -v : v;
  }
  return std::bit_cast<float>(sign | ((exp + 112u) << 23) | (man << 13));
}

namespace {

// Half values are ordered like sign-magnitude integers; step one unit toward
// +inf or -inf from a given half.
uint16_t next_up(uint16_t h) {
  if (h == 0x8000u) return 0x0001u;                 // -0 -> smallest positive
  if (h & 0x8000u) return uint16_t(h - 1);          // negative: magnitude shrinks
  return h == 0x7C00u ? h : uint16_t(h + 1);
}
uint16_t next_down(uint16_t h) {
  if (h == 0x0000u) return 0x8001u;
  if (h & 0x8000u) return h == 0xFC00u ? h : uint16_t(h + 1);
  return uint16_t(h - 1);
}

// Round to nearest half (ties away from zero is enough: the caller corrects
// the direction), saturating to infinity above the half range.
uint16_t float_to_half_near(float f) {
  uint16_t sign = std::signbit(f) ? 0x8000u : 0u;
  float a = std::fabs(f);
  if (std::isnan(f)) return 0x7E00u;
  if (a >= 65520.0f) return uint16_t(sign | 0x7C00u);
  if (a < std::ldexp(1.0f, -14)) {  // subnormal range: multiples of 2^-24
    uint32_t m = uint32_t(std::lround(std::ldexp(a, 24)));
    return uint16_t(sign | m);  // m <= 1024 carries into the exponent correctly
  }
  int e;
  float m = std::frexp(a, &e);  // a = m * 2^e, m in [0.5, 1)
  uint32_t mant = uint32_t(std::lround(std::ldexp(m, 11)));  // 11 significant bits
  uint32_t exp = uint32_t(e - 1 + 15);
  if (mant == 2048) { mant = 1024; ++exp; }
  if (exp >= 31) return uint16_t(sign | 0x7C00u);
  return uint16_t(sign | (exp << 10) | (mant - 1024));
}

}  // namespace

uint16_t float_to_half_down(float f) {
  if (std::isnan(f)) return 0xFC00u;  // -inf: the widest bound
  uint16_t h = float_to_half_near(f);
  while (half_to_float(h) > f) h = next_down(h);
  return h;
}

uint16_t float_to_half_up(float f) {
  if (std::isnan(f)) return 0x7C00u;
  uint16_t h = float_to_half_near(f);
  while (half_to_float(h) < f) h = next_up(h);
  return h;
}

}  // namespace meshcast::layout

#include "layout/tree/quadtree.h"

namespace meshcast::layout {

uint16_t QuadBoundsHalf::encode_one(float v, const BlobHeader& hd, int axis, bool up) {
  if (std::isinf(v)) return v > 0 ? 0x7C00u : 0xFC00u;  // unused child
  float rel = float((double(v) - hd.node_origin[axis]) / hd.node_scale);
  uint16_t h = up ? float_to_half_up(rel) : float_to_half_down(rel);
  // The decode adds rounding of its own; step outward until it is on our side.
  for (int guard = 0; guard < 64; ++guard) {
    float d = decode_one(h, hd, axis);
    if (up ? d >= v : d <= v) return h;
    float f = half_to_float(h);
    h = up ? float_to_half_up(std::nextafter(f, INFINITY)) : float_to_half_down(std::nextafter(f, -INFINITY));
  }
  return up ? 0x7C00u : 0xFC00u;  // never reached in practice; infinity is always outward
}

}  // namespace meshcast::layout
