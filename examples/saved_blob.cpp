// A blob built once (at asset-build time), saved, then memory-mapped by the
// game and cast against without a copy. Usage: saved_blob [FILE]
#include <meshcast/meshcast.h>

#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "saved_blob_example.mcb";
  try {
    {  // the asset build: a unit square of two triangles, saved
      const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
      const std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
      const meshcast::MeshView mesh(xyz, 3, indices);
      meshcast::BuildOptions options;
      options.layout = meshcast::parse_layout_name("AABBTree/Float3");
      meshcast::save_blob(path, meshcast::build_blob(mesh, options, "square"));
    }
    // The game: the file mapped, validated once, walked in place.
    const meshcast::MappedBlob file(path);
    const meshcast::BlobView view(file.bytes(), path);
    const std::vector<meshcast::Ray> rays = {{{0.8f, 0.1f, 1}, {0, 0, -1}, INFINITY},   // triangle 0
                                             {{0.1f, 0.8f, 1}, {0, 0, -1}, INFINITY},   // triangle 1
                                             {{2.0f, 2.0f, 1}, {0, 0, -1}, INFINITY}};  // beside the square
    std::vector<meshcast::Hit> hits(rays.size());
    view.trace(rays, hits);
    const bool ok = hits[0].triangle == 0 && hits[1].triangle == 1 && hits[2].triangle == meshcast::kNoHit;
    // The same bytes read whole agree.
    const std::vector<uint8_t> copy = meshcast::load_blob(path);
    const bool same = copy.size() == file.bytes().size();
    std::printf("%s: %s, %zu bytes mapped, hits %u %u %s\n", ok && same ? "ok" : "WRONG", path.c_str(),
                file.bytes().size(), hits[0].triangle, hits[1].triangle, hits[2].triangle == meshcast::kNoHit ? "miss" : "hit");
    return ok && same ? 0 : 1;
  } catch (const meshcast::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
