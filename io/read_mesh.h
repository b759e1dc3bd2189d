// Reading a triangle mesh from a file (OFF, OBJ, PLY ascii/binary, STL
// ascii/binary) through Assimp, keeping the file's vertices, their positions
// and the triangle order exactly. See read_mesh.cpp for what Assimp does per
// format and how the reader compensates.
#pragma once
#include <string>

#include "meshcast/mesh.h"

namespace meshcast {

// Polygons are fanned (v0, vi, vi+1) in file order; points and lines are
// ignored. Throws InputError (message names the file and the problem) for a
// missing/unreadable file, an unknown format, a malformed file, out-of-range
// indices, NaN/infinite coordinates, or a file without any triangle.
Mesh read_mesh(const std::string& path);

}  // namespace meshcast
