// The double-precision oracle for scenes: every instance's
// triangles moved into the world in double (rotation_scale as exact
// doubles, the translation added in double), the world ray in double, the
// oracle's watertight test; no top level, no float anywhere. Ties: the
// lowest instance id, then the lowest triangle.
#pragma once
#include <vector>

#include "check/oracle.h"
#include "meshcast/scene.h"

namespace meshcast {

struct SceneOracleHit {
  double t = INFINITY;
  uint32_t instance = kNoHit, triangle = kNoHit;
};

// An instance as the oracle places it: `mesh` indexes the meshes given to
// SceneOracle (each the mesh as its blob stores it: the input mesh, or
// stored_mesh() of a blob whose format moves vertices).
struct OracleInstance {
  uint32_t id, mesh;
  Transform transform;
  uint8_t mask = 0xFF;
  bool flip_facing = false;  // Scene::add_instance's
};

class SceneOracle {
 public:
  SceneOracle(const std::vector<const Mesh*>& meshes, const std::vector<OracleInstance>& instances);
  // The closest hit among the instances whose mask shares a bit with
  // `mask`; the front face as the mesh has it (Transform's rule): the
  // winding of the triangle's world corners from the ray's origin, turned
  // where the instance mirrors (its determinant, in double, negative) and
  // turned again by its flip_facing.
  SceneOracleHit closest(const RayD& ray, Cull cull = Cull::None, uint8_t mask = 0xFF) const;
  // Every hit in [t_min, t_max], in order of t, then instance, then triangle.
  std::vector<SceneOracleHit> all(const RayD& ray, Cull cull = Cull::None, uint8_t mask = 0xFF) const;
  // Whether the triangle of instance `instance` (an index into the
  // instances given) meets the ray in double at distance t, to within
  // `slack` in the world: the distance from o + t d to the triangle.
  double distance_to(size_t instance, uint32_t triangle, const RayD& ray, double t) const;
  // The distance from o + t d to the nearest edge of that triangle.
  double distance_to_edge(size_t instance, uint32_t triangle, const RayD& ray, double t) const;
  // The distance from o + t d to the point of that triangle at barycentric
  // (u, v): corner 0 + u (corner 1 - corner 0) + v (corner 2 - corner 0),
  // the corners in the mesh's order (a hit's u, v).
  double distance_to_uv(size_t instance, uint32_t triangle, const RayD& ray, double t, double u, double v) const;
  // The index of instance id `id` among those given.
  size_t index_of(uint32_t id) const;

 private:
  // Every triangle of every instance whose box the ray enters before `cut`
  // (read again after each instance) to take(t, instance id, triangle).
  template <class Take>
  void visit(const RayD& ray, Cull cull, uint8_t mask, const double* cut, Take&& take) const;
  struct Placed {
    OracleInstance instance;
    std::vector<double> corners;  // 9 a triangle, world coordinates
    double min[3], max[3];
    bool world_winding_turned;  // the world corners' front is the mesh's back
  };
  std::vector<Placed> placed_;
};

}  // namespace meshcast
