// Reading a triangle mesh from a file: OFF, OBJ, PLY (ascii and binary) and
// STL (ascii and binary), through Assimp, keeping the file's vertices, their
// positions and the triangle order exactly, so a hit's triangle number is the
// file's own. Part of the `reader` component (meshcast::reader; link it and
// Assimp comes with it); the core library reads no files but blobs.
#pragma once
#include <string>

#include "meshcast/mesh.h"

namespace meshcast {

// Polygons are fanned (v0, vi, vi+1) in file order; points and lines are
// ignored. The mesh passes check_mesh (mesh.h). Throws InputError (the
// message names the file and the problem) for a missing or unreadable file,
// an unknown format, a malformed file, out-of-range indices, NaN or infinite
// coordinates, coordinates beyond kMaxCoordinate, or a file without any
// triangle.
Mesh read_mesh(const std::string& path);

}  // namespace meshcast
