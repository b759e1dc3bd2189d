#include "bench/pairing.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "builder/pairing.h"
#include "check/ray_files.h"
#include "check/generate.h"
#include "meshcast/read.h"
#include "meshcast/errors.h"

namespace meshcast::bench {

namespace {

Mesh shuffled(Mesh m) {
  std::mt19937 rng(2026);
  std::shuffle(m.triangles.begin(), m.triangles.end(), rng);
  return m;
}

// Each pair of the pass made consecutive (as a quad mesh stores them), then
// every vertex turned 45 degrees about the vertical axis.
Mesh rotated_with_pairs_baked(const Mesh& in) {
  Pairing p = pair_triangles(in, PairingOptions{false, 2.0});
  Mesh m;
  m.vertices = in.vertices;
  for (uint32_t t = 0; t < in.triangles.size(); ++t) {
    const uint32_t q = p.partner[t];
    if (q != MC_NO_HIT && q < t) continue;
    m.triangles.push_back(in.triangles[t]);
    if (q != MC_NO_HIT) m.triangles.push_back(in.triangles[q]);
  }
  const double c = std::sqrt(0.5);
  for (Vec3& v : m.vertices) {
    const double x = v.x, z = v.z;
    v.x = float(c * x - c * z), v.z = float(c * x + c * z);
  }
  return m;
}

}  // namespace

std::vector<PairingRow> bench_pairing(const std::string& data_dir, size_t ray_count, uint32_t repeat,
                                      const std::vector<std::string>& only) {
  auto chosen = [&](const std::string& name) {
    return only.empty() || std::any_of(only.begin(), only.end(), [&](const std::string& o) { return name.rfind(o, 0) == 0; });
  };
  std::vector<std::pair<std::string, Mesh>> cases;
  for (const char* name : {"bunny00", "armadillo", "refined_elephant", "ChineseDragon-10kv"}) {
    const std::string path = data_dir + "/" + name + ".off";
    if (chosen(name) && std::filesystem::exists(path)) cases.emplace_back(name, read_mesh(path));
  }
  if (chosen("terrain_2M")) cases.emplace_back("terrain_2M", make_terrain(1024, 1024, 5));
  if (cases.empty()) throw UsageError("bench pairing: no case is named by --only (or its mesh file is not in " + data_dir + ")");
  if (cases.front().first == "bunny00") {
    cases.emplace_back("bunny00 shuffled", shuffled(cases.front().second));
    cases.emplace_back("bunny00 rotated 45, pairs baked", rotated_with_pairs_baked(cases.front().second));
  }
  std::vector<PairingRow> rows;
  for (const auto& [name, mesh] : cases) {
    Pairing p = pair_triangles(mesh);
    std::vector<Ray> rays = make_rays(mesh, RayKind::Long, ray_count, 1);
    OracleTree oracle_tree(mesh);
    std::vector<OracleHit> oracle;
    for (const Ray& r : rays) oracle.push_back(oracle_tree.closest(r));
    // Float3PairSOA4: the pair as the unit of storage and of the test, beside
    // Float3SOA4 in the same tree.
    for (const char* layout : {"QuadTreeHalfFloat/Indexed8BitPackSOA4", "AABBTree/Float3SOA4", "AABBTree/Float3PairSOA4",
                               "QuadTree/Float3SOA4", "QuadTree/Float3PairSOA4"}) {
      PairingRow row{name, layout, p.decision, mesh.triangles.size(), p.ms, p.prescan_ratio, p.paired_ratio};
      BuildOptions o = parse_layout(layout);
      o.leaf_size = 8;
      row.plain = measure(mesh, name, o, rays, oracle, repeat);
      o.pairing = true;
      row.paired = measure(mesh, name, o, rays, oracle, repeat);
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace meshcast::bench
