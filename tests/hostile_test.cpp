// Hostile input: what an adversarial run found, one test per
// defect, each on files the test makes itself. The wrong answers at large
// coordinates are probed on every layout and every Vulkan method by the
// stiff suite (robustness_test.cpp: ExtremeMagnitudesAndDirectionLengths,
// LargeCoordinatesHitTheNearTriangle); the command line's side (exit codes,
// --json, --out /dev/full, a write cut short, links, --device, --count,
// NaN limits, layout options with a blob) by cli_test.sh.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "check/ray_files.h"
#include "check/generate.h"
#include "meshcast/read.h"
#include "layout/blob_format.h"
#include "layout/tree/octtree.h"
#include "tests/testing.h"

namespace fs = std::filesystem;

namespace meshcast::testing {
namespace {

const char* kSquare = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

// 2. A `tristrips` element: Assimp kept 1 of the 2 triangles of a strip (1 of
// 4 with a restart); refused, naming the file and the element.
TEST(Hostile, PlyTriangleStripsAreRefused) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  const std::string path = make_file("strip.ply", header + kSquare + "4 0 1 3 2\n");
  expect_throws<InputError>([&] { read_mesh(path); }, {"strip.ply", "tristrips"});
  const std::string restart = make_file("restart.ply", header + kSquare + "7 0 1 3 -1 1 2 3\n");
  expect_throws<InputError>([&] { read_mesh(restart); }, {"restart.ply", "tristrips"});
}

// An element named with leading digits made Assimp ask for 64 GB (the mesh
// fuzzer's find; ASan aborts there, a plain build got std::bad_alloc or,
// with memory to overcommit, worse): refused before Assimp reads the file,
// naming the file and the name. Property names likewise.
TEST(Hostile, PlyNamesMustBeWords) {
  const std::string vertex = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string element = make_file(
      "digits_element.ply", vertex + "element 666666666666face 1\nproperty list uchar int vertex_indices\nend_header\n" + body);
  expect_throws<InputError>([&] { read_mesh(element); }, {"digits_element.ply", "666666666666face", "not a word"});
  const std::string property = make_file(
      "digits_property.ply", vertex + "element face 1\nproperty list uchar int 9vertex_indices\nend_header\n" + body);
  expect_throws<InputError>([&] { read_mesh(property); }, {"digits_property.ply", "9vertex_indices", "not a word"});
}

// 2. A vertex element without z was read with z = 0; refused, naming the
// property (and x, y likewise).
TEST(Hostile, PlyVertexWithoutACoordinateIsRefused) {
  for (const char* missing : {"x", "y", "z"}) {
    std::string props;
    for (const char* axis : {"x", "y", "z"})
      if (std::strcmp(axis, missing) != 0) props += std::string("property float ") + axis + "\n";
    const std::string path = make_file(std::string("no_") + missing + ".ply",
                                       "ply\nformat ascii 1.0\nelement vertex 3\n" + props +
                                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                           "0 0\n1 0\n0 1\n3 0 1 2\n");
    expect_throws<InputError>([&] { read_mesh(path); }, {path, std::string("no '") + missing + "' property"});
  }
}

// 3. A denormal coordinate (7.5e-43, as a script writes a sphere of radius
// 1e-10) was refused as "reads differently in Assimp"; the exact value is read.
TEST(Hostile, PlyDenormalCoordinatesReadExactly) {
  const std::string path =
      make_file("denormal.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                "7.5e-43 0 0\n1e-10 -3e-44 0\n0 1e-10 1.4e-45\n3 0 1 2\n");
  const Mesh m = read_mesh(path);
  ASSERT_EQ(m.vertices.size(), 3u);
  EXPECT_EQ(m.vertices[0].x, 7.5e-43f);
  EXPECT_EQ(m.vertices[1].y, -3e-44f);
  EXPECT_EQ(m.vertices[2].z, 1.4e-45f);
  EXPECT_EQ(m.triangles.size(), 1u);
}

// 3. ZeroByteHybrid refused a 6,400-triangle sphere of radius 1e-30 as deeper
// than 64 levels (float SAH areas underflowed to 0, so every split cost the
// same); it builds, and answers as the oracle does, as every layout must.
TEST(Hostile, TinySphereBuildsInEveryLayout) {
  const Mesh s = make_sphere(41, 80, 1e-30f, {0, 0, 0});
  ASSERT_GE(s.triangles.size(), 6400u);
  const std::vector<Ray> rays = make_rays(s, RayKind::Long, 300, 3);
  for (const std::string& layout : layout_names()) {
    const std::vector<uint8_t> blob = build_blob(s, parse_layout(layout), "sphere of radius 1e-30");
    expect_oracle(s, blob, rays, trace_all(blob, rays), layout);
    EXPECT_LE(layout::header_of(blob.data()).max_depth, 40u) << layout;
  }
}

// 4. Output to a full disk exited 0 with nothing written: every write is
// checked. /dev/full is written in place (renaming over a device would
// replace it) and fails with the path and the reason.
TEST(Hostile, WritesToAFullDeviceFail) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this machine";
  const std::vector<Ray> rays(3, Ray{{0, 0, 0}, {0, 0, 1}, INFINITY});
  expect_throws<OutputError>([&] { write_rays("/dev/full", rays); }, {"/dev/full", "No space left"});
  expect_throws<OutputError>([&] { write_hits("/dev/full", std::vector<Hit>(5)); }, {"/dev/full", "No space left"});
  expect_throws<OutputError>([&] { write_file("/dev/full", "x", 1); }, {"/dev/full", "No space left"});
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

// 4. A regular file is written beside its name and renamed: a write that
// fails (here the file-size limit, as a full disk would) leaves the old file
// whole and no partial file behind.
TEST(Hostile, AFailedWriteLeavesNoPartialFile) {
  const fs::path dir = scratch_dir() / "aside";
  fs::create_directories(dir);
  const std::string path = (dir / "m.blob").string();
  write_file(path, "old", 3);
  const std::vector<uint8_t> big(1 << 16, 7);
  struct rlimit before;
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  struct rlimit small = before;
  small.rlim_cur = 4096;
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // the write then fails with EFBIG
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  expect_throws<OutputError>([&] { write_file(path, big.data(), big.size()); }, {path, "write"});
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &before), 0);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(read_file(path), std::vector<uint8_t>({'o', 'l', 'd'}));
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1u) << "a partial file was left beside " << path;
  write_file(path, big.data(), big.size());
  EXPECT_EQ(read_file(path), big);
}

