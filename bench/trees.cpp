#include "bench/trees.h"

#include <map>

#include "cpu/rays.h"

namespace meshcast::bench {

namespace {

struct Setup {
  std::vector<Ray> rays;
  std::vector<OracleHit> oracle;
};

Setup setup(const Mesh& mesh, size_t count) {
  Setup s{make_rays(mesh, RayKind::Long, count, 1), {}};
  OracleTree tree(mesh);
  for (const Ray& r : s.rays) s.oracle.push_back(tree.closest(r));
  return s;
}

}  // namespace

std::vector<TreeRow> bench_splitters(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat) {
  // Seed 000 §4.1 (time for 1024 rays as printed there; the units of that
  // table read as ms for the 1024 rays).
  const std::map<std::string, double> seed_float3 = {
      {"Binning", 0.62}, {"Mean", 0.68}, {"LongestAxis", 0.73}, {"Morton", 0.74}, {"FixedLeafSize", 0.81}};
  const std::map<std::string, double> seed_soa4 = {
      {"Binning", 0.60}, {"Mean", 0.65}, {"LongestAxis", 0.67}, {"FixedLeafSize", 0.71}, {"Morton", 0.71}};
  Setup s = setup(mesh, rays);
  std::vector<TreeRow> rows;
  for (const char* layout : {"AABBTree/Float3", "AABBTree/Float3SOA4"})
    for (Splitter sp : all_splitters()) {
      BuildOptions o = parse_layout(layout);
      o.splitter = sp;
      const auto& seed = std::string(layout) == "AABBTree/Float3" ? seed_float3 : seed_soa4;
      rows.push_back({splitter_name(sp), layout, seed.at(splitter_name(sp)), measure(mesh, name, o, s.rays, s.oracle, repeat)});
    }
  return rows;
}

std::vector<TreeRow> bench_leafsize(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat) {
  const std::map<uint32_t, double> seed = {{4, 0.62}, {8, 0.62}, {16, 0.70}};  // seed 000 §4.2
  Setup s = setup(mesh, rays);
  std::vector<TreeRow> rows;
  for (uint32_t leaf : {4u, 8u, 16u}) {
    BuildOptions o = parse_layout("AABBTree/Float3");
    o.leaf_size = leaf;
    rows.push_back({std::to_string(leaf), "AABBTree/Float3", seed.at(leaf), measure(mesh, name, o, s.rays, s.oracle, repeat)});
  }
  return rows;
}

std::vector<TreeRow> bench_trees(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat) {
  // Seed 000 §6: time for 1024 rays and tree size without triangles (bytes),
  // Stanford Bunny, Float3, Binning, 8 triangles a leaf.
  const std::map<std::string, std::pair<double, double>> seed = {
      {"QuadTree", {0.53, 646340}}, {"QuadTreeHalfFloat", {0.54, 378212}}, {"AABBTree", {0.62, 651476}},
      {"AABBTreeSplitAxis", {0.67, 651476}}, {"AABBTreePNS", {0.68, 651476}}};
  Setup s = setup(mesh, rays);
  std::vector<TreeRow> rows;
  for (const char* tree : {"QuadTree", "QuadTreeHalfFloat", "AABBTree", "AABBTreeSplitAxis", "AABBTreePNS"}) {
    BuildOptions o = parse_layout(std::string(tree) + "/Float3");
    TreeRow row{tree, std::string(tree) + "/Float3", seed.at(tree).first, measure(mesh, name, o, s.rays, s.oracle, repeat)};
    row.seed_tree_bytes = seed.at(tree).second;
    rows.push_back(row);
  }
  return rows;
}

}  // namespace meshcast::bench
