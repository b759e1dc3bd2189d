#include "cpu/mesh.h"

#include <algorithm>
#include <cmath>

namespace meshcast {

void Box3::grow(const Vec3& p) {
  min = {std::min(min.x, p.x), std::min(min.y, p.y), std::min(min.z, p.z)};
  max = {std::max(max.x, p.x), std::max(max.y, p.y), std::max(max.z, p.z)};
}

void Box3::grow(const Box3& b) {  // min of minima, max of maxima: an empty b changes nothing
  min = {std::min(min.x, b.min.x), std::min(min.y, b.min.y), std::min(min.z, b.min.z)};
  max = {std::max(max.x, b.max.x), std::max(max.y, b.max.y), std::max(max.z, b.max.z)};
}

Vec3 Box3::centre() const {
  return {0.5f * (min.x + max.x), 0.5f * (min.y + max.y), 0.5f * (min.z + max.z)};
}

Vec3 Box3::extent() const { return {max.x - min.x, max.y - min.y, max.z - min.z}; }

double Box3::half_area() const {
  // In double: float products of extents near 1e-30 underflow to 0 (every
  // split then costs the same and the tree degenerates into a chain), and
  // near 1e20 they overflow.
  if (empty()) return 0.0;
  const double x = double(max.x) - min.x, y = double(max.y) - min.y, z = double(max.z) - min.z;
  return x * y + y * z + z * x;
}

double Box3::diagonal() const {
  Vec3 e = extent();
  return std::sqrt(double(e.x) * e.x + double(e.y) * e.y + double(e.z) * e.z);
}

Box3 Mesh::bounds() const {
  Box3 b;
  for (const Triangle& t : triangles)
    for (uint32_t v : t) b.grow(vertices[v]);
  return b;
}

void check_mesh(const Mesh& mesh, const std::string& name) {
  if (mesh.triangles.empty()) throw InputError(name + ": the mesh has no triangles");
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw InputError(name + ": vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
    if (std::fabs(v.x) > kMaxCoordinate || std::fabs(v.y) > kMaxCoordinate || std::fabs(v.z) > kMaxCoordinate)
      throw InputError(name + ": vertex " + std::to_string(i) + " lies beyond +-2^100, the coordinate range meshcast "
                       "supports (box extents and areas must stay finite in float)");
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t])
      if (v >= mesh.vertices.size())
        throw InputError(name + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(v) +
                         " but the mesh has only " + std::to_string(mesh.vertices.size()) + " vertices");
  if (mesh.triangles.size() > 0xFFFFFFFEu)
    throw InputError(name + ": more than 2^32-2 triangles");
}

}  // namespace meshcast