// 5. A directory ended in std::bad_alloc, /dev/zero was read until memory ran
// out: both are refused before any read, naming the path.
TEST(Hostile, DirectoriesAndDevicesAreRefusedBeforeReading) {
  const std::string dir = scratch_dir().string();
  expect_throws<InputError>([&] { read_file(dir); }, {dir, "is a directory"});
  expect_throws<InputError>([&] { read_rays(dir); }, {dir, "is a directory"});
  expect_throws<InputError>([&] { read_mesh(dir); }, {dir, "is a directory"});
  const std::string off_dir = (scratch_dir() / "mesh.off").string();
  fs::create_directories(off_dir);
  expect_throws<InputError>([&] { read_mesh(off_dir); }, {off_dir, "is a directory"});
  if (fs::exists("/dev/zero")) {
    expect_throws<InputError>([&] { read_mesh("/dev/zero"); }, {"/dev/zero", "not a regular file"});
    expect_throws<InputError>([&] { read_file("/dev/zero"); }, {"/dev/zero", "not a regular file"});
  }
}

// A blob must start at a 4-byte aligned address (blob.h): one copied to an
// odd offset inside a buffer of one's own (a pack file) is refused with an
// InputError naming its address and how far off it is, never read
// misaligned; at a multiple of 4 in the same buffer it is walked.
// A tree whose boxes miss their triangles would hide hits (each walk culls
// the subtree, and answers by the order it takes): a blob resealed after
// a node's box was narrowed is refused, naming the leaf and the box. The
// fuzz corpus holds a blob found so (tree_boxes_miss_their_triangles.mcb).
TEST(Hostile, ATreeWhoseBoxesMissTheirTrianglesIsRefused) {
  const Mesh sphere = make_sphere(12, 24, 1.0f, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(sphere, parse_layout("OctTreeCompressed/ClusterBitPackSOA8"), "sphere");
  const layout::BlobHeader& h = layout::header_of(blob.data());
  ASSERT_EQ(layout::oct_count(h.root), 0u) << "the root is a node";
  uint8_t* node = blob.data() + h.tree_offset + layout::oct_offset(h.root);
  int child = 0;
  while (child < 8 && !layout::oct_child_properties(node, child)) ++child;
  ASSERT_LT(child, 8);
  // The child's box flat at its lowest z: its triangles rise above it.
  node[MC_OCT_QHI_AT + 16 + child] = node[MC_OCT_QLO_AT + 16 + child];
  layout::seal(blob);
  expect_throws<InputError>([&] { BlobView view(blob, "narrowed.mcb"); }, {"narrowed.mcb", "does not bound its triangles", "axis 2"});
}

TEST(Hostile, AMisalignedBlobIsRefusedNamingItsAddress) {
  const Mesh m = make_sphere(8, 16, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(m, parse_layout("AABBTree/Float3"), "sphere");
  std::vector<uint32_t> words(blob.size() / 4 + 2);  // 4-byte aligned storage
  uint8_t* const base = reinterpret_cast<uint8_t*>(words.data());
  for (size_t offset : {1, 2, 3}) {
    std::copy(blob.begin(), blob.end(), base + offset);
    const std::span<const uint8_t> bytes(base + offset, blob.size());
    char address[32];
    std::snprintf(address, sizeof address, "0x%jx", uintmax_t(reinterpret_cast<uintptr_t>(bytes.data())));
    expect_throws<InputError>([&] { BlobView(bytes, "pack.dat at " + std::to_string(offset)); },
                              {"pack.dat at " + std::to_string(offset), std::string("blob bytes at ") + address,
                               "not 4-byte aligned (address % 4 = " + std::to_string(offset) + ")"});
  }
  std::copy(blob.begin(), blob.end(), base + 4);
  const BlobView view(std::span<const uint8_t>(base + 4, blob.size()), "pack.dat at 4");
  const std::vector<Ray> rays = make_rays(m, RayKind::Long, 100, 1);
  EXPECT_EQ(trace_all(view, rays).size(), rays.size());
  expect_oracle(m, blob, rays, trace_all(view, rays), "the blob at offset 4");
}

// Found by the mesh fuzzer: Assimp reads an OBJ face's texture and normal
// indices without a range check, and reads any line starting with 'f' as a
// face; out-of-range references and look-alike statements are refused first.
TEST(Hostile, ObjReferencesOutOfRangeAndLookAlikeStatementsAreRefused) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
  expect_throws<InputError>([&] { read_mesh(make_file("vt.obj", v + "f 1/2 2/1 3/1\n")); },
                            {"vt.obj", "texture coordinate index 2", "out of range"});
  expect_throws<InputError>([&] { read_mesh(make_file("vn.obj", v + "f 1//1 2//1 3//5\n")); },
                            {"vn.obj", "normal index 5"});
  expect_throws<InputError>([&] { read_mesh(make_file("f12.obj", v + "f 1 2 3\nf12 2/4/ 3/3\n")); },
                            {"f12.obj", "line 7", "unknown statement 'f12'"});
  expect_throws<InputError>([&] { read_mesh(make_file("rel.obj", v + "f 1/-2 2 3\n")); },
                            {"rel.obj", "texture coordinate index -2"});
  // Every reference in range, relative ones too, reads as before.
  const Mesh m = read_mesh(make_file("ok.obj", v + "vp 0.5\nf 1/1/1 2/-1/1 -1//-1\n"));
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0], (Triangle{0, 1, 2}));
}

