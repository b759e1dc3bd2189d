// A blob laid out over a binary tree another builder made: the same
// quantization, leaf encoding, collapse to wide nodes and header as
// build_blob, only the binary tree over the stored triangles' boxes comes
// from `source` instead of the options' splitter. What it is for: walking a
// peer's hierarchy (bench/embree_tree.cpp: Embree's builder) with
// meshcast's walkers, so that a difference in time splits into the tree's
// share and the walk's.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "builder/binary_tree.h"
#include "meshcast/build.h"

namespace meshcast {

// The binary tree over `boxes` (the stored triangles', by index): leaves of
// at most `leaf_capacity` triangles (the options' leaf size is what the
// splitter would aim at), no deeper than `depth_limit`, BuildTree::depth
// and sah_cost filled in. Every triangle in exactly one leaf.
using TreeSource = std::function<BuildTree(const std::vector<Box3>& boxes, uint32_t leaf_size, uint32_t depth_limit,
                                           uint32_t leaf_capacity)>;

// build_blob with the binary tree from `source` (InputError as build_blob's,
// and for a tree that misses a triangle or holds one twice, or a layout
// whose writer keeps its own order: BruteForce, AABBList, pairing).
std::vector<uint8_t> build_blob_over(const Mesh& mesh, const BuildOptions& options, const std::string& name,
                                     const TreeSource& source, BuildReport* report = nullptr);

}  // namespace meshcast
