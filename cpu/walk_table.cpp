#include "cpu/walk_table.h"

#include <array>
#include <type_traits>

#include "layout/triangles/codecs.h"
#include "layout/tree/zerobyte.h"

namespace meshcast {
MC_ISA_BEGIN

namespace {

template <class Tree, class Codec, TriangleTest kTest>
void walk_as(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  walk<Codec, kTest>(Tree{}, blob, rays, hits, n, skipped, request);
}

// The trees these objects hold walkers for: the whole catalog for the
// library's (watertight) walkers; for the plain test's, only the AABBTree
// and QuadTree families, the trees `meshcast bench robustness` compares
// (CMakeLists.txt compiles walk_aabbtree.cpp and walk_quadtree.cpp alone
// for it, so a build pays for no more than the benchmark walks).
template <class Tree>
constexpr bool walked_here() {
  if constexpr (kWalkersTriangleTest == TriangleTest::Watertight) return true;
  using namespace layout::tree;
  return std::is_same_v<Tree, AABBTree> || std::is_same_v<Tree, AABBTreeSplitAxis> ||
         std::is_same_v<Tree, AABBTreePNS> || std::is_same_v<Tree, QuadTree> || std::is_same_v<Tree, QuadTreeHalfFloat>;
}

// Every (tree, triangle format) pair the catalog allows among those trees:
// every codec under the trees that take them all, Indexed24 under the
// zero-byte trees. A plain array, no container: no library code is
// compiled for this set (cpu/isa.h).
#define MC_COUNT_ONE(...) +1
constexpr size_t kCodecs = 0 MC_FOR_EACH_TRIANGLE_CODEC(MC_COUNT_ONE);
#define MC_COUNT_TREE(Name, ...)                    \
  +(!walked_here<layout::tree::Name>()          ? 0 \
    : layout::tree::Name::kTriangles == layout::TreeTriangles::AllCodecs ? kCodecs \
                                                                         : 1)
constexpr size_t kEntries = 0 MC_FOR_EACH_TREE_FORMAT(MC_COUNT_TREE);
#undef MC_COUNT_TREE
#undef MC_COUNT_ONE

template <TriangleTest kTest>
std::array<WalkEntry, kEntries> make_walkers() {
  std::array<WalkEntry, kEntries> entries{};
  size_t n = 0;
  auto add = [&](auto tree) {
    using Tree = decltype(tree);
    if constexpr (!walked_here<Tree>()) {
      return;
    } else if constexpr (Tree::kTriangles == layout::TreeTriangles::AllCodecs) {
#define MC_CODEC_ENTRY(Codec, name) entries[n++] = {Tree::kId, layout::Codec::kFormat, &walk_as<Tree, layout::Codec, kTest>};
      MC_FOR_EACH_TRIANGLE_CODEC(MC_CODEC_ENTRY)
#undef MC_CODEC_ENTRY
    } else {
      entries[n++] = {Tree::kId, layout::Indexed24::kFormat, &walk_as<Tree, layout::Indexed24, kTest>};
    }
  };
#define MC_TREE_ENTRIES(Name, ...) add(layout::tree::Name{});
  MC_FOR_EACH_TREE_FORMAT(MC_TREE_ENTRIES)
#undef MC_TREE_ENTRIES
  return entries;
}

}  // namespace

// Made on first use, not at static initialisation: a BlobView made by
// another translation unit's static initialiser finds it ready.
template <TriangleTest kTest>
std::span<const WalkEntry> walk_table() {
  static const std::array<WalkEntry, kEntries> table = make_walkers<kTest>();
  return table;
}

// The test these sources are compiled with alone (CMakeLists.txt).
template std::span<const WalkEntry> walk_table<kWalkersTriangleTest>();

MC_ISA_END
}  // namespace meshcast