// 5. A truncated binary STL got Assimp's "Failed to determine STL storage
// representation"; the message now gives the facet count and both sizes.
TEST(Hostile, TruncatedBinaryStlSaysSo) {
  std::string stl(80, ' ');
  const uint32_t facets = 2;
  stl.append(reinterpret_cast<const char*>(&facets), 4);
  stl.append(50 + 20, '\0');  // one whole facet and part of the second
  const std::string path = make_file("cut.stl", stl);
  expect_throws<InputError>([&] { read_mesh(path); }, {"cut.stl", "truncated", "2 facets", "184 bytes", "154 bytes"});
  const std::string tiny = make_file("tiny.stl", "abc");
  expect_throws<InputError>([&] { read_mesh(tiny); }, {"tiny.stl", "3 bytes"});
}

}  // namespace
}  // namespace meshcast::testing

// Every-hit files (Query::All's answers): HITC written and read back
// record for record, its size following the kept hits; the fixed HITN rows
// of earlier files read into the same compact rows; a bad magic, a row
// width outside 1..kMaxHitsLimit and a size that is not the header's (or
// the counts') are refused with the file's name; rows that do not keep
// min(found, max_hits) records are not written.
namespace meshcast::testing {
namespace {

std::string u32_bytes(std::initializer_list<uint32_t> words) {
  std::string out(4 * words.size(), '\0');
  std::memcpy(out.data(), std::data(words), out.size());
  return out;
}

std::string record_bytes(float t, uint32_t triangle) {
  std::string out(8, '\0');
  std::memcpy(out.data(), &t, 4), std::memcpy(out.data() + 4, &triangle, 4);
  return out;
}

TEST(Hostile, HitListFilesRoundTripAndRefuseBadHeaders) {
  HitLists lists;
  lists.max_hits = 3;
  lists.add_row(0, {});
  const Hit two[] = {{1.5f, 7}, {2.5f, 3}}, three[] = {{0.5f, 1}, {0.75f, 2}, {1.0f, 9}};
  lists.add_row(2, two);
  lists.add_row(5, three);  // 5 found, the nearest 3 kept
  const std::string path = (scratch_dir() / "lists.hitc").string();
  write_hit_lists(path, lists);
  const HitLists back = read_hit_lists(path);
  ASSERT_EQ(back.max_hits, 3u);
  EXPECT_EQ(back.found, lists.found);
  EXPECT_EQ(back.offsets, (std::vector<size_t>{0, 0, 2, 5}));
  ASSERT_EQ(back.hits.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(back.hits[i].t, lists.hits[i].t) << i;
    EXPECT_EQ(back.hits[i].triangle, lists.hits[i].triangle) << i;
  }
  const std::vector<uint8_t> raw = read_file(path);
  std::string bytes(raw.begin(), raw.end());
  EXPECT_EQ(bytes.substr(0, 4), "HITC");
  EXPECT_EQ(bytes.size(), 12u + 3 * 4 + 5 * 8);  // the kept hits alone
  const std::string truncated = make_file("short.hitc", bytes.substr(0, bytes.size() - 1));
  expect_throws<InputError>([&] { read_hit_lists(truncated); }, {"short.hitc", "3 rays keeping 5 hits"});
  const std::string counts_cut = make_file("counts.hitc", bytes.substr(0, 14));
  expect_throws<InputError>([&] { read_hit_lists(counts_cut); }, {"counts.hitc", "counts alone take 24 bytes"});
  std::string wide = bytes;
  const uint32_t width = kMaxHitsLimit + 1;
  std::memcpy(wide.data() + 8, &width, 4);
  const std::string too_wide = make_file("wide.hitc", wide);
  expect_throws<InputError>([&] { read_hit_lists(too_wide); }, {"wide.hitc", "records a ray"});
  const std::string hits_file = make_file("plain.hitc", "HITS" + bytes.substr(4));
  expect_throws<InputError>([&] { read_hit_lists(hits_file); }, {"plain.hitc", "not a HITC file", "but a HITS file"});

  // The fixed rows: two rays of 2 records, the unused one a miss.
  const std::string fixed = "HITN" + u32_bytes({2, 2}) + u32_bytes({1}) + record_bytes(4.0f, 11) +
                            record_bytes(INFINITY, MC_NO_HIT) + u32_bytes({3}) + record_bytes(0.25f, 5) +
                            record_bytes(0.5f, 6);
  const HitLists old = read_hit_lists(make_file("old.hitn", fixed));
  EXPECT_EQ(old.found, (std::vector<uint32_t>{1, 3}));
  EXPECT_EQ(old.offsets, (std::vector<size_t>{0, 1, 3}));
  ASSERT_EQ(old.hits.size(), 3u);
  EXPECT_EQ(old.row(0)[0].triangle, 11u);
  EXPECT_EQ(old.row(1)[1].t, 0.5f);
  const std::string short_fixed = make_file("short.hitn", fixed.substr(0, fixed.size() - 1));
  expect_throws<InputError>([&] { read_hit_lists(short_fixed); }, {"short.hitn", "header says 2 rays of 2 records"});

  HitLists uneven = lists;
  uneven.found[1] = 1;  // a row of 2 for 1 hit found
  expect_throws<UsageError>([&] { write_hit_lists((scratch_dir() / "uneven.hitc").string(), uneven); },
                            {"ray 1 found 1 hits but its row keeps 2"});
}

}  // namespace
}  // namespace meshcast::testing

