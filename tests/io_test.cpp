// Tests for io/read_mesh and io/generate. Small files of every format are
// written by the tests themselves; the CGAL meshes are read from
// $MESHCAST_DATA (default "data") and compared with an independent OFF parse.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "check/generate.h"
#include "meshcast/read.h"
#include "tests/testing.h"

namespace fs = std::filesystem;
using namespace meshcast;
using meshcast::testing::make_file;

namespace {

// The reference polygon set: a triangle, a quad and a pentagon over 6 vertices.
// 0.1 is not exactly representable: checks correct rounding of text formats.
const std::vector<Vec3> kVerts = {{0.1f, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, 0}, {2, 0, -3}, {2, 1, 1e-3f}};
const char* kVertText = "0.1 0 0\n1 0 0\n1 1 0.5\n0 1 0\n2 0 -3\n2 1 0.001\n";
const std::vector<Triangle> kFanned = {{0, 1, 2}, {0, 1, 2}, {0, 2, 3}, {0, 1, 4}, {0, 4, 5}, {0, 5, 2}};

std::string ply_header(const char* format, int nfaces = 3) {
  return std::string("ply\nformat ") + format +
         " 1.0\ncomment test\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
         "element face " + std::to_string(nfaces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

std::string binary_ply(const std::vector<std::vector<int32_t>>& faces) {
  std::string s = ply_header("binary_little_endian", int(faces.size()));
  for (const Vec3& v : kVerts) s.append(reinterpret_cast<const char*>(&v), 12);  // host is little-endian
  for (const auto& f : faces) {
    s.push_back(char(f.size()));
    s.append(reinterpret_cast<const char*>(f.data()), 4 * f.size());
  }
  return s;
}

void expect_same(const Mesh& m, const std::vector<Vec3>& verts, const std::vector<Triangle>& tris) {
  ASSERT_EQ(m.vertices.size(), verts.size());
  for (size_t i = 0; i < verts.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.vertices[i][k], verts[i][k]) << "vertex " << i;
  EXPECT_EQ(m.triangles, tris);
}

// read_mesh must throw InputError mentioning the file name and `word`.
void expect_error(const std::string& path, const std::string& word) {
  try {
    read_mesh(path);
    ADD_FAILURE() << path << ": no error, expected one about '" << word << "'";
  } catch (const InputError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find(fs::path(path).filename().string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(word), std::string::npos) << "expected '" << word << "' in: " << msg;
  }
}

}  // namespace

TEST(ReadMesh, OffKeepsIndexingAndFanOrder) {
  std::string p = make_file("a.off", std::string("OFF\n# comment\n6 3 0\n") + kVertText +
                                           "3 0 1 2\n4 0 1 2 3\n5 0 1 4 5 2\n");
  expect_same(read_mesh(p), kVerts, kFanned);
}

TEST(ReadMesh, ObjRestoresSharedVerticesAcrossGroups) {
  // Assimp splits this into several aiMeshes and unrolls the corners; the
  // reader must give back the file's 6 vertices and its face order (the
  // texture and normal references name records the file has).
  std::string p = make_file("a.obj", std::string("# test\n") + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n" +
                                           "v 0.1 0 0\nv 1 0 0\nv 1 1 0.5\n" +
                                           "g one\nf 1 2 3\nv 0 1 0\nv 2 0 -3\nv 2 1 0.001\nusemtl m\n" +
                                           "f 1/1 2/2 3/3 4/4\ng two\nl 1 2\nf -6//1 -5//1 5//1 6//1 3//1\n");
  expect_same(read_mesh(p), kVerts, kFanned);
}

TEST(ReadMesh, PlyAscii) {
  std::string p = make_file("a.ply", ply_header("ascii") + kVertText + "3 0 1 2\n4 0 1 2 3\n5 0 1 4 5 2\n");
  expect_same(read_mesh(p), kVerts, kFanned);
  // Windows line ends in the header and a UTF-8 comment are still PLY.
  std::string header = ply_header("binary_little_endian");
  std::string crlf;
  for (char c : header.substr(0, header.size() - 11)) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  crlf += "comment auteur Zo\xc3\xab\r\nend_header\n";
  std::string bin = binary_ply({{0, 1, 2}, {0, 1, 2, 3}, {0, 1, 4, 5, 2}});
  expect_same(read_mesh(make_file("crlf.ply", crlf + bin.substr(header.size()))), kVerts, kFanned);
}

TEST(ReadMesh, PlyBinary) {
  std::string p = make_file("b.ply", binary_ply({{0, 1, 2}, {0, 1, 2, 3}, {0, 1, 4, 5, 2}}));
  expect_same(read_mesh(p), kVerts, kFanned);
}

TEST(ReadMesh, StlAsciiAndBinary) {
  // STL has no indexing: three own vertices per facet, in file order.
  std::string a = "solid one\n";
  for (int f = 0; f < 2; ++f) {
    a += "facet normal 0 0 1\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = kVerts[f * 3 + k];
      std::ostringstream line;
      line.precision(9);
      line << "vertex " << v.x << ' ' << v.y << ' ' << v.z << '\n';
      a += line.str();
    }
    a += "endloop\nendfacet\n";
  }
  a += "endsolid one\n";
  const std::vector<Triangle> tris = {{0, 1, 2}, {3, 4, 5}};
  expect_same(read_mesh(make_file("a.stl", a)), kVerts, tris);

  std::string b(80, '\0');
  uint32_t n = 2;
  b.append(reinterpret_cast<const char*>(&n), 4);
  for (int f = 0; f < 2; ++f) {
    float normal[3] = {0, 0, 1};
    b.append(reinterpret_cast<const char*>(normal), 12);
    for (int k = 0; k < 3; ++k) b.append(reinterpret_cast<const char*>(&kVerts[f * 3 + k]), 12);
    b.append(2, '\0');
  }
  expect_same(read_mesh(make_file("b.stl", b)), kVerts, tris);
}

TEST(ReadMeshErrors, MissingUnknownMalformed) {
  expect_error((meshcast::testing::scratch_dir() / "no_such_file.off").string(), "cannot open");
  expect_error(make_file("mesh.xyz", "1 2 3\n"), "unknown format");
  expect_error(make_file("garbage.off", "hello world\n"), "malformed");
  expect_error(make_file("garbage_index.off", std::string("OFF\n6 1 0\n") + kVertText + "3 0 x 2\n"), "malformed");
  expect_error(make_file("truncated.off", std::string("OFF\n6 2 0\n") + kVertText + "3 0 1 2\n"), "ends after");
  expect_error(make_file("garbage.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"), "malformed");
  // Assimp hangs on a PLY header without end_header and reads past the end of
  // truncated PLY files; the reader checks the layout first.
  expect_error(make_file("no_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"), "end_header");
  expect_error(make_file("short.ply", ply_header("ascii") + kVertText + "3 0 1 2\n4 0 1 2 3\n"), "truncated");
  std::string bin = binary_ply({{0, 1, 2}, {0, 1, 2, 3}, {0, 1, 4, 5, 2}});
  expect_error(make_file("short_bin.ply", bin.substr(0, bin.size() - 6)), "truncated");
  // A header line that is no PLY keyword made Assimp read past its buffers
  // (found by fuzz/mesh_fuzz).
  expect_error(make_file("bad_keyword.ply", "ply\nformat ascii 1.0\nelement vertex 3\npropertLL float x\nend_header\n"),
               "unknown PLY header line");
  expect_error(make_file("short_property.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty\nend_header\n"),
               "bad property line");
  expect_error(make_file("hash.ply", "ply\nformat ascii 1.0\nelement vertex 3\n#propertLL float x\nend_header\n"),
               "'#' in a PLY header line");
  expect_error(make_file("huge_element.ply", "ply\nformat binary_little_endian 1.0\nelement foo 4000000000\nend_header\n"),
               "bad element line");
  expect_error(make_file("float_count.ply", "ply\nformat ascii 1.0\nelement face 1\nproperty list float int v\nend_header\n"),
               "bad property line");
  expect_error(make_file("header_byte.ply", "ply\nformat ascii 1.0\nelement vertex 3\x8a\nend_header\n"),
               "printable ASCII");
  expect_error(make_file("garbage.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"), "malformed");
  expect_error(make_file("big_face.off", std::string("OFF\n6 1 0\n") + kVertText + "10 0 1 2 3 4 5 0 1 2 3\n"),
               "corners");
}

TEST(ReadMeshErrors, NonFiniteCoordinates) {
  expect_error(make_file("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"), "NaN");
  expect_error(make_file("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n"), "infinite");
  expect_error(make_file("nan.ply", ply_header("ascii") + "0 0 0\n1 0 0\n1 1 nan\n0 1 0\n2 0 0\n2 1 0\n" +
                                         "3 0 1 2\n3 0 2 3\n3 1 4 5\n"),
               "NaN");
}

TEST(ReadMeshErrors, OutOfRangeIndices) {
  // Assimp clamps this one to vertex 5 without a word.
  expect_error(make_file("oor.off", std::string("OFF\n6 1 0\n") + kVertText + "3 0 1 6\n"), "out of range");
  expect_error(make_file("neg.off", std::string("OFF\n6 1 0\n") + kVertText + "3 0 -1 2\n"), "out of range");
  expect_error(make_file("oor.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), "out of range");
  expect_error(make_file("oor.ply", ply_header("ascii") + kVertText + "3 0 1 2\n3 0 1 7\n3 0 1 2\n"),
               "out of range");
  expect_error(make_file("oor_bin.ply", binary_ply({{0, 1, 2}, {0, 1, 6}, {0, 1, 2}})), "out of range");
  expect_error(make_file("neg_bin.ply", binary_ply({{0, 1, 2}, {0, -1, 2}, {0, 1, 2}})), "out of range");
}

TEST(ReadMeshErrors, EmptyAndPointsOrLinesOnly) {
  expect_error(make_file("empty.off", std::string("OFF\n6 0 0\n") + kVertText), "no faces");
  expect_error(make_file("empty.obj", std::string("v 0 0 0\nv 1 0 0\n")), "no faces");
  expect_error(make_file("pl.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\np 1\n"), "lines");
  expect_error(make_file("pl.off", std::string("OFF\n6 2 0\n") + kVertText + "2 0 1\n1 2\n"), "lines");
  expect_error(make_file("blank.stl", "solid x\nendsolid x\n"), "empty");
}

// --- the CGAL meshes against an independent, naive OFF parse ---------------

struct OffCase {
  const char* file;
  size_t vertices, triangles;
};

class CgalMesh : public ::testing::TestWithParam<OffCase> {};

TEST_P(CgalMesh, MatchesIndependentOffParse) {
  const char* env = std::getenv("MESHCAST_DATA");
  fs::path path = fs::path(env ? env : "data") / GetParam().file;
  if (!fs::exists(path)) GTEST_SKIP() << path << " not found (set MESHCAST_DATA)";

  std::ifstream in(path);
  std::string magic;
  size_t nv, nf, ne;
  in >> magic >> nv >> nf >> ne;
  std::vector<Vec3> v(nv);
  std::string tok;
  for (Vec3& p : v)
    for (int k = 0; k < 3; ++k) in >> tok, p[k] = std::strtof(tok.c_str(), nullptr);
  std::vector<Triangle> tris;
  for (size_t f = 0; f < nf; ++f) {
    size_t n;
    in >> n;
    std::vector<uint32_t> idx(n);
    for (auto& i : idx) in >> i;
    for (size_t k = 1; k + 1 < n; ++k) tris.push_back({idx[0], idx[k], idx[k + 1]});
  }
  ASSERT_TRUE(in) << "reference parse failed";
  EXPECT_EQ(v.size(), GetParam().vertices);
  EXPECT_EQ(tris.size(), GetParam().triangles);

  Mesh m = read_mesh(path.string());
  ASSERT_EQ(m.vertices.size(), v.size());
  ASSERT_EQ(m.triangles.size(), tris.size());
  size_t bad = 0;
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) bad += m.corner(t, k)[c] != v[tris[t][k]][c];  // bitwise-exact positions
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(m.triangles, tris);
}

INSTANTIATE_TEST_SUITE_P(Data, CgalMesh,
                         ::testing::Values(OffCase{"bunny00.off", 37706, 75408}, OffCase{"armadillo.off", 26002, 52000},
                                           OffCase{"refined_elephant.off", 44460, 88928},
                                           OffCase{"ChineseDragon-10kv.off", 10000, 19994}),
                         [](const auto& info) {
                           std::string s = info.param.file;
                           return s.substr(0, s.find_first_of(".-"));
                         });

// --- generators -------------------------------------------------------------

TEST(Generate, SphereIsClosedAndOutward) {
  for (auto [rings, segments] : {std::pair{2, 3}, {8, 16}, {31, 64}}) {
    Mesh m = make_sphere(rings, segments, 2.0f, {1, -2, 3});
    check_mesh(m, "sphere");
    EXPECT_EQ(m.vertices.size(), size_t(2 + (rings - 1) * segments));
    EXPECT_EQ(m.triangles.size(), size_t(2 * (rings - 1) * segments));
    // Every undirected edge in exactly two triangles, once in each direction.
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    double volume6 = 0;
    for (size_t t = 0; t < m.triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) ++directed[{m.triangles[t][k], m.triangles[t][(k + 1) % 3]}];
      Vec3 a = m.corner(t, 0), b = m.corner(t, 1), c = m.corner(t, 2);
      a = {a.x - 1, a.y + 2, a.z - 3}, b = {b.x - 1, b.y + 2, b.z - 3}, c = {c.x - 1, c.y + 2, c.z - 3};
      volume6 += a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
    }
    for (const auto& [e, n] : directed) {
      EXPECT_EQ(n, 1) << e.first << "->" << e.second;
      EXPECT_EQ(directed.count({e.second, e.first}), 1u) << "open edge " << e.first << "-" << e.second;
    }
    EXPECT_GT(volume6, 0.0);  // outward-facing
    for (const Vec3& v : m.vertices)
      EXPECT_NEAR(std::hypot(v.x - 1, v.y + 2, v.z - 3), 2.0, 1e-5);
  }
}

TEST(Generate, GridPlaneHasIntegerCoordinates) {
  Mesh m = make_grid_plane(5, 3);
  check_mesh(m, "grid");
  EXPECT_EQ(m.vertices.size(), 6u * 4u);
  EXPECT_EQ(m.triangles.size(), 2u * 5u * 3u);
  for (const Vec3& v : m.vertices) {
    EXPECT_EQ(v.x, std::floor(v.x));
    EXPECT_EQ(v.y, std::floor(v.y));
    EXPECT_EQ(v.z, 0.0f);
  }
  Box3 b = m.bounds();
  EXPECT_EQ(b.min.x, 0.0f);
  EXPECT_EQ(b.min.y, 0.0f);
  EXPECT_EQ(b.max.x, 5.0f);
  EXPECT_EQ(b.max.y, 3.0f);
}

TEST(Generate, TerrainLargeDeterministicFinite) {
  Mesh m = make_terrain(1024, 1024, 7);
  EXPECT_EQ(m.triangles.size(), 2097152u);
  check_mesh(m, "terrain");  // finite, indices in range
  Mesh again = make_terrain(1024, 1024, 7), other = make_terrain(1024, 1024, 8);
  EXPECT_EQ(std::memcmp(m.vertices.data(), again.vertices.data(), m.vertices.size() * sizeof(Vec3)), 0);
  EXPECT_NE(std::memcmp(m.vertices.data(), other.vertices.data(), m.vertices.size() * sizeof(Vec3)), 0);
  Box3 b = m.bounds();
  EXPECT_EQ(b.max.x, 1024.0f);
  EXPECT_GT(b.max.z - b.min.z, 1.0f);  // not flat
}
