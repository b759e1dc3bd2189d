// The one list of layouts: every tree format carries every triangle format.
// Walker instantiations and the dispatch table in trace.cpp are generated
// from these lists, so adding a codec is one line here plus its Loader.
#pragma once

#define MC_FOR_EACH_TRIANGLE_CODEC(X) \
  X(Float3)                           \
  X(Float3SOA4)                       \
  X(Indexed8BitPackSOA4)

#define MC_FOR_EACH_TREE(X)                         \
  X(AABBTree, MC_TREE_AABBTREE)                     \
  X(QuadTree, MC_TREE_QUADTREE)                     \
  X(QuadTreeHalfFloat, MC_TREE_QUADTREEHALFFLOAT)
