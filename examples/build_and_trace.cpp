// From the caller's arrays in memory to hits, on this thread: a 2 x 2 quad
// floor (8 triangles) built into a blob and cast at from above.
#include <meshcast/meshcast.h>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  // 3 x 3 vertices on the plane z = 0, x and y in 0..2; two triangles a cell.
  std::vector<float> xyz;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) xyz.insert(xyz.end(), {float(x), float(y), 0.0f});
  std::vector<uint16_t> indices;  // 16-bit indices, as an engine's index buffer may hold them
  for (uint16_t y = 0; y < 2; ++y)
    for (uint16_t x = 0; x < 2; ++x) {
      const uint16_t v = uint16_t(3 * y + x);
      indices.insert(indices.end(), {v, uint16_t(v + 1), uint16_t(v + 4), v, uint16_t(v + 4), uint16_t(v + 3)});
    }

  const meshcast::MeshView mesh(xyz, 3, indices);  // packed x y z; 16-bit indices deduced from the span
  try {
    const std::vector<uint8_t> blob = meshcast::build_blob(mesh, meshcast::BuildOptions{}, "floor");
    const meshcast::BlobView view(blob, "floor");

    // Straight down onto the centre of each cell's lower-right triangle
    // (x - floor(x) > y - floor(y)), which is triangle 2 * cell.
    std::vector<meshcast::Ray> rays;
    for (int cell = 0; cell < 4; ++cell) {
      const float x = float(cell % 2) + 0.7f, y = float(cell / 2) + 0.2f;
      rays.push_back({{x, y, 5}, {0, 0, -1}, INFINITY});
    }
    std::vector<meshcast::Hit> hits(rays.size());
    view.trace(rays, hits);
    int wrong = 0;
    for (size_t i = 0; i < hits.size(); ++i) {
      std::printf("ray %zu: triangle %u at t = %g\n", i, hits[i].triangle, hits[i].t);
      wrong += hits[i].triangle != 2 * i || std::fabs(hits[i].t - 5.0f) > 1e-4f;
    }
    std::printf("%s: %zu bytes for %u triangles (%s)\n", wrong ? "WRONG" : "ok", blob.size(), view.triangle_count(),
                meshcast::layout_name(view.layout()).c_str());
    return wrong ? 1 : 0;
  } catch (const meshcast::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
