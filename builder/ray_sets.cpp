#include "builder/ray_sets.h"

#include <algorithm>
#include <cmath>

namespace meshcast {

namespace {

// SplitMix64: small, fast, and the same sequence on every platform (the
// standard distributions are not), so ray files are reproducible.
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1p-53; }  // [0, 1)
  Vec3 unit() {  // uniform on the sphere
    double z = 2 * uniform() - 1, phi = 2 * M_PI * uniform(), r = std::sqrt(std::max(0.0, 1 - z * z));
    return {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
  }
};

Vec3 lerp_box(const Box3& b, Rng& rng) {
  return {float(b.min.x + rng.uniform() * (double(b.max.x) - b.min.x)),
          float(b.min.y + rng.uniform() * (double(b.max.y) - b.min.y)),
          float(b.min.z + rng.uniform() * (double(b.max.z) - b.min.z))};
}

}  // namespace

const std::vector<std::string>& ray_kind_names() {
  static const std::vector<std::string> names = {"long", "probe", "radial", "segment"};
  return names;
}

RayKind parse_ray_kind(const std::string& name) {
  const std::vector<std::string>& names = ray_kind_names();
  std::string valid;
  for (size_t k = 0; k < names.size(); ++k) {
    if (name == names[k]) return RayKind(k);
    valid += (k ? ", " : "") + names[k];
  }
  throw InputError("unknown ray kind '" + name + "'; valid kinds: " + valid);
}

RaySource::RaySource(const Mesh& mesh, RayKind kind, uint64_t seed)
    : mesh_(mesh), kind_(kind), state_(seed * 0x2545F4914F6CDD1Dull + uint64_t(kind)), box_(mesh.bounds()),
      diagonal_(box_.diagonal()) {}

void RaySource::fill(std::span<Ray> rays) {
  Rng rng{state_};
  const Vec3 c = box_.centre();
  const double diag = diagonal_;
  // A point of a random triangle moved off it along its normal, to either
  // side, by 10^-4 of the diagonal.
  auto off_surface = [&](Rng& g) {
    size_t t = size_t(g.uniform() * mesh_.triangles.size());
    double a = g.uniform(), b = g.uniform();
    if (a + b > 1) a = 1 - a, b = 1 - b;
    Vec3 p0 = mesh_.corner(t, 0), p1 = mesh_.corner(t, 1), p2 = mesh_.corner(t, 2);
    double e1[3], e2[3], n[3];
    for (int k = 0; k < 3; ++k) e1[k] = double(p1[k]) - p0[k], e2[k] = double(p2[k]) - p0[k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double side = g.uniform() < 0.5 ? -1 : 1, off = 1e-4 * diag * side / (len > 0 ? len : 1);
    Vec3 o;
    for (int k = 0; k < 3; ++k) o[k] = float(p0[k] + a * e1[k] + b * e2[k] + (len > 0 ? n[k] * off : 0));
    return o;
  };
  for (Ray& r : rays) {
    Vec3 o, d;
    float tmax = INFINITY;
    if (kind_ == RayKind::Long) {
      Vec3 u = rng.unit();
      o = {float(c.x + diag * u.x), float(c.y + diag * u.y), float(c.z + diag * u.z)};
      Vec3 p = lerp_box(box_, rng);
      d = {p.x - o.x, p.y - o.y, p.z - o.z};
    } else if (kind_ == RayKind::Radial) {
      o = c;
      d = rng.unit();
    } else if (kind_ == RayKind::Probe) {
      o = off_surface(rng);
      d = rng.unit();
      tmax = float(0.05 * diag);
    } else {
      o = off_surface(rng);
      const Vec3 p = off_surface(rng);
      d = {p.x - o.x, p.y - o.y, p.z - o.z};
      tmax = 1.0f;
    }
    r = {{o.x, o.y, o.z}, {d.x, d.y, d.z}, tmax};
  }
  state_ = rng.s;
}

std::vector<Ray> make_rays(const Mesh& mesh, RayKind kind, size_t count, uint64_t seed) {
  std::vector<Ray> rays(count);
  RaySource(mesh, kind, seed).fill(rays);
  return rays;
}

}  // namespace meshcast
