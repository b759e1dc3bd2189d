// The input mesh as the caller gave it: vertex positions and triangles in input
// order. Everything downstream (builder, layouts, oracle) starts from this.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace meshcast {

struct Vec3 {
  float x = 0, y = 0, z = 0;
  float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

struct Box3 {
  Vec3 min{+INFINITY, +INFINITY, +INFINITY};
  Vec3 max{-INFINITY, -INFINITY, -INFINITY};
  void grow(const Vec3& p);
  void grow(const Box3& b);
  bool empty() const { return min.x > max.x; }
  Vec3 centre() const;
  Vec3 extent() const;
  double half_area() const;  // SAH cost unit: xy + yz + zx, in double (1e-30 or 1e30 wide boxes)
  double diagonal() const;
};

using Triangle = std::array<uint32_t, 3>;

struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;

  size_t triangle_count() const { return triangles.size(); }
  Vec3 corner(size_t tri, int k) const { return vertices[triangles[tri][k]]; }
  Box3 bounds() const;
};

// Thrown for bad input; the message names the input and the problem.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Coordinates beyond this (about 1.27e30) are refused, in meshes and in ray
// origins: extents, areas and half-float scales computed from them must stay
// finite in float, and the triangle test's double redo must stay in range.
constexpr float kMaxCoordinate = 0x1p100f;

// Checks what every layout relies on: at least one triangle, every index in
// range, every coordinate finite and within kMaxCoordinate. `name` is used in the message (a file path or
// a generator name). Throws InputError.
void check_mesh(const Mesh& mesh, const std::string& name);

}  // namespace meshcast
