// Mesh reader on top of Assimp 5.2.5 (Debian 12). What the loaders actually do
// when called with no post-processing flags (checked with small probe files and
// the CGAL meshes):
//  - OFF: keeps the file's shared vertices and indexing, polygons stay
//    polygons. But it silently clamps out-of-range indices to nv-1, reads
//    negative or garbage indices as 0, drops faces with 0 or more than 9
//    corners, and on a truncated file returns faces with no indices; none of
//    this is reported (only logged).
//  - OBJ: unrolls every face corner into its own vertex (file indexing lost),
//    splits the scene into one aiMesh per group/object/material change (in
//    file order), turns `l` into 2-index and `p` into 1-index faces, and
//    reports out-of-range/zero indices as errors.
//  - PLY: keeps shared vertices and indexing; out-of-range (even negative)
//    indices are passed through unchecked. It loops forever on a header
//    without end_header and reads garbage past the end of a truncated file,
//    so the PLY layout is checked before Assimp is called.
//  - STL: three own vertices per facet (the format has no indexing); one
//    aiMesh per `solid`.
//  - All text formats parse numbers with Assimp's fast_atoreal, which is not
//    correctly rounded: about 5% of armadillo.off's coordinates come out one
//    ulp away from the nearest float. Binary formats copy floats exactly.
//  - aiProcess_Triangulate does not fan: a quad (0 1 2 3) becomes (2 0 1)
//    (2 3 0), larger polygons are ear-clipped. JoinIdenticalVertices merges by
//    position, which would weld distinct file vertices that happen to coincide.
// What we do: read with flags 0 (no post-processing at all) and fan polygons
// ourselves. For the text formats we also scan the text (OFF/OBJ: vertices and
// faces; PLY/STL ascii: vertex coordinates only) with correctly rounded
// std::from_chars; Assimp's result must agree with the scan polygon by polygon
// (within a few ulps), otherwise the file is reported as malformed. The scan's
// exact coordinates replace Assimp's, and for OFF/OBJ the scan's own indexing
// is used, which restores OBJ's shared vertices faithfully. Points and lines
// are ignored; a file with only those is an error. Assimp's logging stays off:
// we never create a DefaultLogger, so it uses its NullLogger.
#include "meshcast/read.h"

#include "io/files.h"

#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string_view>

namespace meshcast {
namespace {

// Polygon soup with shared vertices: face f uses idx[start[f] .. start[f+1]).
struct Polys {
  std::vector<Vec3> vertices;
  std::vector<uint32_t> idx;
  std::vector<size_t> start{0};
  size_t faces() const { return start.size() - 1; }
  size_t corners(size_t f) const { return start[f + 1] - start[f]; }
};

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputError(path + ": " + what);
}

// Splits a line into whitespace-separated tokens; stops at a '#' comment.
std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace((unsigned char)line[i])) ++i;
    if (i == line.size() || line[i] == '#') break;
    size_t j = i;
    while (j < line.size() && !std::isspace((unsigned char)line[j])) ++j;
    out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

// Correctly rounded decimal -> float (unlike Assimp's fast_atoreal).
bool parse_float(std::string_view t, float& out) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  auto r = std::from_chars(t.data(), t.data() + t.size(), out);
  if (r.ec == std::errc::result_out_of_range && r.ptr == t.data() + t.size()) {
    out = std::strtof(std::string(t).c_str(), nullptr);  // overflow -> inf, underflow -> denormal/0
    return true;
  }
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

bool parse_int(std::string_view t, long long& out) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  auto r = std::from_chars(t.data(), t.data() + t.size(), out);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// Iterates over lines, counting them for messages.
struct Lines {
  std::string_view text;
  size_t pos = 0, number = 0;
  bool next(std::string_view& line) {
    if (pos >= text.size()) return false;
    size_t e = text.find('\n', pos);
    if (e == std::string_view::npos) e = text.size();
    line = text.substr(pos, e - pos);
    pos = e + 1;
    ++number;
    return true;
  }
  std::string at() const { return "line " + std::to_string(number) + ": "; }
};

Vec3 parse_vec(const std::string& path, const Lines& ln, std::vector<std::string_view> t, size_t first) {
  Vec3 v;
  if (t.size() < first + 3) fail(path, ln.at() + "malformed file: expected 3 coordinates");
  for (int k = 0; k < 3; ++k)
    if (!parse_float(t[first + k], v[k]))
      fail(path, ln.at() + "malformed file: bad coordinate '" + std::string(t[first + k]) + "'");
  return v;
}

