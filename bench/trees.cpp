#include "bench/trees.h"

#include <algorithm>
#include <cstdio>
#include <map>

#include "check/ray_files.h"

namespace meshcast::bench {

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
      {"AABBTreeSplitAxis", {0.67, 651476}}, {"AABBTreePNS", {0.68, 651476}}, {"AABBTreeCompressed", {0.94, 139596}},
      {"SKDTree", {2.58, 186132}}, {"StacklessLBVH", {0, 0}}};
  Setup s = setup(mesh, rays);
  std::vector<TreeRow> rows;
  for (const char* tree : {"QuadTree", "QuadTreeHalfFloat", "AABBTree", "AABBTreeSplitAxis", "AABBTreePNS",
                           "AABBTreeCompressed", "SKDTree", "StacklessLBVH", "StacklessLBVH left first"}) {
    std::string format = std::string(tree).substr(0, std::string(tree).find(' '));
    BuildOptions o = parse_layout(format + "/Float3");
    o.lbvh_near_first = format == tree;
    TreeRow row{tree, format + "/Float3", seed.at(format).first, measure(mesh, name, o, s.rays, s.oracle, repeat)};
    row.seed_tree_bytes = seed.at(format).second;
    rows.push_back(row);
  }
  return rows;
}

std::vector<TreeRow> bench_order(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat) {
  // Seed 000 §4.3 (its AABBTree/Float3, whose node format here pins the order).
  const std::map<NodeOrder, double> seed = {{NodeOrder::DepthFirst, 0.527},
                                            {NodeOrder::DepthFirstTrianglesLast, 0.539},
                                            {NodeOrder::BreadthFirstTrianglesLast, 0.546},
                                            {NodeOrder::BreadthFirst, 0.547}};
  Setup s = setup(mesh, rays);
  std::vector<TreeRow> rows;
  for (const char* layout : {"QuadTree/Float3", "QuadTreeHalfFloat/Float3"})
    for (NodeOrder order : all_node_orders()) {
      BuildOptions o = parse_layout(layout);
      o.node_order = order;
      rows.push_back({node_order_name(order), layout, seed.at(order), measure(mesh, name, o, s.rays, s.oracle, repeat)});
    }
  return rows;
}

std::vector<TreeRow> bench_combos(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat,
                                  const std::string& only) {
  // Seed 000 §6, second table (Stanford Bunny): time for 1024 rays, bytes a triangle.
  const std::map<std::string, std::pair<double, double>> seed = {
      {"QuadTree/Indexed8BitPackSOA4", {0.47, 18.3}}, {"QuadTree/BitPackSOA4", {0.47, 38.2}},
      {"QuadTree/Indexed16BitPackSOA4", {0.48, 20.5}}, {"QuadTreeHalfFloat/Indexed8BitPackSOA4", {0.48, 14.4}},
      {"QuadTree/Float3SOA4", {0.48, 52.8}}, {"QuadTreeHalfFloat/BitPackSOA4", {0.49, 34.3}},
      {"QuadTreeHalfFloat/Indexed16BitPackSOA4", {0.49, 16.6}}, {"QuadTree/Float3SOA8", {0.50, 57.3}},
      {"QuadTreeHalfFloat/Indexed16SOA4", {0.50, 18.6}}, {"QuadTree/UncompressedStrip", {0.50, 26.4}},
      {"QuadTree/Indexed16SOA4", {0.51, 22.5}}, {"QuadTreeHalfFloat/Float3SOA8", {0.52, 53.4}},
      {"QuadTreeHalfFloat/Float3SOA4", {0.53, 48.9}}, {"QuadTree/Float3", {0.53, 45.3}},
      {"QuadTreeHalfFloat/UncompressedStrip", {0.53, 22.6}}, {"QuadTree/Indexed16", {0.53, 21.4}},
      {"QuadTree/BitPack", {0.53, 33.2}}, {"QuadTreeHalfFloat/Float3", {0.54, 41.4}},
      {"QuadTree/CompressedStrip", {0.55, 20.6}}, {"QuadTreeHalfFloat/Indexed16", {0.55, 17.5}},
      {"QuadTreeHalfFloat/BitPack", {0.56, 29.3}}, {"QuadTreeHalfFloat/CompressedStrip", {0.56, 16.7}},
      {"AABBTreeCompressed/Indexed16SOA4", {0.81, 15.3}}, {"AABBTreeCompressed/Indexed8BitPackSOA4", {0.85, 10.8}},
      {"AABBTreeCompressed/Indexed16BitPackSOA4", {0.86, 13.3}}, {"AABBTreeCompressed/Indexed16", {0.89, 14.0}},
      {"AABBTreeCompressed/Float3SOA8", {0.89, 50.3}}, {"AABBTreeCompressed/BitPackSOA4", {0.89, 31.2}},
      {"AABBTreeCompressed/Float3SOA4", {0.89, 45.8}}, {"AABBTreeCompressed/CompressedStrip", {0.92, 13.4}},
      {"AABBTreeCompressed/UncompressedStrip", {0.93, 19.1}}, {"AABBTreeCompressed/Float3", {0.94, 38.0}},
      {"AABBTreeCompressed/BitPack", {0.95, 26.0}}};
  auto kept = [&](const std::string& layout) {
    if (only.empty()) return true;
    for (size_t at = 0; at <= only.size();) {
      size_t comma = std::min(only.find(',', at), only.size());
      if (comma > at && layout.find(only.substr(at, comma - at)) != std::string::npos) return true;
      at = comma + 1;
    }
    return false;
  };
  // Each layout with its default options, then the zero-byte variants.
  std::vector<std::pair<std::string, BuildOptions>> cases;
  for (const std::string& layout : layout_names()) cases.push_back({layout, parse_layout(layout)});
  for (bool cache : {true, false})
    for (bool shuffle : {true, false}) {
      if (cache && shuffle) continue;  // the default, above
      BuildOptions o = parse_layout("ZeroByteTree/Indexed24");
      o.zbt_box_cache = cache, o.zbt_shuffle = shuffle;
      cases.push_back({std::string("ZeroByteTree/Indexed24 (") + (cache ? "cache" : "no cache") + ", " +
                           (shuffle ? "shuffled" : "not shuffled") + ")", o});
    }
  for (uint32_t leaf : {64u, 1024u}) {
    BuildOptions o = parse_layout("ZeroByteHybrid/Indexed24");
    o.hybrid_leaf = leaf;
    cases.push_back({"ZeroByteHybrid/Indexed24 (leaf " + std::to_string(leaf) + ")", o});
  }
  Setup s = setup(mesh, rays);
  std::vector<TreeRow> rows;
  for (const auto& [layout, o] : cases) {
    if (uint32_t(o.layout.tree) == MC_TREE_BRUTEFORCE || uint32_t(o.layout.triangles) == MC_TRI_FLOAT3SOA128 ||
        uint32_t(o.layout.triangles) == MC_TRI_BITPACKSOA128 || !kept(layout))
      continue;
    std::fprintf(stderr, "  %s\n", layout.c_str());
    auto it = seed.find(layout);
    TreeRow row{layout.substr(0, layout.find('/')), layout, it == seed.end() ? 0.0 : it->second.first, {}};
    row.seed_bytes_per_tri = it == seed.end() ? 0.0 : it->second.second;
    try {
      row.timing = measure(mesh, name, o, s.rays, s.oracle, repeat);
    } catch (const InputError& e) {  // a format limit this mesh exceeds (16-bit indices, offsets)
      row.refused = e.what();
    }
    rows.push_back(row);
  }
  return rows;
}

