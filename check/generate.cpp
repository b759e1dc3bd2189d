#include "check/generate.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

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

namespace {

void append(Mesh& to, const Mesh& from) {
  const uint32_t base = uint32_t(to.vertices.size());
  to.vertices.insert(to.vertices.end(), from.vertices.begin(), from.vertices.end());
  for (const Triangle& t : from.triangles) to.triangles.push_back({base + t[0], base + t[1], base + t[2]});
}

// A closed box [lo, hi] whose faces are grids of cells of about `cell`,
// outward-facing; the edges are shared, so the box is watertight.
Mesh make_box(Vec3 lo, Vec3 hi, float cell) {
  Mesh m;
  const float size[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = std::max(1, int(std::lround(size[a] / cell)));
  // Vertices on the box surface: every lattice point with one coordinate at
  // its minimum or maximum, numbered through a map of lattice coordinates.
  std::vector<int32_t> index(size_t(n[0] + 1) * (n[1] + 1) * (n[2] + 1), -1);
  auto vertex = [&](int i, int j, int k) {
    int32_t& at = index[(size_t(k) * (n[1] + 1) + j) * (n[0] + 1) + i];
    if (at < 0) {
      at = int32_t(m.vertices.size());
      m.vertices.push_back({lo.x + size[0] * float(i) / float(n[0]), lo.y + size[1] * float(j) / float(n[1]),
                            lo.z + size[2] * float(k) / float(n[2])});
    }
    return uint32_t(at);
  };
  // Face of axis a at side s (0 min, 1 max), spanned by axes u, v.
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const int u = (a + 1) % 3, v = (a + 2) % 3;
      for (int y = 0; y < n[v]; ++y)
        for (int x = 0; x < n[u]; ++x) {
          auto at = [&](int du, int dv) {
            int c[3];
            c[a] = side * n[a], c[u] = x + du, c[v] = y + dv;
            return vertex(c[0], c[1], c[2]);
          };
          // (u, v, a) is right-handed: counter-clockwise in (u, v) faces +a.
          if (side) quad(m, at(0, 0), at(1, 0), at(0, 1), at(1, 1));
          else quad(m, at(0, 0), at(0, 1), at(1, 0), at(1, 1));
        }
    }
  return m;
}

}  // namespace

Mesh make_city(size_t triangles, uint32_t seed) {
  require(triangles >= 10000, "make_city: needs at least 10,000 triangles");
  uint64_t state = seed;
  constexpr float kSide = 2000.0f, kBlock = 50.0f, kStreet = 12.0f;
  // The ground: a gentle terrain a tenth of the budget, stretched over the city.
  const int cells = std::max(8, int(std::sqrt(double(triangles) / 20.0)));
  Mesh city = make_terrain(cells, cells, seed);
  const float stretch = kSide / float(cells);
  for (Vec3& v : city.vertices) v = {v.x * stretch, v.y * stretch, v.z * 0.25f - 3.0f};
  // Buildings to half the budget, block by block in a random order of blocks.
  const int blocks = int(kSide / kBlock);
  std::vector<float> roofs;  // x, y, z of roof tops, for objects on them
  while (city.triangles.size() < triangles / 2) {
    const int bx = int(unit(state) * blocks), by = int(unit(state) * blocks);
    const float x0 = float(bx) * kBlock + kStreet / 2, y0 = float(by) * kBlock + kStreet / 2;
    const float room = kBlock - kStreet;
    const float w = 3.0f + float(unit(state)) * (room - 3.0f), d = 3.0f + float(unit(state)) * (room - 3.0f);
    const float h = 3.0f + float(std::pow(unit(state), 3.0)) * 150.0f;  // mostly low, some towers
    const float x = x0 + float(unit(state)) * (room - w), y = y0 + float(unit(state)) * (room - d);
    append(city, make_box({x, y, 0.0f}, {x + w, y + d, h}, 2.5f));
    roofs.insert(roofs.end(), {x + w / 2, y + d / 2, h});
  }
  // Detailed objects to the budget: in the streets or on a roof.
  while (city.triangles.size() < triangles) {
    const int rings = 8 + int(unit(state) * 88);
    const float radius = 0.15f + float(unit(state)) * 3.0f;
    Vec3 at;
    if (!roofs.empty() && unit(state) < 0.3) {
      const size_t r = size_t(unit(state) * double(roofs.size() / 3)) * 3;
      at = {roofs[r], roofs[r + 1], roofs[r + 2] + radius};
    } else {
      const float street = float(int(unit(state) * blocks)) * kBlock + float(unit(state)) * kStreet / 2;
      const float along = float(unit(state)) * kSide;
      at = unit(state) < 0.5 ? Vec3{street, along, radius} : Vec3{along, street, radius};
    }
    append(city, make_sphere(rings, 2 * rings, radius, at));
  }
  return city;
}

std::array<double, 9> random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  double q[4] = {n(rng), n(rng), n(rng), n(rng)};
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& x : q) x /= len;
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

}  // namespace meshcast
