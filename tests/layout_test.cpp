// layout/: half-float directed rounding, bit packing, blob validation, and
// corrupted blobs (run under AddressSanitizer by the CI's sanitizer job).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "io/generate.h"
#include "layout/blob.h"
#include "layout/block.h"
#include "layout/half.h"
#include "tests/testing.h"

#if !defined(MESHCAST_SCALAR)
#include <immintrin.h>
#endif

namespace meshcast::testing {
namespace {

using namespace layout;

// Every finite half, in increasing order: the independent reference for the
// directed conversions.
std::vector<float> all_finite_halves() {
  std::vector<float> v;
  for (uint32_t h = 0; h < 0x10000; ++h) {
    float f = half_to_float(uint16_t(h));
    if (std::isfinite(f)) v.push_back(f);
  }
  std::sort(v.begin(), v.end());
  return v;
}

TEST(Half, DecodeMatchesHardware) {
#if defined(MESHCAST_SCALAR)
  GTEST_SKIP() << "scalar build: no F16C to compare with";
#else
  for (uint32_t h = 0; h < 0x10000; ++h) {
    float hw = _mm_cvtss_f32(_mm_cvtph_ps(_mm_cvtsi32_si128(int(h))));
    float sw = half_to_float(uint16_t(h));
    if (std::isnan(hw)) EXPECT_TRUE(std::isnan(sw)) << h;
    else EXPECT_EQ(std::bit_cast<uint32_t>(hw), std::bit_cast<uint32_t>(sw)) << h;
  }
#endif
}

TEST(Half, DirectedRoundingIsTightAndOutward) {
  std::vector<float> halves = all_finite_halves();
  std::mt19937 rng(5);
  std::vector<float> probes = {0.0f, -0.0f, 1e-9f, -1e-9f, 6.0e-8f, 65504.0f, 65505.0f, -65504.0f, 70000.0f,
                               -1e30f, 1e30f, 1.0f / 3.0f, -2.5f};
  for (int i = 0; i < 20000; ++i)
    probes.push_back(std::ldexp(std::uniform_real_distribution<float>(-1, 1)(rng), int(rng() % 40) - 24));
  for (float f : probes) {
    float down = half_to_float(float_to_half_down(f)), up = half_to_float(float_to_half_up(f));
    EXPECT_LE(down, f);
    EXPECT_GE(up, f);
    // Tight: no finite half lies strictly between the result and f.
    auto below = std::upper_bound(halves.begin(), halves.end(), f);
    float expect_down = below == halves.begin() ? -INFINITY : *(below - 1);
    auto above = std::lower_bound(halves.begin(), halves.end(), f);
    float expect_up = above == halves.end() ? INFINITY : *above;
    EXPECT_EQ(down, expect_down) << f;
    EXPECT_EQ(up, expect_up) << f;
  }
}

TEST(BitPack, RoundTripWithinHalfAStep) {
  float offset[3] = {-3.0f, 1000.0f, 0.0f}, scale[3];
  float extent[3] = {6.0f, 0.15f, 0.0f};
  for (int a = 0; a < 3; ++a) scale[a] = extent[a] / float(MC_BITPACK_MAX);
  float bound[3];
  quantization_bound(offset, scale, bound);
  std::mt19937 rng(9);
  for (int i = 0; i < 100000; ++i) {
    float v[3], d[3];
    for (int a = 0; a < 3; ++a) v[a] = offset[a] + std::uniform_real_distribution<float>(0, 1)(rng) * extent[a];
    uint64_t w = bitpack_encode(v, offset, scale);
    EXPECT_EQ(w >> 63, 0u);
    bitpack_decode(w, offset, scale, d);
    for (int a = 0; a < 3; ++a) ASSERT_LE(std::fabs(d[a] - v[a]), bound[a]) << a;
  }
}

std::vector<std::vector<uint8_t>> sample_blobs() {
  std::vector<std::vector<uint8_t>> blobs;
  Mesh sphere = make_sphere(12, 24, 1.0f, {0, 0, 0});
  Mesh grid = make_grid_plane(9, 7);
  for (const std::string& name : layout_names())
    for (const Mesh* m : {&sphere, &grid}) blobs.push_back(build_blob(*m, parse_layout(name), name));
  return blobs;
}

TEST(Blob, FreshBlobsValidate) {
  for (const auto& blob : sample_blobs()) EXPECT_EQ(validate(blob), "");
}

TEST(Blob, TruncationIsRefusedWithAReason) {
  for (const auto& blob : sample_blobs()) {
    for (size_t len : {size_t(0), size_t(3), size_t(100), size_t(160), blob.size() / 2, blob.size() - 1}) {
      std::vector<uint8_t> cut(blob.begin(), blob.begin() + std::ptrdiff_t(len));
      std::string why = validate(cut);
      EXPECT_NE(why, "") << len;
      EXPECT_TRUE(why.find("bytes") != std::string::npos || why.find("truncated") != std::string::npos) << why;
    }
  }
}

TEST(Blob, AnyFlippedByteIsRefused) {
  std::mt19937 rng(3);
  for (const auto& blob : sample_blobs())
    for (int i = 0; i < 200; ++i) {
      std::vector<uint8_t> bad = blob;
      bad[rng() % bad.size()] ^= uint8_t(1 + rng() % 255);
      EXPECT_NE(validate(bad), "");
    }
}

// The structural checks on their own: corrupt, re-seal so the checksum
// matches, then either validation refuses the blob or every walk ends with
// an answer that names a real triangle. Under ASan this also proves no read
// leaves the blob.
TEST(Blob, ResealedCorruptionIsRefusedOrWalkedSafely) {
  std::mt19937 rng(11);
  std::vector<Ray> rays = make_rays(make_sphere(12, 24, 1.0f, {0, 0, 0}), RayKind::Long, 64, 2);
  for (Ray& r : make_rays(make_grid_plane(9, 7), RayKind::Long, 64, 3)) rays.push_back(r);
  size_t refused = 0, walked = 0;
  for (const auto& blob : sample_blobs()) {
    const uint32_t triangles = header_of(blob.data()).triangle_count;
    for (int i = 0; i < 400; ++i) {
      std::vector<uint8_t> bad = blob;
      int flips = 1 + int(rng() % 4);
      for (int f = 0; f < flips; ++f) {
        // Half the flips land in the header, where every field matters.
        size_t at = (rng() & 1) ? rng() % sizeof(BlobHeader) : rng() % bad.size();
        bad[at] ^= uint8_t(1u << (rng() % 8));
      }
      if (bad.size() >= sizeof(BlobHeader)) seal(bad);
      if (!validate(bad).empty()) {
        ++refused;
        continue;
      }
      ++walked;
      BlobView view(bad, "corrupted");
      std::vector<Hit> hits(rays.size());
      view.trace(rays, hits);
      for (const Hit& h : hits) ASSERT_TRUE(h.triangle == MC_NO_HIT || h.triangle < triangles);
    }
  }
  EXPECT_GT(refused, 0u);
  EXPECT_GT(walked, 0u);  // flips of bounds or vertices still give a valid blob
}

}  // namespace
}  // namespace meshcast::testing
