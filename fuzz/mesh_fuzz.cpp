// libFuzzer target: any bytes as a mesh file. The first byte picks the
// format (OFF, OBJ, PLY, STL by its value mod 4), the rest is the file. A
// file the reader accepts must build into a blob that validates (or be
// refused by the builder with InputError), and be walked without fault.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "meshcast/mesh.h"
#include "meshcast/blob.h"
#include "fuzz/rays.h"
#include "meshcast/read.h"
#include "layout/blob_format.h"

using namespace meshcast;

namespace {

// The reader takes a path (it needs the extension, Assimp reads the file):
// one scratch file per process, in a directory of its own.
std::string scratch(const char* ext) {
  static char dir[] = "/tmp/meshcast_fuzz_XXXXXX";  // a plain array: still there when atexit runs
  static const bool made = [] {
    if (!mkdtemp(dir)) std::abort();
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    });
    return true;
  }();
  (void)made;
  return std::string(dir) + "/mesh" + ext;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kExt[] = {".off", ".obj", ".ply", ".stl"};
  const std::string path = scratch(kExt[data[0] % 4]);
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size > 1) std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
  } else {
    std::abort();
  }
  try {
    Mesh mesh = read_mesh(path);
    if (mesh.triangles.size() > 4096) return 0;  // keep an execution short
    std::vector<uint8_t> blob = build_blob(mesh, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), path);
    if (!layout::validate(blob).empty()) __builtin_trap();  // the builder wrote what validation refuses
    BlobView view(blob, path);
    Box3 b = mesh.bounds();
    const float lo[3] = {b.min.x, b.min.y, b.min.z}, hi[3] = {b.max.x, b.max.y, b.max.z};
    std::vector<Ray> rays = fuzz::rays_through_box(lo, hi);
    std::vector<Hit> hits(rays.size());
    view.trace(rays, hits);
    if (!fuzz::hits_on_segments(rays, hits)) __builtin_trap();
  } catch (const InputError&) {
  }
  return 0;
}