[[noreturn]] void index_error(const std::string& path, const Lines& ln, size_t face, long long i, size_t nv) {
  fail(path, ln.at() + "face " + std::to_string(face) + " uses vertex index " + std::to_string(i) +
                 ", out of range (the file has " + std::to_string(nv) + " vertices)");
}

Polys scan_off(const std::string& path, std::string_view text) {
  Lines ln{text};
  std::string_view line;
  std::vector<std::string_view> head;  // magic word and counts, possibly over several lines
  while (head.size() < 4 && ln.next(line))
    for (auto t : tokens(line)) head.push_back(t);
  if (head.size() < 4 || head[0].size() < 3 || head[0].substr(head[0].size() - 3) != "OFF")
    fail(path, "malformed file: no OFF header with vertex/face/edge counts");
  if (head[0].find_first_of("4n") != std::string_view::npos)
    fail(path, "unsupported OFF variant '" + std::string(head[0]) + "'");
  long long nv, nf, ne;
  if (!parse_int(head[1], nv) || !parse_int(head[2], nf) || !parse_int(head[3], ne) || nv < 0 || nf < 0)
    fail(path, "malformed file: bad counts in the OFF header");
  Polys p;
  while ((long long)p.vertices.size() < nv) {
    if (!ln.next(line)) fail(path, "malformed file: ends after " + std::to_string(p.vertices.size()) + " of " +
                                       std::to_string(nv) + " vertices");
    auto t = tokens(line);
    if (!t.empty()) p.vertices.push_back(parse_vec(path, ln, t, 0));
  }
  while ((long long)p.faces() < nf) {
    if (!ln.next(line)) fail(path, "malformed file: ends after " + std::to_string(p.faces()) + " of " +
                                       std::to_string(nf) + " faces");
    auto t = tokens(line);
    if (t.empty()) continue;
    long long n, i;
    if (!parse_int(t[0], n) || n < 1 || (long long)t.size() < n + 1)
      fail(path, ln.at() + "malformed file: bad face '" + std::string(line) + "'");
    if (n > 9)  // Assimp's OFF loader silently drops such faces
      fail(path, ln.at() + "face with " + std::to_string(n) + " corners (the reader supports at most 9)");
    for (long long k = 1; k <= n; ++k) {
      if (!parse_int(t[k], i)) fail(path, ln.at() + "malformed file: bad index '" + std::string(t[k]) + "'");
      if (i < 0 || i >= nv) index_error(path, ln, p.faces(), i, nv);
      p.idx.push_back(uint32_t(i));
    }
    p.start.push_back(p.idx.size());
  }
  return p;
}