std::vector<OffsetRow> bench_offset(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat) {
  // The mesh scaled to the test's size, at the origin and moved by the
  // offset along every axis; the rays are the origin set moved the same way.
  struct Case { const char* label; double size, offset; };
  const Case cases[] = {{"0.15 units at 1000", 0.15, 1000.0}, {"150 units at 30000", 150.0, 30000.0}};
  std::vector<OffsetRow> rows;
  Box3 box = mesh.bounds();
  double extent = std::max({box.extent().x, box.extent().y, box.extent().z});
  for (const Case& c : cases) {
    Mesh at_origin = mesh, far_away = mesh;
    for (size_t v = 0; v < mesh.vertices.size(); ++v)
      for (int a = 0; a < 3; ++a) {
        double p = (double(mesh.vertices[v][a]) - box.centre()[a]) * c.size / extent;
        at_origin.vertices[v][a] = float(p);
        far_away.vertices[v][a] = float(p + c.offset);
      }
    Setup near_set = setup(at_origin, rays), far_set{near_set.rays, {}};
    for (Ray& r : far_set.rays)
      for (int a = 0; a < 3; ++a) r.org[a] = float(double(r.org[a]) + c.offset);
    OracleTree far_oracle(far_away);
    for (const Ray& r : far_set.rays) far_set.oracle.push_back(far_oracle.closest(r));
    for (const char* layout : {"QuadTreeHalfFloat/Float3", "QuadTreeHalfFloat/Indexed8BitPackSOA4", "QuadTree/Float3",
                               "AABBTreeCompressed/Float3"}) {
      BuildOptions o = parse_layout(layout);
      // Interleaved: each pass of one runs right after the other's, so a
      // slow spell of the machine hits both.
      OffsetRow row{layout, c.label, {}, {}};
      std::vector<Timing> a, b;
      for (uint32_t k = 0; k < 3; ++k) {
        a.push_back(measure(at_origin, name + " at the origin", o, near_set.rays, near_set.oracle, repeat));
        b.push_back(measure(far_away, name + " moved", o, far_set.rays, far_set.oracle, repeat));
      }
      auto best = [](std::vector<Timing>& v) {
        return *std::min_element(v.begin(), v.end(), [](const Timing& x, const Timing& y) { return x.min_ms < y.min_ms; });
      };
      row.origin = best(a), row.offset = best(b);
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace meshcast::bench
