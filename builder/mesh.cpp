#include "meshcast/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "builder/binary_tree.h"

namespace meshcast {

double Box3::half_area() const { return box_half_area(*this); }

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

// The vertex stride as the caller gave it: in floats from the typed
// constructors, in bytes by hand.
static std::string stride_text(const MeshView& view) {
  if (view.stride_in_floats) return "vertex stride " + std::to_string(*view.stride_in_floats) + " floats";
  return "vertex stride " + std::to_string(view.vertex_stride) + " bytes";
}

Mesh copy_mesh(const MeshView& view, const std::string& name) {
  // An enum read from memory filled in by hand may hold any value; read as
  // 32-bit indices it would build a mesh of the wrong triangles.
  if (view.index_type != IndexType::Uint16 && view.index_type != IndexType::Uint32)
    throw InputError(name + ": index_type " + std::to_string(unsigned(view.index_type)) +
                     " is neither IndexType::Uint16 (0) nor IndexType::Uint32 (1)");
  const size_t index_bytes = view.index_type == IndexType::Uint16 ? 2 : 4;
  const size_t triangle_stride = view.triangle_stride ? view.triangle_stride : 3 * index_bytes;
  if ((view.vertex_count && !view.positions) || (view.triangle_count && !view.indices))
    throw InputError(name + ": a null position or index array with a nonzero count");
  // The byte stride is the one the reads take (a typed view's too): the
  // floats only word the message.
  if (view.vertex_stride < 3 * sizeof(float))
    throw InputError(name + ": " + stride_text(view) + " is shorter than a position (" +
                     (view.stride_in_floats ? "3 floats)" : "12 bytes: three floats)"));
  if (triangle_stride < 3 * index_bytes)
    throw InputError(name + ": triangle stride " + std::to_string(triangle_stride) + " is shorter than three " +
                     std::to_string(8 * index_bytes) + "-bit indices");
  // The reads below step count - 1 strides from the start: a stride whose
  // product with its count overflows would wrap to memory it never meant.
  // A typed view's stride in floats may overflow as bytes by itself.
  const bool vertex_overflow =
      view.vertex_count != 0 && ((view.stride_in_floats && *view.stride_in_floats > SIZE_MAX / sizeof(float)) ||
                                 view.vertex_stride > SIZE_MAX / view.vertex_count);
  if (vertex_overflow)
    throw InputError(name + ": " + std::to_string(view.vertex_count) + " vertices of " + stride_text(view) +
                     " do not fit in this process's address space");
  if (view.triangle_count && triangle_stride > SIZE_MAX / view.triangle_count)
    throw InputError(name + ": " + std::to_string(view.triangle_count) + " triangles of triangle stride " +
                     std::to_string(triangle_stride) + " bytes do not fit in this process's address space");
  // Where a view states its buffers' sizes (the typed constructors do), the
  // last vertex and triangle must lie inside them: a stride or index type
  // that does not match the data reads past them otherwise.
  auto past_end = [](size_t count, size_t stride, size_t element, size_t bytes) {
    return bytes != 0 && count != 0 && (bytes < element || (count - 1) > (bytes - element) / stride);
  };
  if (past_end(view.vertex_count, view.vertex_stride, 12, view.positions_bytes))
    throw InputError(name + ": the positions hold " +
                     (view.stride_in_floats ? std::to_string(view.positions_bytes / sizeof(float)) + " floats"
                                            : std::to_string(view.positions_bytes) + " bytes") +
                     ", not " + std::to_string(view.vertex_count) + " vertices at " + stride_text(view) +
                     " (the last vertex is cut short: check the stride and where the span starts)");
  if (past_end(view.triangle_count, triangle_stride, 3 * index_bytes, view.indices_bytes))
    throw InputError(name + ": the index buffer holds " + std::to_string(view.indices_bytes / index_bytes) + " " +
                     std::to_string(8 * index_bytes) + "-bit indices, fewer than three for each of " +
                     std::to_string(view.triangle_count) +
                     " triangles (check the index type, and that the indices are whole triangles)");
  if (view.vertex_count > 0xFFFFFFFFu)
    throw InputError(name + ": " + std::to_string(view.vertex_count) + " vertices; 32-bit indices reach 2^32");
  // check_mesh's limit, before the copy is allocated from the count.
  if (view.triangle_count > 0xFFFFFFFEu)
    throw InputError(name + ": " + std::to_string(view.triangle_count) + " triangles, more than 2^32-2");
  Mesh mesh;
  mesh.vertices.resize(view.vertex_count);
  const auto* positions = static_cast<const unsigned char*>(view.positions);
  for (size_t i = 0; i < view.vertex_count; ++i) std::memcpy(&mesh.vertices[i], positions + i * view.vertex_stride, 12);
  mesh.triangles.resize(view.triangle_count);
  const auto* indices = static_cast<const unsigned char*>(view.indices);
  for (size_t t = 0; t < view.triangle_count; ++t)
    for (int k = 0; k < 3; ++k) {
      const unsigned char* at = indices + t * triangle_stride + size_t(k) * index_bytes;
      if (index_bytes == 2) {
        uint16_t v;
        std::memcpy(&v, at, 2);
        mesh.triangles[t][size_t(k)] = v;
      } else {
        std::memcpy(&mesh.triangles[t][size_t(k)], at, 4);
      }
    }
  // An index past the view's vertices, named with the stride that counted
  // them: a stride given in bytes where floats were meant (or any stride
  // too long) leaves fewer vertices than the indices use, which check_mesh
  // would report without the stride.
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t])
      if (v >= mesh.vertices.size())
        throw InputError(name + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(v) +
                         " but the view has only " + std::to_string(mesh.vertices.size()) + " vertices at " +
                         stride_text(view) +
                         (view.stride_in_floats ? " over " + std::to_string(view.positions_bytes / sizeof(float)) +
                                                      " floats (check that the stride counts floats, not bytes)"
                                                : " (vertex_count " + std::to_string(view.vertex_count) + ")"));
  check_mesh(mesh, name);
  return mesh;
}

}  // namespace meshcast