// OBJ: the positions and faces, every index checked, texture and normal
// indices too: Assimp reads them without a range check (an out-of-range one
// made it write freed memory under the mesh fuzzer). Assimp dispatches a
// line on its first letter, so a statement that starts like one of its own
// and is not (`f12`, `vx`) is refused rather than read differently by the two.
Polys scan_obj(const std::string& path, std::string_view text) {
  Lines ln{text};
  std::string_view line;
  Polys p;
  // 1-based references (kind 0 position, 1 texture, 2 normal), checked once
  // every line is read.
  struct Ref {
    long long index;
    int kind;
  };
  std::vector<Ref> refs;
  std::vector<size_t> face_line, face_refs;
  size_t counts[3] = {0, 0, 0};
  static const char* const kKind[3] = {"vertex", "texture coordinate", "normal"};
  while (ln.next(line)) {
    auto t = tokens(line);
    if (t.empty()) continue;
    const std::string_view key = t[0];
    if (key == "v") {
      p.vertices.push_back(parse_vec(path, ln, t, 1));
      ++counts[0];
    } else if (key == "vt" || key == "vn") {
      ++counts[key == "vt" ? 1 : 2];
    } else if (key == "vp") {  // parameter-space vertices: not referenced by faces
    } else if (key == "f" || key == "l" || key == "p") {
      // "l" and "p" are kept as cornerless faces, only to tell "points/lines
      // only" from "empty"; their indices are checked all the same.
      face_line.push_back(ln.number);
      face_refs.push_back(refs.size());
      for (size_t k = 1; k < t.size(); ++k) {
        std::string_view rest = t[k];
        for (int kind = 0; kind < 3 && !rest.empty(); ++kind) {
          const size_t slash = rest.find('/');
          const std::string_view part = rest.substr(0, slash);
          rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash + 1);
          if (kind > 0 && part.empty()) continue;  // "1//3", "1/2/"
          long long i;
          if (!parse_int(part, i) || (kind == 2 && !rest.empty()))
            fail(path, ln.at() + "malformed file: bad index '" + std::string(t[k]) + "'");
          if (i < 0) i += (long long)counts[kind] + 1;  // relative to what precedes the line
          if (i <= 0)
            fail(path, ln.at() + "face " + std::to_string(face_line.size() - 1) + " uses " + kKind[kind] + " index " +
                           std::string(part) + ", out of range");
          refs.push_back({i, kind});
        }
        if (key == "f") p.idx.push_back(0);  // a corner; its vertex is set below
      }
      p.start.push_back(p.idx.size());
    } else if (key.front() == 'v' || key.front() == 'f' || key.front() == 'l' || key.front() == 'p') {
      fail(path, ln.at() + "malformed file: unknown statement '" + std::string(key) +
                     "' (Assimp would read it as '" + std::string(1, key.front()) + "')");
    }
  }
  size_t corner = 0;
  for (size_t f = 0; f < face_line.size(); ++f) {
    const size_t end = f + 1 < face_line.size() ? face_refs[f + 1] : refs.size();
    for (size_t r = face_refs[f]; r < end; ++r) {
      if (refs[r].index > (long long)counts[refs[r].kind]) {
        ln.number = face_line[f];
        if (refs[r].kind == 0) index_error(path, ln, f, refs[r].index, counts[0]);
        fail(path, ln.at() + "face " + std::to_string(f) + " uses " + kKind[refs[r].kind] + " index " +
                       std::to_string(refs[r].index) + ", out of range (the file has " +
                       std::to_string(counts[refs[r].kind]) + ")");
      }
      if (refs[r].kind == 0 && p.start[f + 1] > p.start[f]) p.idx[corner++] = uint32_t(refs[r].index - 1);
    }
  }
  return p;
}

// PLY ascii: the vertex coordinates only (Assimp keeps PLY's indexing).
// Returns nothing where the layout is beyond this simple scan.
std::optional<std::vector<Vec3>> scan_ply_ascii(const std::string& path, std::string_view text) {
  Lines ln{text};
  std::string_view line;
  size_t skip_records = 0, nv = 0;
  int xyz[3] = {-1, -1, -1}, nprop = 0;
  bool in_vertex = false, seen_vertex = false;
  while (ln.next(line)) {
    auto t = tokens(line);
    if (t.empty()) continue;
    if (t[0] == "end_header") break;
    if (t[0] == "element" && t.size() >= 3) {
      long long n;
      if (!parse_int(t[2], n) || n < 0) return std::nullopt;
      in_vertex = t[1] == "vertex";
      if (in_vertex) nv = size_t(n), seen_vertex = true;
      else if (!seen_vertex) skip_records += size_t(n);
    } else if (t[0] == "property" && in_vertex) {
      if (t.size() < 3 || t[1] == "list") return std::nullopt;
      for (int k = 0; k < 3; ++k)
        if (t[2] == std::string_view("xyz" + k, 1)) xyz[k] = nprop;
      ++nprop;
    }
  }
  if (!seen_vertex || xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) return std::nullopt;
  std::vector<Vec3> v;
  while (v.size() < nv && ln.next(line)) {
    auto t = tokens(line);
    if (t.empty()) continue;
    if (skip_records > 0) { --skip_records; continue; }
    if ((int)t.size() < nprop) fail(path, ln.at() + "malformed file: short vertex record");
    Vec3 p;
    for (int k = 0; k < 3; ++k)
      if (!parse_float(t[xyz[k]], p[k])) fail(path, ln.at() + "malformed file: bad coordinate");
    v.push_back(p);
  }
  return v;
}

// STL ascii: every `vertex x y z`, in order (= Assimp's per-facet vertices).
std::vector<Vec3> scan_stl_ascii(const std::string& path, std::string_view text) {
  Lines ln{text};
  std::string_view line;
  std::vector<Vec3> v;
  while (ln.next(line)) {
    auto t = tokens(line);
    if (!t.empty() && t[0] == "vertex") v.push_back(parse_vec(path, ln, t, 1));
  }
  return v;
}

