// Ray sets and the two files exchanged with the outside (ARCHITECTURE.md):
//   rays: "RAYS", uint32 count, per ray 7 float32 (origin, direction, t_max)
//   hits: "HITS", uint32 count, per ray float32 t (inf: miss), uint32 triangle
// All little-endian.
#pragma once
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cpu/mesh.h"
#include "cpu/ray.h"

namespace meshcast {

enum class RayKind { Long, Probe, Radial };

// Throws InputError for an unknown name, listing the valid ones.
RayKind parse_ray_kind(const std::string& name);

// Deterministic for a given mesh, kind, count and seed.
//  Long:   origins on a sphere around the mesh (radius = box diagonal) aimed at
//          random points inside its box; t_max infinite.
//  Probe:  short rays (t_max = 5% of the diagonal) from just off a random
//          point of a random triangle, in random directions.
//  Radial: from the centre of the box in random directions; t_max infinite.
std::vector<Ray> make_rays(const Mesh& mesh, RayKind kind, size_t count, uint64_t seed);

// Throw InputError naming the file on a bad magic, short or oversized file.
std::vector<Ray> read_rays(const std::string& path);
void write_rays(const std::string& path, const std::vector<Ray>& rays);
std::vector<Hit> read_hits(const std::string& path);
void write_hits(const std::string& path, const std::vector<Hit>& hits);

// Most rays a rays file may hold, and `meshcast rays --count` make: 2^27
// (3.5 GiB of records).
constexpr size_t kMaxRayCount = size_t(1) << 27;

// Whole-file helpers for meshes, blobs, rays and hits: read_file reads a
// regular file and throws InputError naming the path for anything else (a
// directory, a device such as /dev/zero or a pipe is refused before any
// read: it has no size to read up to). write_file writes the pieces in order to a file
// beside `path`, checks every write, the flush and the close, then renames it
// to `path`, so a failed write (a full disk) leaves no partial file under
// that name; an existing path that is not a regular file (/dev/null,
// /dev/full, a pipe) is written in place. Failures throw OutputError naming
// the path and the reason.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
struct Bytes {
  const void* data;
  size_t size;
};
// The check read_file makes first, for a reader that must judge the path
// before it reads (read_mesh: kind of file, then extension, then bytes).
void require_regular_file(const std::string& path);
std::vector<uint8_t> read_file(const std::string& path);

// Text output (CSV, plot scripts, profiles): built in memory, then written
// by write_file when commit() is called, so it is checked the same way.
class OutputText : public std::ostringstream {
 public:
  explicit OutputText(std::string path) : path_(std::move(path)) {}
  void commit();

 private:
  std::string path_;
};
void write_file(const std::string& path, std::initializer_list<Bytes> pieces);
inline void write_file(const std::string& path, const void* data, size_t size) { write_file(path, {{data, size}}); }

}  // namespace meshcast