// Scenes' files (RAYD rays with double origins, HITI hits naming the
// instance): written and read back exactly, doubles whole; a truncated
// file and a bad magic refused with the file's name.
namespace meshcast::testing {
namespace {
TEST(Hostile, SceneRayAndHitFilesRoundTripAndRefuseBadHeaders) {
  const std::vector<RayD> rays = {{{1e7 + 0.125, -3.5e6, 0.1}, {0, -1, 0.5f}, INFINITY},
                                  {{-2.0, 1e15, 7.0}, {1, 2, 3}, 4.5f}};
  const std::string rays_path = (scratch_dir() / "level.rayd").string();
  write_scene_rays(rays_path, rays);
  EXPECT_TRUE(is_scene_rays_file(rays_path));
  const std::vector<RayD> rays_back = read_scene_rays(rays_path);
  ASSERT_EQ(rays_back.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    for (int a = 0; a < 3; ++a) EXPECT_EQ(rays_back[i].org[a], rays[i].org[a]) << i;  // every bit of the double
    for (int a = 0; a < 3; ++a) EXPECT_EQ(rays_back[i].dir[a], rays[i].dir[a]) << i;
    EXPECT_EQ(rays_back[i].tmax, rays[i].tmax) << i;
  }
  const std::vector<uint8_t> raw = read_file(rays_path);
  EXPECT_EQ(raw.size(), 8u + 2 * 40);
  // The files hold no t_min: rays read start at 0, and a ray with another
  // is refused rather than written without it (RAYS alike).
  for (const RayD& r : rays_back) EXPECT_EQ(r.tmin, 0.0f);
  RayD offset = rays[1];
  offset.tmin = 0.25f;
  expect_throws<UsageError>([&] { write_scene_rays(rays_path, {rays[0], offset}); },
                            {"level.rayd", "ray 1 has t_min 0.25", "does not hold"});
  const std::string float_path = (scratch_dir() / "level.rays").string();
  write_rays(float_path, {{{1, 2, 3}, {0, 0, -1}, 9.0f}});
  EXPECT_EQ(read_file(float_path).size(), 8u + 28);
  EXPECT_EQ(read_rays(float_path).at(0).tmin, 0.0f);
  expect_throws<UsageError>([&] { write_rays(float_path, {{{1, 2, 3}, {0, 0, -1}, 9.0f, 1.5f}}); },
                            {"level.rays", "ray 0 has t_min 1.5", "does not hold"});
  EXPECT_EQ(read_rays(float_path).size(), 1u);  // the refused write left the file as it was
  const std::string cut = make_file("cut.rayd", std::string(raw.begin(), raw.end() - 1));
  expect_throws<InputError>([&] { read_scene_rays(cut); }, {"cut.rayd", "header says 2 records"});
  const std::string plain = make_file("plain.rayd", "RAYS" + std::string(raw.begin() + 4, raw.end()));
  expect_throws<InputError>([&] { read_scene_rays(plain); }, {"plain.rayd", "not a RAYD file", "but a RAYS file"});
  EXPECT_FALSE(is_scene_rays_file(plain));

  const std::string empty = make_file("empty.rayd", "");
  EXPECT_TRUE(is_scene_rays_file(empty));  // by its name: too short to tell by its bytes
  expect_throws<InputError>([&] { read_scene_rays(empty); }, {"empty.rayd", "0 bytes, shorter than a RAYD file's"});

  const std::vector<SceneHit> hits = {{2.5f, 7, 11}, {}};
  const std::string hits_path = (scratch_dir() / "level.hiti").string();
  write_scene_hits(hits_path, hits);
  const std::vector<SceneHit> hits_back = read_scene_hits(hits_path);
  ASSERT_EQ(hits_back.size(), 2u);
  EXPECT_EQ(hits_back[0].t, 2.5f);
  EXPECT_EQ(hits_back[0].instance, 7u);
  EXPECT_EQ(hits_back[0].triangle, 11u);
  EXPECT_EQ(hits_back[1].t, INFINITY);
  EXPECT_EQ(hits_back[1].instance, kNoHit);
  EXPECT_EQ(hits_back[1].triangle, kNoHit);
  const std::vector<uint8_t> hit_bytes = read_file(hits_path);
  EXPECT_EQ(hit_bytes.size(), 8u + 2 * 12);
  const std::string short_hits = make_file("short.hiti", std::string(hit_bytes.begin(), hit_bytes.end() - 4));
  expect_throws<InputError>([&] { read_scene_hits(short_hits); }, {"short.hiti", "header says 2 records"});
}

// A rays file is made and written a chunk at a time (meshcast rays
// --count 2^27 held 3.5 GiB of rays and a copy of them as bytes): the
// chunks are the rays make_rays gives at once, bit for bit, whatever the
// chunks' sizes, and a file of more than one chunk reads back as them.
TEST(Hostile, RaysFilesAreMadeAChunkAtATime) {
  const Mesh mesh = make_sphere(8, 16, 1.0f, {0, 0, 0});
  constexpr size_t kCount = 70000;  // past the writer's chunk of 2^16
  for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial}) {
    const std::vector<Ray> whole = make_rays(mesh, kind, kCount, 9);
    std::vector<Ray> pieces(kCount);
    RaySource source(mesh, kind, 9);
    for (size_t at = 0, step = 1; at < kCount; at += step, step = step * 3 + 1)
      source.fill(std::span(pieces).subspan(at, std::min(step, kCount - at)));
    EXPECT_EQ(std::memcmp(pieces.data(), whole.data(), kCount * sizeof(Ray)), 0) << int(kind);
    const std::string path = (scratch_dir() / "chunks.rays").string();
    RaySource streamed(mesh, kind, 9);
    write_rays(path, kCount, [&](std::span<Ray> rays) { streamed.fill(rays); });
    const std::vector<Ray> back = read_rays(path);
    ASSERT_EQ(back.size(), kCount);
    EXPECT_EQ(std::memcmp(back.data(), whole.data(), kCount * sizeof(Ray)), 0) << int(kind);
  }
  expect_throws<InputError>([&] { write_rays("/dev/null", kMaxRayCount + 1, [](std::span<Ray>) {}); },
                            {"/dev/null", "more than a RAYS file may hold"});
  // And they are the rays the one-piece generator made before (the FNV-1a
  // hashes of 70,000 rays of each kind, seed 9, around a tetrahedron, as
  // make_rays gave them before it was built on RaySource, compiled with the
  // project's flags: gcc 12's SLP vectorizer, which they turn off, skips
  // a rounding to float in the long rays): ray files made since read as
  // those made before.
  Mesh tetrahedron;
  tetrahedron.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0.5f, 0.5f, 1.5f}};
  tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  const std::pair<RayKind, uint64_t> before[] = {
      {RayKind::Long, 0xd4f089d4b21ae798ull}, {RayKind::Probe, 0xa5206af3bc4fe7c4ull}, {RayKind::Radial, 0xbc5784949feab900ull}};
  for (const auto& [kind, hash] : before) {
    std::vector<Ray> rays(kCount);
    RaySource source(tetrahedron, kind, 9);
    for (size_t at = 0; at < kCount; at += 4096) source.fill(std::span(rays).subspan(at, std::min<size_t>(4096, kCount - at)));
    // Over each ray's record, its 7 floats before t_min (what the hashes
    // were taken over when a Ray was those 7 floats).
    uint64_t h = 0xcbf29ce484222325ull;
    for (const Ray& r : rays) {
      const auto* bytes = reinterpret_cast<const unsigned char*>(&r);
      for (size_t i = 0; i < offsetof(Ray, tmin); ++i) h = (h ^ bytes[i]) * 0x100000001b3ull;
    }
    EXPECT_EQ(h, hash) << int(kind);
  }
}
}  // namespace
}  // namespace meshcast::testing