// PLY: checks the header and that the body holds every record it declares.
// Assimp 5.2.5 loops forever without `end_header`, reads past the end of a
// truncated file (garbage indices), and reads past its buffers when a header
// line is not what it expects (found by fuzz/mesh_fuzz: an unknown keyword,
// a line ended by another byte than a newline), so this runs before Assimp
// sees the file and lets through only a header of the PLY grammar in
// printable ASCII, one statement a line.
void check_ply_layout(const std::string& path, std::string_view text) {
  struct Prop { int count_size = 0, size = 0; std::string_view name; };  // count_size > 0: a list
  struct Element { std::string_view name; size_t n = 0; std::vector<Prop> props; };
  std::vector<Element> elements;
  auto type_size = [](std::string_view t) {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
  };
  // PLY names are words. Assimp 5.2.5 reads an element named with leading
  // digits as a count of about 2^32 records and asks for 64 GB (found by
  // fuzz/mesh_fuzz: `element 666...6face 1`); a name must start with a letter
  // or '_'.
  auto is_name = [](std::string_view n) {
    return !n.empty() && (std::isalpha((unsigned char)n[0]) || n[0] == '_') &&
           std::all_of(n.begin(), n.end(), [](char c) { return std::isalnum((unsigned char)c) || c == '_' || c == '-'; });
  };
  Lines ln{text};
  std::string_view line, format;
  size_t end = std::string_view::npos;
  while (end == std::string_view::npos && ln.next(line)) {
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    // Comments may carry any text but control bytes (UTF-8 names, paths).
    const bool comment = line.starts_with("comment") || line.starts_with("obj_info");
    for (unsigned char c : line)
      if ((c < 0x20 && c != '\t') || c == 0x7f || (c > 0x7f && !comment))
        fail(path, ln.at() + "malformed file: a byte outside printable ASCII in the PLY header");
    // PLY has no '#' comments (tokens() would cut the line there and hide
    // the rest from this check, not from Assimp).
    if (!comment && line.find('#') != std::string_view::npos)
      fail(path, ln.at() + "malformed file: '#' in a PLY header line");
    auto t = tokens(line);
    if (ln.number == 1) {
      if (t.size() != 1 || t[0] != "ply") fail(path, "malformed file: no PLY header ending in end_header");
      continue;
    }
    long long n = 0;
    if (t.empty() || comment) continue;
    if (t[0] == "end_header" && t.size() == 1) {
      end = std::min(ln.pos, text.size());
    } else if (t[0] == "format") {
      if (t.size() != 3 || (t[1] != "ascii" && t[1] != "binary_little_endian" && t[1] != "binary_big_endian"))
        fail(path, ln.at() + "malformed file: bad format line");
      format = t[1];
    } else if (t[0] == "element") {
      // Every record takes a byte at least: a count beyond the file's size
      // is malformed (and would overflow the record total below).
      if (t.size() != 3 || !parse_int(t[2], n) || n < 0 || uint64_t(n) > text.size())
        fail(path, ln.at() + "malformed file: bad element line");
      if (!is_name(t[1]))
        fail(path, ln.at() + "malformed file: PLY element name '" + std::string(t[1].substr(0, 32)) +
                       "' is not a word (a letter or '_', then letters, digits, '_' or '-')");
      // Assimp reads `tristrips` but drops triangles of every strip (1 of 2;
      // restarts at -1 lose more): refused rather than read wrong.
      if (t[1] == "tristrips")
        fail(path, ln.at() + "PLY element 'tristrips' (triangle strips) is not supported: write the triangles "
                             "as a 'face' element");
      elements.push_back({t[1], size_t(n), {}});
    } else if (t[0] == "property") {
      // `property TYPE NAME` or `property list COUNT_TYPE TYPE NAME`
      bool list = t.size() == 5 && t[1] == "list";
      if (elements.empty() || t.size() != (list ? 5u : 3u)) fail(path, ln.at() + "malformed file: bad property line");
      Prop p{list ? type_size(t[2]) : 0, type_size(t[list ? 3 : 1]), t.back()};
      const bool integer_count = !list || (t[2] != "float" && t[2] != "float32" && t[2] != "double" && t[2] != "float64");
      if (p.size == 0 || (list && p.count_size == 0) || !integer_count)
        fail(path, ln.at() + "malformed file: bad property line");
      if (!is_name(p.name))
        fail(path, ln.at() + "malformed file: PLY property name '" + std::string(p.name.substr(0, 32)) +
                       "' is not a word (a letter or '_', then letters, digits, '_' or '-')");
      elements.back().props.push_back(p);
    } else {
      fail(path, ln.at() + "malformed file: unknown PLY header line '" + std::string(t[0].substr(0, 32)) + "'");
    }
  }
  if (end == std::string_view::npos) fail(path, "malformed file: no PLY header ending in end_header");
  // Assimp reads a missing coordinate as 0: a vertex needs x, y and z.
  for (const Element& e : elements)
    if (e.name == "vertex")
      for (std::string_view axis : {"x", "y", "z"})
        if (std::none_of(e.props.begin(), e.props.end(), [&](const Prop& p) { return p.name == axis; }))
          fail(path, "malformed file: the PLY vertex element has no '" + std::string(axis) + "' property");
  size_t records = 0, pos = end;
  for (const Element& e : elements) records += e.n;
  if (format == "ascii") {  // one record per line
    Lines body{text.substr(end)};
    size_t have = 0;
    while (have < records && body.next(line)) have += !tokens(line).empty();
    if (have < records) fail(path, "malformed file: truncated, " + std::to_string(have) + " of " +
                                       std::to_string(records) + " records");
    return;
  }
  const bool big = format == "binary_big_endian";
  if (!big && format != "binary_little_endian") fail(path, "malformed file: unknown PLY format");
  for (const Element& e : elements)
    for (size_t r = 0; r < e.n && !e.props.empty(); ++r)  // an element without properties takes no bytes
      for (const Prop& p : e.props) {
        uint64_t count = 1;
        if (p.count_size) {
          if (pos + p.count_size > text.size()) fail(path, "malformed file: truncated binary PLY");
          count = 0;
          for (int b = 0; b < p.count_size; ++b)  // unsigned read; a negative count is huge and fails below
            count |= uint64_t((unsigned char)text[pos + (big ? p.count_size - 1 - b : b)]) << (8 * b);
          pos += p.count_size;
        }
        pos += count * p.size;
        if (pos > text.size()) fail(path, "malformed file: truncated binary PLY");
      }
  if (pos > text.size()) fail(path, "malformed file: truncated binary PLY");
}

