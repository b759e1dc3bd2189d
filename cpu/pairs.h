// The one list of layouts: every tree format carries every triangle format
// of layout/codecs.h. Walker instantiations and the dispatch table in
// trace.cpp are generated from these lists.
#pragma once
#include "layout/codecs.h"

#define MC_FOR_EACH_TREE(X)                           \
  X(AABBTree, MC_TREE_AABBTREE)                       \
  X(AABBTreeSplitAxis, MC_TREE_AABBTREESPLITAXIS)     \
  X(AABBTreePNS, MC_TREE_AABBTREEPNS)                 \
  X(AABBTreeCompressed, MC_TREE_AABBTREECOMPRESSED)   \
  X(SKDTree, MC_TREE_SKDTREE)                         \
  X(StacklessLBVH, MC_TREE_STACKLESSLBVH)             \
  X(QuadTree, MC_TREE_QUADTREE)                       \
  X(QuadTreeHalfFloat, MC_TREE_QUADTREEHALFFLOAT)     \
  X(BruteForce, MC_TREE_BRUTEFORCE)                   \
  X(AABBList, MC_TREE_AABBLIST)
