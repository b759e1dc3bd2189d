#include "meshcast/blob.h"

#include <algorithm>
#include <cfloat>
#include <vector>

#include "cpu/walk.h"
#include "layout/blob_format.h"
#include "layout/codecs.h"
#include "layout/zerobyte.h"

namespace meshcast {

namespace {

struct Entry {
  uint32_t tree, triangles;
  WalkFn walk;
};

template <class Tree, class Codec>
void walk_as(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, uint32_t outputs) {
  walk<Codec>(Tree{}, blob, rays, hits, n, skipped, outputs);
}

// Every (tree, triangle format) pair the catalog allows: every codec under
// the trees that take them all, Indexed24 under the zero-byte trees.
std::vector<Entry> make_walkers() {
  std::vector<Entry> entries;
  auto add = [&](auto tree) {
    using Tree = decltype(tree);
    if constexpr (Tree::kTriangles == layout::TreeTriangles::AllCodecs) {
#define MC_CODEC_ENTRY(Codec, name) entries.push_back({Tree::kId, layout::Codec::kFormat, &walk_as<Tree, layout::Codec>});
      MC_FOR_EACH_TRIANGLE_CODEC(MC_CODEC_ENTRY)
#undef MC_CODEC_ENTRY
    } else {
      entries.push_back({Tree::kId, layout::Indexed24::kFormat, &walk_as<Tree, layout::Indexed24>});
    }
  };
#define MC_TREE_ENTRIES(Name, ...) add(layout::tree::Name{});
  MC_FOR_EACH_TREE_FORMAT(MC_TREE_ENTRIES)
#undef MC_TREE_ENTRIES
  return entries;
}

// Made on first use, not at static initialisation: a BlobView made by
// another translation unit's static initialiser finds it ready.
const std::vector<Entry>& walkers() {
  static const std::vector<Entry> table = make_walkers();
  return table;
}

}  // namespace

bool watertight_lane_double(const float ax, const float ay, const float bx, const float by, const float cx,
                            const float cy, const float az, const float bz, const float cz, const float sz,
                            float closest, LaneHit* out) {
  double U = double(cx) * by - double(cy) * bx;
  double V = double(ax) * cy - double(ay) * cx;
  double W = double(bx) * ay - double(by) * ax;
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return false;
  double det = U + V + W;
  if (det == 0) return false;
  double T = (U * az + V * bz + W * cz) * double(sz);
  if (det < 0) T = -T, U = -U, V = -V, W = -W, det = -det;
  if (T < 0) return false;
  // Compared in double: a t past the largest float is no hit.
  const double t = T / det;
  if (!(t <= double(std::min(closest, FLT_MAX)))) return false;
  out->t = float(t), out->u = float(V / det), out->v = float(W / det);
  return true;
}

BlobView::BlobView(std::span<const uint8_t> bytes, const std::string& name) : bytes_(bytes) {
  std::string why = layout::validate(bytes);
  if (!why.empty()) throw InputError(name + ": " + why);
  const layout::BlobHeader& h = layout::header_of(bytes.data());
  for (const Entry& e : walkers())
    if (e.tree == h.tree_format && e.triangles == h.triangle_format) walk_ = e.walk;
  if (!walk_) throw InputError(name + ": no walker for this layout");
}

uint64_t BlobView::trace(std::span<const Ray> rays, std::span<Hit> hits, HitOutputs outputs) const {
  if (hits.size() < rays.size())
    throw UsageError("BlobView::trace: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(hits.size()) + " hits; the hits span must hold one hit a ray");
  uint64_t skipped = 0;
  walk_(bytes_.data(), rays.data(), hits.data(), rays.size(), &skipped, uint32_t(outputs));
  return skipped;
}

Layout BlobView::layout() const {
  const layout::BlobHeader& h = layout::header_of(bytes_.data());
  return {TreeFormat(h.tree_format), TriangleFormat(h.triangle_format)};
}

uint32_t BlobView::triangle_count() const { return layout::header_of(bytes_.data()).triangle_count; }

}  // namespace meshcast