// STL: Assimp reads a file as binary when its size is 84 + 50 n bytes (n the
// facet count at byte 80), else as text when it starts with `solid`; anything
// else gets its "Failed to determine STL storage representation". A binary
// file cut short is the usual cause: say so, with the sizes. Returns whether
// the file is binary (Assimp's rule), else it is text.
bool check_stl_layout(const std::string& path, std::string_view text) {
  uint32_t n = 0;
  if (text.size() >= 84) std::memcpy(&n, text.data() + 80, 4);
  if (text.size() >= 84 && text.size() == 84 + 50ull * n) return true;
  // Text: starts with `solid` and is text throughout (many binary writers
  // put `solid` in their 80-byte header too, then floats follow).
  const size_t first = text.find_first_not_of(" \t\r\n");
  const bool ascii = std::all_of(text.begin(), text.end(), [](char c) {
    const unsigned char u = static_cast<unsigned char>(c);
    return (u >= 0x20 && u < 0x7f) || u == '\t' || u == '\n' || u == '\r' || u == '\f' || u == '\v';
  });
  if (first != std::string_view::npos && text.substr(first, 5) == "solid" && ascii) return false;
  if (text.size() < 84)
    fail(path, "malformed file: " + std::to_string(text.size()) +
                   " bytes, neither ASCII STL (no 'solid') nor binary STL (an 84-byte header at least)");
  fail(path, "malformed file: binary STL truncated or padded: the header says " + std::to_string(n) +
                 " facets (84 + 50 x " + std::to_string(n) + " = " + std::to_string(84 + 50ull * n) +
                 " bytes) but the file has " + std::to_string(text.size()) + " bytes");
}

Polys read_assimp(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, 0);  // 0: no post-processing, see top
  if (!scene) fail(path, std::string("malformed file (Assimp: ") + importer.GetErrorString() + ")");
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) fail(path, "malformed file (Assimp: incomplete scene)");
  Polys p;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {  // concatenated in scene order
    const aiMesh* am = scene->mMeshes[m];
    const uint32_t base = uint32_t(p.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      p.vertices.push_back({am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z});
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= am->mNumVertices)  // PLY passes these through
          fail(path, "face " + std::to_string(p.faces()) + " uses vertex index " +
                         std::to_string((int32_t)face.mIndices[k]) + ", out of range (the file has " +
                         std::to_string(am->mNumVertices) + " vertices)");
        p.idx.push_back(base + face.mIndices[k]);
      }
      p.start.push_back(p.idx.size());
    }
  }
  return p;
}

