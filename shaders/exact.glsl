// Arithmetic the CPU does in one rounding that a Vulkan device may not:
// Vulkan lets fma() round twice, so the CPU's std::fma (the BitPack decode
// of layout/triangles/block.cpp) is rebuilt from double operations, which Vulkan does
// round correctly: the product of two floats is exact in double, the sum is
// rounded to odd (TwoSum, then the last bit set when anything was lost), and
// the one conversion to float then rounds exactly as a fused fma would
// (Boldo and Melquiond 2008).
#ifndef MESHCAST_EXACT_GLSL
#define MESHCAST_EXACT_GLSL

float fma_exact(float a, float b, float c) {
  precise double p = double(a) * double(b);
  precise double s = p + double(c);
  precise double bb = s - p;
  precise double e = (p - (s - bb)) + (double(c) - bb);
  if (e != 0.0lf) {
    uvec2 bits = unpackDouble2x32(s);
    if ((bits.x & 1u) == 0u) {  // even: step one ulp toward the lost part, making it odd
      const bool away = (e > 0.0lf) == (s > 0.0lf);
      uint64_t m = (uint64_t(bits.y) << 32) | uint64_t(bits.x);
      m = away ? m + 1ul : m - 1ul;
      s = packDouble2x32(uvec2(uint(m & 0xFFFFFFFFul), uint(m >> 32)));
    }
  }
  return float(s);
}

// a / b rounded once, as the CPU's IEEE division: Vulkan bounds a float
// division's error at 2.5 ulp (and a double one no tighter), so the
// quotient taken in double, rounded to float, may be one float ulp off.
// Of it and its two neighbours the correctly rounded one leaves the least
// remainder a - q b, exact in double (a float product fits in a double;
// the difference of two doubles within a factor of 2 is exact); a tie (a
// quotient half way) goes to the even one. Zeros and infinities as IEEE.
float div_exact(float a, float b) {
  const uint sign = (floatBitsToUint(a) ^ floatBitsToUint(b)) & 0x80000000u;
  if (a == 0.0 || isinf(b)) return uintBitsToFloat(sign);
  if (b == 0.0 || isinf(a)) return uintBitsToFloat(sign | 0x7F800000u);
  const float q = float(double(a) / double(b));
  const uint m = floatBitsToUint(abs(q));
  if (m == 0u || m >= 0x7F800000u) return q;  // under- or overflow: no neighbour to weigh
  uint best = m;
  precise double r = abs(double(a) - double(uintBitsToFloat(sign | m)) * double(b));
  for (int step = -1; step <= 1; step += 2) {
    const uint n = uint(int(m) + step);
    precise double rn = abs(double(a) - double(uintBitsToFloat(sign | n)) * double(b));
    if (rn < r || (rn == r && (n & 1u) == 0u)) best = n, r = rn;
  }
  return uintBitsToFloat(sign | best);
}

// IEEE binary16 to float, exactly (ldexp is exact in Vulkan; subnormal
// halves are kept, never flushed).
float half_to_float_exact(uint h) {
  const uint e = (h >> 10) & 31u, m = h & 1023u;
  float v;
  if (e == 0u) v = ldexp(float(m), -24);
  else if (e == 31u) v = m == 0u ? uintBitsToFloat(0x7F800000u) : uintBitsToFloat(0x7FC00000u);
  else v = ldexp(float(m + 1024u), int(e) - 25);
  return (h >> 15) != 0u ? -v : v;
}

#endif
