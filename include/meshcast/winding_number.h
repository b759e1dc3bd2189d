// The generalized winding number of a blob's stored mesh at query points
// (Jacobson, Kavan and Sorkine-Hornung 2013): the triangles' signed solid
// angles seen from the point, over 4 pi. 1 inside a closed mesh wound
// outward (counter-clockwise seen from outside), -1 wound inward, 0
// outside; on a mesh with holes, gaps or self-intersections it varies
// smoothly in between, and |w| > 1/2 is the robust inside test.
//
// Evaluated on the blob's own tree as Barill, Dickson, Schmidt, Levin and
// Jacobson (2018) do: a cluster of triangles far enough from the point
// counts by its expansion about its centre (the area-weighted normal
// sum and its first moment, second order), a near one triangle by
// triangle (Van Oosterom and Strackee's formula, in double). Each answer
// comes with a bound on its error that holds for any mesh: a cluster of
// area A whose triangles lie within r of its centre, at distance s from
// the point, is off its exact sum by at most 3 A r^2 / (4 pi (s - r)^4)
// (the third derivatives of 1/|x| are at most 3!/|x|^4), and the bound is
// the sum over the clusters expanded. A cluster is expanded where that
// is at most `tolerance` times its own largest contribution (A / (4 pi
// (s - r)^2)), so the bound is at most `tolerance` times the sum of the
// clusters' absolute solid angles: about `tolerance` for a point seeing
// the mesh once around. A cluster is expanded where its gap to the point
// is at least sqrt(3 / tolerance) times its radius: the looser the
// tolerance, the fewer clusters are opened.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/mesh.h"

namespace meshcast {

class WindingNumbers {
 public:
  // Reads the moments of every cluster of the blob's tree once (about 16
  // bytes a triangle, beside the blob, which it reads again for near
  // triangles and must outlive it). OctTreeCompressed blobs alone:
  // UsageError naming another layout.
  explicit WindingNumbers(const BlobView& view);

  struct Answer {
    double w = 0;      // the winding number, in double
    double bound = 0;  // |w - exact| <= bound (besides double's rounding of the sum)
  };
  // The winding number at each point (in the blob's frame), expanded to
  // `tolerance` (above). A NaN or infinite point gets NaN. UsageError when
  // out is shorter than points, or for a tolerance not in (0, 1).
  void evaluate(std::span<const Vec3> points, std::span<Answer> out, double tolerance = 1e-2) const;
  // The exact sum at one point, every triangle by its solid angle (the
  // reference the bound is against; slow: the whole mesh).
  double exact(const Vec3& point) const;
  // Whether |w| > 1/2 at each point: evaluated loosely first (a bound of
  // a few tenths decides most points, which lie near 0 or 1), again more
  // tightly where that leaves it in doubt, and on the exact sum where the
  // tight bound still does. UsageError when out is shorter than points.
  void inside(std::span<const Vec3> points, std::span<uint8_t> out) const;
  // The tolerances inside() tries in turn before the exact sum (a caller
  // summing several blobs' numbers decides as it does).
  static constexpr double kInsideTolerances[2] = {0.3, 1e-2};

  size_t nbytes() const { return clusters_.capacity() * sizeof(Cluster); }

 private:
  // A node's child as the expansion sees it: its triangles' total area,
  // area-weighted centroid c, radius r about c (every corner within it),
  // vector area N (the sum of area times unit normal) and first moment
  // M[i][j] = sum of area * n_i * (centroid_j - c_j).
  struct Cluster {
    double c[3], r, area;
    double n[3];
    double m[9];
    uint32_t leaf_block = 0;     // a leaf: its block's offset in the tree section; else 0
    uint32_t leaf_count = 0;     // a leaf's triangles; 0 for a node
    uint32_t first_child = 0;    // a node: its children's clusters, consecutive
    uint32_t child_count = 0;
  };
  void fill(uint32_t index, uint32_t properties);
  double leaf_sum(const Cluster& leaf, const double p[3]) const;
  Answer walk(const double p[3], double ratio) const;

  std::span<const uint8_t> blob_;
  std::vector<Cluster> clusters_;  // [0]: the whole mesh
};

}  // namespace meshcast