// Same number within a few ulps (Assimp's rounding), or both NaN, or both
// below FLT_MIN: Assimp's fast_atoreal reads denormals inexactly (7.5e-43
// comes out another denormal or 0), and the exact scan's value is kept.
bool close(float a, float b) {
  if (a == b || (std::isnan(a) && std::isnan(b))) return true;
  if (std::fabs(a) < FLT_MIN && std::fabs(b) < FLT_MIN) return true;
  return std::fabs(a - b) <= 4e-7f * std::max(std::fabs(a), std::fabs(b));
}
bool close(const Vec3& a, const Vec3& b) { return close(a.x, b.x) && close(a.y, b.y) && close(a.z, b.z); }

// The polygons (3+ corners) of `file` and of Assimp's reading must agree.
void cross_check(const std::string& path, const Polys& file, const Polys& as) {
  auto polys = [](const Polys& p) {
    std::vector<size_t> r;
    for (size_t f = 0; f < p.faces(); ++f)
      if (p.corners(f) >= 3) r.push_back(f);
    return r;
  };
  std::vector<size_t> a = polys(file), b = polys(as);
  if (a.size() != b.size())
    fail(path, "malformed file: Assimp read " + std::to_string(b.size()) + " polygons where the text lists " +
                   std::to_string(a.size()));
  for (size_t i = 0; i < a.size(); ++i) {
    bool same = file.corners(a[i]) == as.corners(b[i]);
    for (size_t k = 0; same && k < file.corners(a[i]); ++k)
      same = close(file.vertices[file.idx[file.start[a[i]] + k]], as.vertices[as.idx[as.start[b[i]] + k]]);
    if (!same) fail(path, "malformed file: polygon " + std::to_string(i) + " reads differently in Assimp");
  }
}

// Replaces Assimp's coordinates by the exactly parsed ones, after checking them.
void take_coordinates(const std::string& path, Polys& as, const std::vector<Vec3>& exact) {
  if (exact.size() != as.vertices.size())
    fail(path, "malformed file: Assimp read " + std::to_string(as.vertices.size()) + " vertices where the text has " +
                   std::to_string(exact.size()));
  for (size_t i = 0; i < exact.size(); ++i) {
    if (!close(exact[i], as.vertices[i])) fail(path, "malformed file: vertex " + std::to_string(i) + " reads differently in Assimp");
    as.vertices[i] = exact[i];
  }
}

// An empty file or one with only points/lines gets its own message.
void check_polygons(const std::string& path, const Polys& p) {
  for (size_t f = 0; f < p.faces(); ++f)
    if (p.corners(f) >= 3) return;
  fail(path, p.faces() ? "the file has only points or lines, no triangles" : "empty mesh: the file has no faces");
}

}  // namespace

Mesh read_mesh(const std::string& path) {
  // A directory or /dev/zero is named as such whatever its name ends in.
  require_regular_file(path);
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower((unsigned char)c));
  if (ext != ".off" && ext != ".obj" && ext != ".ply" && ext != ".stl")
    fail(path, "unknown format '" + ext + "' (expected .off, .obj, .ply or .stl)");
  const std::vector<uint8_t> bytes = read_file(path);
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());

  Polys result;
  if (ext == ".off" || ext == ".obj") {
    // Scan first: its messages (with line numbers) are clearer than Assimp's.
    result = ext == ".off" ? scan_off(path, text) : scan_obj(path, text);
    check_polygons(path, result);
    cross_check(path, result, read_assimp(path));
  } else {
    if (ext == ".ply") check_ply_layout(path, text);
    const bool binary_stl = ext == ".stl" && check_stl_layout(path, text);
    Polys as = read_assimp(path);
    if (ext == ".ply" && text.find("format ascii") < text.find("end_header")) {
      if (auto v = scan_ply_ascii(path, text)) take_coordinates(path, as, *v);
    } else if (ext == ".stl" && !binary_stl) {
      take_coordinates(path, as, scan_stl_ascii(path, text));
    }
    result = std::move(as);
  }

  check_polygons(path, result);
  Mesh mesh;
  mesh.vertices = std::move(result.vertices);
  for (size_t f = 0; f < result.faces(); ++f) {  // fan (v0, vi, vi+1), in file order
    const uint32_t* c = result.idx.data() + result.start[f];
    for (size_t k = 1; k + 1 < result.corners(f); ++k) mesh.triangles.push_back({c[0], c[k], c[k + 1]});
  }
  check_mesh(mesh, path);
  return mesh;
}

}  // namespace meshcast
