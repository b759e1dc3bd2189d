// nearest_on_triangles (cpu/walk_points.h): the nearest points of a leaf's
// near triangles, 8 side by side, compiled once an instruction set. Each
// lane makes nearest_on_triangle's own operations (cpu/point_triangle.h)
// in its order, with no fused multiply-add (the build's -ffp-contract=off),
// so each answer has its bits whatever the set: the region is picked by
// selects in place of its branches (every region's candidate is worked
// out, the others' divisions by zero dropped). A triangle of no area takes
// nearest_on_triangle itself, after the lanes. (Written with the
// compiler's vector types: its loop vectorizer left the branchy form one
// lane at a time.)
#include <algorithm>

#include "cpu/point_triangle.h"
#include "cpu/walk_points.h"

namespace meshcast {
MC_ISA_BEGIN

namespace {
// 8 doubles, in GCC's vector extension: each set's compiler lowers the
// operations to its widest registers (two AVX2 registers, one AVX-512
// register, or one lane at a time), each lane's arithmetic IEEE's, as a
// double's.
constexpr uint32_t kLanes = 8;
using D = double __attribute__((vector_size(kLanes * sizeof(double))));
using Mask = int64_t __attribute__((vector_size(kLanes * sizeof(int64_t))));
// (The sum as nearest_on_triangle's dot takes it. Out through a reference:
// a vector returned by value is a different ABI on each set, which gcc warns of.)
[[gnu::always_inline]] inline void dot(const D x[3], const D y[3], D& sum) { sum = x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; }
}  // namespace

void nearest_on_triangles(const double p[3], const double (*corners)[3][3], uint32_t n, PointOnTriangle* out) {
  for (uint32_t first = 0; first < n; first += kLanes) {
    // Lanes past n repeat the last triangle (their answers are dropped).
    D c[3][3] = {};  // [corner][axis], a triangle a lane
    for (uint32_t i = 0; i < kLanes; ++i) {
      const double(&t)[3][3] = corners[std::min(first + i, n - 1)];
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) c[k][a][i] = t[k][a];
    }
    D ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int k = 0; k < 3; ++k) {
      ab[k] = c[1][k] - c[0][k], ac[k] = c[2][k] - c[0][k];
      ap[k] = p[k] - c[0][k], bp[k] = p[k] - c[1][k], cp[k] = p[k] - c[2][k];
    }
    D d1, d2, d3, d4, d5, d6;
    dot(ab, ap, d1), dot(ac, ap, d2), dot(ab, bp, d3), dot(ac, bp, d4), dot(ab, cp, d5), dot(ac, cp, d6);
    const D vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    const D area = va + vb + vc;
    const D normal[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
    D normal2, ab2, ac2;
    dot(normal, normal, normal2), dot(ab, ab, ab2), dot(ac, ac, ac2);
    const Mask flat = ~(normal2 > 0x1p-60 * ab2 * ac2);
    // The regions in nearest_on_triangle's order: the first that holds is
    // the one taken, so the selects run from the last to the first.
    const Mask at_a = (d1 <= 0) & (d2 <= 0);
    const Mask at_b = (d3 >= 0) & (d4 <= d3);
    const Mask on_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0);
    const Mask at_c = (d6 >= 0) & (d5 <= d6);
    const Mask on_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0);
    const Mask on_bc = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0);
    const D zero = {}, one = zero + 1;
    const D s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    D u = vb / area, v = vc / area;
    u = on_bc ? one - s : u, v = on_bc ? s : v;
    u = on_ac ? zero : u, v = on_ac ? d2 / (d2 - d6) : v;
    u = at_c ? zero : u, v = at_c ? one : v;
    u = on_ab ? d1 / (d1 - d3) : u, v = on_ab ? zero : v;
    u = at_b ? one : u, v = at_b ? zero : v;
    u = at_a ? zero : u, v = at_a ? zero : v;
    D point[3], d2_sum = zero;
    for (int k = 0; k < 3; ++k) {
      point[k] = c[0][k] + u * ab[k] + v * ac[k];
      const D d = p[k] - point[k];
      d2_sum = d2_sum + d * d;
    }
    for (uint32_t i = 0; i < kLanes && first + i < n; ++i) {
      PointOnTriangle& o = out[first + i];
      if (flat[i]) {
        const double(&t)[3][3] = corners[first + i];
        o = nearest_on_triangle(p, t[0], t[1], t[2]);
        continue;
      }
      o.u = u[i], o.v = v[i], o.d2 = d2_sum[i];
      for (int k = 0; k < 3; ++k) o.point[k] = point[k][i];
    }
  }
}

MC_ISA_END
}  // namespace meshcast
