#include "check/generate.h"

#include <cmath>
#include <string>

namespace meshcast {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw InputError(what);
}

// Appends the two triangles of the grid cell with corners a (x,y), b (x+1,y),
// c (x,y+1), d (x+1,y+1), both counter-clockwise seen from +z.
void quad(Mesh& m, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  m.triangles.push_back({a, b, d});
  m.triangles.push_back({a, d, c});
}

// Grid triangles for (nx+1)*(ny+1) vertices laid out row by row.
void grid_triangles(Mesh& m, int nx, int ny) {
  m.triangles.reserve(size_t(2) * nx * ny);
  const uint32_t row = uint32_t(nx) + 1;
  for (uint32_t y = 0; y < uint32_t(ny); ++y)
    for (uint32_t x = 0; x < uint32_t(nx); ++x)
      quad(m, y * row + x, y * row + x + 1, (y + 1) * row + x, (y + 1) * row + x + 1);
}

// splitmix64-style hash: a portable, deterministic source of parameters.
uint64_t mix(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
double unit(uint64_t& state) { return double((state = mix(state)) >> 11) * 0x1.0p-53; }

}  // namespace

Mesh make_sphere(int rings, int segments, float radius, Vec3 centre) {
  require(rings >= 2 && segments >= 3 && radius > 0, "make_sphere: needs rings >= 2, segments >= 3, radius > 0");
  const double pi = 3.14159265358979323846;
  Mesh m;
  m.vertices.push_back({centre.x, centre.y, centre.z + radius});  // north pole: vertex 0
  for (int r = 1; r < rings; ++r) {                               // inner rings, no seam copy
    double theta = pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      double phi = 2 * pi * s / segments;
      m.vertices.push_back({float(centre.x + radius * std::sin(theta) * std::cos(phi)),
                            float(centre.y + radius * std::sin(theta) * std::sin(phi)),
                            float(centre.z + radius * std::cos(theta))});
    }
  }
  const uint32_t south = uint32_t(m.vertices.size());
  m.vertices.push_back({centre.x, centre.y, centre.z - radius});
  auto ring = [&](int r, int s) { return uint32_t(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) m.triangles.push_back({0, ring(1, s), ring(1, s + 1)});
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      uint32_t a = ring(r, s), b = ring(r, s + 1), c = ring(r + 1, s), d = ring(r + 1, s + 1);
      m.triangles.push_back({a, c, d});
      m.triangles.push_back({a, d, b});
    }
  for (int s = 0; s < segments; ++s) m.triangles.push_back({south, ring(rings - 1, s + 1), ring(rings - 1, s)});
  return m;
}

Mesh make_grid_plane(int nx, int ny) {
  require(nx >= 1 && ny >= 1, "make_grid_plane: needs nx, ny >= 1");
  Mesh m;
  m.vertices.reserve(size_t(nx + 1) * (ny + 1));
  for (int y = 0; y <= ny; ++y)
    for (int x = 0; x <= nx; ++x) m.vertices.push_back({float(x), float(y), 0.0f});
  grid_triangles(m, nx, ny);
  return m;
}

Mesh make_terrain(int nx, int ny, uint32_t seed) {
  require(nx >= 1 && ny >= 1, "make_terrain: needs nx, ny >= 1");
  // Height = sum over octaves of amplitude * sin(fx x + px) * sin(fy y + py).
  // Separable, so each octave needs only (nx+1) + (ny+1) sines: fast at 1024^2.
  constexpr int octaves = 4;
  uint64_t state = seed;
  std::vector<float> sx[octaves], sy[octaves];
  double amplitude[octaves];
  for (int o = 0; o < octaves; ++o) {
    double wavelength = 64.0 / (1 << o) * (0.75 + 0.5 * unit(state));  // 48..80, 24..40, ...
    double px = 6.283185307179586 * unit(state), py = 6.283185307179586 * unit(state);
    amplitude[o] = 8.0 / (1 << o);
    for (int x = 0; x <= nx; ++x) sx[o].push_back(float(std::sin(6.283185307179586 * x / wavelength + px)));
    for (int y = 0; y <= ny; ++y) sy[o].push_back(float(std::sin(6.283185307179586 * y / wavelength + py)));
  }
  Mesh m;
  m.vertices.resize(size_t(nx + 1) * (ny + 1));
  size_t i = 0;
  for (int y = 0; y <= ny; ++y)
    for (int x = 0; x <= nx; ++x) {
      float h = 0;
      for (int o = 0; o < octaves; ++o) h += float(amplitude[o]) * sx[o][x] * sy[o][y];
      m.vertices[i++] = {float(x), float(y), h};
    }
  grid_triangles(m, nx, ny);
  return m;
}

}  // namespace meshcast
