// The input mesh as the caller gave it: vertex positions and triangles in input
// order. Everything downstream (builder, layouts, oracle) starts from this.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "meshcast/errors.h"

namespace meshcast {

struct Vec3 {
  float x = 0, y = 0, z = 0;
  float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

struct Box3 {
  Vec3 min{+INFINITY, +INFINITY, +INFINITY};
  Vec3 max{-INFINITY, -INFINITY, -INFINITY};
  // Inline: the builder grows boxes for every triangle at every level, and
  // an out-of-line call each took a third of the build's time.
  void grow(const Vec3& p) {
    min = {std::min(min.x, p.x), std::min(min.y, p.y), std::min(min.z, p.z)};
    max = {std::max(max.x, p.x), std::max(max.y, p.y), std::max(max.z, p.z)};
  }
  void grow(const Box3& b) {  // min of minima, max of maxima: an empty b changes nothing
    min = {std::min(min.x, b.min.x), std::min(min.y, b.min.y), std::min(min.z, b.min.z)};
    max = {std::max(max.x, b.max.x), std::max(max.y, b.max.y), std::max(max.z, b.max.z)};
  }
  bool empty() const { return min.x > max.x; }
  Vec3 centre() const { return {0.5f * (min.x + max.x), 0.5f * (min.y + max.y), 0.5f * (min.z + max.z)}; }
  Vec3 extent() const { return {max.x - min.x, max.y - min.y, max.z - min.z}; }
  // SAH cost unit: xy + yz + zx, in double (1e-30 or 1e30 wide boxes).
  // Out of line: a caller's copy compiled with fused multiply-adds would
  // round it otherwise and change the tree the builder chooses.
  double half_area() const;
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


// Coordinates beyond this (about 1.27e30) are refused, in meshes and in ray
// origins: extents, areas and half-float scales computed from them must stay
// finite in float, and the triangle test's double redo must stay in range.
// Below, the formats that keep vertices on a grid refuse a mesh whose extent
// on an axis is above 0 but under about 2^-106 (1.2e-32; the message names
// the format's own limit): the grid's step would fall below FLT_MIN.
constexpr float kMaxCoordinate = 0x1p100f;

// A mesh in the caller's own memory, read where it lies: `vertex_count`
// positions of three floats (x, y, z) every `vertex_stride` bytes, and
// `triangle_count` triangles of three 16- or 32-bit vertex indices every
// `triangle_stride` bytes (0: the three indices packed, 6 or 12 bytes). An
// engine's interleaved vertex buffer and its index buffer serve as they are;
// build_blob reads them once and keeps nothing.
//
// Make it from typed spans where you can: the counts, the stride's unit and
// the index type then come from the types, and the buffers' sizes are
// checked (a wrong stride or index type is an error, not a wrong mesh):
//
//   // position, normal, uv interleaved: 8 floats a vertex; 16-bit indices
//   meshcast::MeshView mesh(std::span<const float>(vertices), 8, std::span<const uint16_t>(indices));
//
// `positions` starts at the first vertex's x (take a subspan when the
// position is not first in a vertex) and `stride` counts floats from one
// vertex's x to the next (3 when packed). Every stride's start in the span
// is a vertex, and the span must hold the last one's three floats; the
// indices must be a whole number of triangles. A stride under 3 floats, or
// one so large that a vertex count times it overflows, is refused, and
// every message names the stride as given, in floats.
//
// Filled in by hand (the raw pointers, for buffers that are not floats),
// the sizes stay 0 (unknown) and only the strides can be checked: set
// `index_type` to the buffer's own (it defaults to 32-bit; a value that is
// neither IndexType is refused), and `vertex_stride` in bytes.
enum class IndexType : uint8_t { Uint16, Uint32 };
struct MeshView {
  const void* positions = nullptr;
  size_t vertex_count = 0;
  size_t vertex_stride = 3 * sizeof(float);
  const void* indices = nullptr;
  size_t triangle_count = 0;
  IndexType index_type = IndexType::Uint32;
  size_t triangle_stride = 0;
  // The bytes `positions` and `indices` hold, where known (0: unknown):
  // copy_mesh refuses a view whose last vertex or triangle lies past them.
  size_t positions_bytes = 0, indices_bytes = 0;
  // The typed constructors' stride as the caller gave it, in floats, which
  // copy_mesh's messages name (`vertex_stride` holds it in bytes, SIZE_MAX
  // where that overflows); unset for a view filled in by hand.
  std::optional<size_t> stride_in_floats;

  MeshView() = default;
  MeshView(std::span<const float> positions, size_t stride, std::span<const uint32_t> indices)
      : MeshView(positions, stride, indices.data(), indices.size(), IndexType::Uint32) {}
  MeshView(std::span<const float> positions, size_t stride, std::span<const uint16_t> indices)
      : MeshView(positions, stride, indices.data(), indices.size(), IndexType::Uint16) {}

 private:
  MeshView(std::span<const float> p, size_t stride, const void* i, size_t index_count, IndexType type)
      : positions(p.data()),
        // Every stride's start in the span. A stride of 0 is left for
        // copy_mesh to refuse (shorter than a position); one past any
        // buffer's size stays past it rather than wrapping.
        vertex_count(stride ? p.size() / stride + (p.size() % stride != 0) : 0),
        vertex_stride(stride > SIZE_MAX / sizeof(float) ? SIZE_MAX : stride * sizeof(float)),
        indices(i),
        triangle_count(index_count / 3 + (index_count % 3 != 0)),
        index_type(type),
        positions_bytes(p.size() * sizeof(float)),
        indices_bytes(index_count * (type == IndexType::Uint16 ? 2 : 4)),
        stride_in_floats(stride) {}
};

// The view's mesh, copied into a Mesh and checked (check_mesh), named
// `name` in messages; InputError also for a null array with a count, a
// stride shorter than its element or whose product with its count
// overflows, an index_type that is neither IndexType, a last vertex or
// triangle past the bytes a view states, an index past the view's
// vertices (naming the stride), or sizes beyond 2^32 vertices.
Mesh copy_mesh(const MeshView& view, const std::string& name);

// Checks what every layout relies on: at least one triangle, every index in
// range, every coordinate finite and within kMaxCoordinate. `name` is used in the message (a file path or
// a generator name). Throws InputError.
void check_mesh(const Mesh& mesh, const std::string& name);

}  // namespace meshcast
