#include "check/ray_files.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "layout/message_text.h"

namespace meshcast {

namespace {

// A file of records: a 4-byte magic, a uint32 count, then the records
// (their bytes as they lie in memory: every format here is little-endian).
static_assert(std::endian::native == std::endian::little, "the files' records are their structs' bytes");

// What each file of ray_files.h holds, for a message that names what was
// given where another was expected.
const char* file_kind(const std::string& magic) {
  if (magic == "RAYS") return "rays with float origins";
  if (magic == "RAYD") return "rays with double origins, read by scenes";
  if (magic == "HITS") return "a mesh's closest or any hits";
  if (magic == "HITN") return "a mesh's every hit, in rows of N records";
  if (magic == "HITC") return "a mesh's every hit, the rows compact";
  if (magic == "HITI") return "a scene's hits";
  return nullptr;
}

// InputError unless the file's first bytes are `magic` and its header
// (`header` bytes, the magic's 4 included) is whole.
void check_magic(const std::string& path, const std::vector<uint8_t>& b, const char magic[4], size_t header) {
  const std::string expected(magic, 4);
  if (b.size() < header)
    throw InputError(path + ": " + std::to_string(b.size()) + " bytes, shorter than a " + expected + " file's " +
                     std::to_string(header) + "-byte header (" + file_kind(expected) + ")");
  const std::string found(reinterpret_cast<const char*>(b.data()), 4);
  if (found == expected) return;
  if (const char* kind = file_kind(found))
    throw InputError(path + ": not a " + expected + " file (" + file_kind(expected) + ") but a " + found + " file (" +
                     kind + ")");
  throw InputError(path + ": not a " + expected + " file (" + file_kind(expected) + "): its first 4 bytes are not \"" +
                   expected + "\"");
}

template <class Record>
std::vector<Record> read_records(const std::string& path, const char magic[4]) {
  constexpr size_t record_bytes = sizeof(Record);
  std::vector<uint8_t> b = read_file(path);
  check_magic(path, b, magic, 8);
  uint32_t n;
  std::memcpy(&n, b.data() + 4, 4);
  if (b.size() != 8 + uint64_t(n) * record_bytes)
    throw InputError(path + ": header says " + std::to_string(n) + " records (" +
                     std::to_string(8 + uint64_t(n) * record_bytes) + " bytes) but the file has " +
                     std::to_string(b.size()) + " bytes");
  std::vector<Record> out(n);
  for (uint32_t i = 0; i < n; ++i) std::memcpy(&out[i], b.data() + 8 + size_t(i) * record_bytes, record_bytes);
  return out;
}

// Each item written as to_record(item, its index); at most kMaxRayCount (a
// ray file and its hits file hold one record a ray).
template <class Record, class Item, class ToRecord>
void write_records(const std::string& path, const char magic[4], const std::vector<Item>& items, ToRecord to_record) {
  if (items.size() > kMaxRayCount)
    throw InputError(path + ": " + std::to_string(items.size()) + " records, more than a " + std::string(magic, 4) +
                     " file may hold (" + std::to_string(kMaxRayCount) + ")");
  std::vector<uint8_t> b(8 + items.size() * sizeof(Record));
  const uint32_t n = uint32_t(items.size());
  std::memcpy(b.data(), magic, 4), std::memcpy(b.data() + 4, &n, 4);
  for (size_t i = 0; i < items.size(); ++i) {
    const Record r = to_record(items[i], i);
    std::memcpy(b.data() + 8 + i * sizeof(Record), &r, sizeof(Record));
  }
  write_file(path, b.data(), b.size());
}

// The ray records of RAYS and RAYD files: a Ray's and a RayD's fields up to
// tmax. The files have no t_min: a ray read has t_min 0 (a caller that
// wants another sets it, as `meshcast trace --t-min` does), and a ray with
// another t_min is refused by the writers rather than written without it.
// These four functions are the one place a ray and its record meet.
struct RayRecord {
  float org[3], dir[3], tmax;
};
struct RayDRecord {
  double org[3];
  float dir[3], tmax;
};

Ray ray_of(const RayRecord& r) { return {{r.org[0], r.org[1], r.org[2]}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax}; }
RayD ray_of(const RayDRecord& r) { return {{r.org[0], r.org[1], r.org[2]}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax}; }

// `path`'s record of ray `i`; UsageError for a t_min the file cannot hold.
template <class Record, class R>
Record record_of(const std::string& path, const R& r, size_t i) {
  if (r.tmin != 0)
    throw UsageError(path + ": ray " + std::to_string(i) + " has t_min " + number_text(r.tmin) +
                     ", which a rays file does not hold (its rays start at t_min 0)");
  return {{r.org[0], r.org[1], r.org[2]}, {r.dir[0], r.dir[1], r.dir[2]}, r.tmax};
}

struct HitRecord {
  float t;
  uint32_t triangle;
};

struct SceneHitRecord {
  float t;
  uint32_t instance, triangle;
};

}  // namespace

static_assert(sizeof(RayRecord) == 28 && sizeof(RayDRecord) == 40 && sizeof(HitRecord) == 8 &&
                  sizeof(SceneHitRecord) == 12,
              "the records of README's file formats");

std::vector<Ray> read_rays(const std::string& path) {
  const std::vector<RayRecord> records = read_records<RayRecord>(path, "RAYS");
  std::vector<Ray> rays(records.size());
  for (size_t i = 0; i < records.size(); ++i) rays[i] = ray_of(records[i]);
  return rays;
}

void write_rays(const std::string& path, const std::vector<Ray>& rays) {
  write_records<RayRecord>(path, "RAYS", rays, [&](const Ray& r, size_t i) { return record_of<RayRecord>(path, r, i); });
}

void write_rays(const std::string& path, size_t count, const std::function<void(std::span<Ray>)>& make) {
  if (count > kMaxRayCount)
    throw InputError(path + ": " + std::to_string(count) + " rays, more than a RAYS file may hold (" +
                     std::to_string(kMaxRayCount) + ")");
  char header[8] = {'R', 'A', 'Y', 'S'};
  const uint32_t n = uint32_t(count);
  std::memcpy(header + 4, &n, 4);
  constexpr size_t kChunk = size_t(1) << 16;  // 1.75 MiB of records at a time
  std::vector<Ray> chunk;
  std::vector<RayRecord> records;
  size_t written = 0;
  bool header_written = false;
  write_file_pieces(path, [&]() -> Bytes {
    if (!header_written) return header_written = true, Bytes{header, sizeof header};
    chunk.assign(std::min(kChunk, count - written), Ray{});
    make(chunk);
    records.resize(chunk.size());
    for (size_t i = 0; i < chunk.size(); ++i) records[i] = record_of<RayRecord>(path, chunk[i], written + i);
    written += chunk.size();
    return {records.data(), records.size() * sizeof(RayRecord)};
  });
}

std::vector<Hit> read_hits(const std::string& path) {
  std::vector<Hit> hits;
  for (const HitRecord& r : read_records<HitRecord>(path, "HITS")) hits.push_back({r.t, r.triangle});
  return hits;
}

void write_hits(const std::string& path, const std::vector<Hit>& hits) {
  write_records<HitRecord>(path, "HITS", hits, [](const Hit& h, size_t) { return HitRecord{h.t, h.triangle}; });
}

namespace {

// `count` (t, triangle) records at `p` as the next ray's row, `found` hits
// found in all.
void add_record_row(HitLists& lists, const uint8_t* p, size_t count, uint32_t found) {
  for (size_t k = 0; k < count; ++k) {
    HitRecord r;
    std::memcpy(&r, p + 8 * k, 8);
    lists.hits.push_back({r.t, r.triangle});
  }
  lists.end_row(found);
}

// HITC: the counts, then each ray's kept records one after the other.
HitLists read_compact_rows(const std::string& path, const std::vector<uint8_t>& b, uint32_t n, uint32_t width) {
  if (b.size() < 12 + 4 * uint64_t(n))
    throw InputError(path + ": header says " + std::to_string(n) + " rays, whose counts alone take " +
                     std::to_string(12 + 4 * uint64_t(n)) + " bytes, but the file has " + std::to_string(b.size()) +
                     " bytes");
  std::vector<uint32_t> found(n);
  std::memcpy(found.data(), b.data() + 12, 4 * size_t(n));
  uint64_t kept = 0;
  for (uint32_t f : found) kept += std::min(f, width);
  if (b.size() != 12 + 4 * uint64_t(n) + 8 * kept)
    throw InputError(path + ": header and counts say " + std::to_string(n) + " rays keeping " + std::to_string(kept) +
                     " hits (" + std::to_string(12 + 4 * uint64_t(n) + 8 * kept) + " bytes) but the file has " +
                     std::to_string(b.size()) + " bytes");
  HitLists lists;
  lists.max_hits = width;
  lists.hits.reserve(kept);
  const uint8_t* p = b.data() + 12 + 4 * size_t(n);
  for (uint32_t f : found) {
    const size_t count = std::min(f, width);
    add_record_row(lists, p, count, f);
    p += 8 * count;
  }
  return lists;
}

// HITN: a fixed row of `width` records a ray, after its count; the kept
// ones are read.
HitLists read_fixed_rows(const std::string& path, const std::vector<uint8_t>& b, uint32_t n, uint32_t width) {
  const uint64_t row = 4 + 8 * uint64_t(width);
  if (b.size() != 12 + n * row)
    throw InputError(path + ": header says " + std::to_string(n) + " rays of " + std::to_string(width) + " records (" +
                     std::to_string(12 + n * row) + " bytes) but the file has " + std::to_string(b.size()) + " bytes");
  HitLists lists;
  lists.max_hits = width;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = b.data() + 12 + i * row;
    uint32_t found;
    std::memcpy(&found, p, 4);
    add_record_row(lists, p + 4, std::min(found, width), found);
  }
  return lists;
}

}  // namespace

HitLists read_hit_lists(const std::string& path) {
  std::vector<uint8_t> b = read_file(path);
  const bool compact = b.size() >= 4 && std::memcmp(b.data(), "HITC", 4) == 0;
  // Named HITC unless it is a HITN file: HITC is what meshcast writes.
  const bool fixed = b.size() >= 4 && std::memcmp(b.data(), "HITN", 4) == 0;
  check_magic(path, b, fixed ? "HITN" : "HITC", 12);
  uint32_t n, width;
  std::memcpy(&n, b.data() + 4, 4), std::memcpy(&width, b.data() + 8, 4);
  if (width < 1 || width > kMaxHitsLimit)
    throw InputError(path + ": " + std::to_string(width) + " records a ray, not in 1.." + std::to_string(kMaxHitsLimit));
  return compact ? read_compact_rows(path, b, n, width) : read_fixed_rows(path, b, n, width);
}

void write_hit_lists(const std::string& path, const HitLists& lists) {
  const size_t n = lists.rays();
  if (n > kMaxRayCount)
    throw InputError(path + ": " + std::to_string(n) + " rays, more than a HITC file may hold (" +
                     std::to_string(kMaxRayCount) + ")");
  // The file is read back by the counts alone: every row must keep
  // exactly min(found, N) records.
  if (lists.offsets.size() != n + 1 || lists.offsets.back() != lists.hits.size())
    throw UsageError(path + ": the rows' offsets do not cover their " + std::to_string(n) + " rays and " +
                     std::to_string(lists.hits.size()) + " hits");
  for (size_t i = 0; i < n; ++i)
    if (lists.row(i).size() != std::min(lists.found[i], lists.max_hits))
      throw UsageError(path + ": ray " + std::to_string(i) + " found " + std::to_string(lists.found[i]) +
                       " hits but its row keeps " + std::to_string(lists.row(i).size()) + " of at most " +
                       std::to_string(lists.max_hits));
  std::vector<HitRecord> records(lists.hits.size());
  for (size_t k = 0; k < records.size(); ++k) records[k] = {lists.hits[k].t, lists.hits[k].triangle};
  uint8_t head[12];
  const uint32_t counts[2] = {uint32_t(n), lists.max_hits};
  std::memcpy(head, "HITC", 4), std::memcpy(head + 4, counts, 8);
  write_file(path, {{head, 12}, {lists.found.data(), 4 * n}, {records.data(), records.size() * sizeof(HitRecord)}});
}

std::vector<RayD> read_scene_rays(const std::string& path) {
  const std::vector<RayDRecord> records = read_records<RayDRecord>(path, "RAYD");
  std::vector<RayD> rays(records.size());
  for (size_t i = 0; i < records.size(); ++i) rays[i] = ray_of(records[i]);
  return rays;
}

void write_scene_rays(const std::string& path, const std::vector<RayD>& rays) {
  write_records<RayDRecord>(path, "RAYD", rays,
                            [&](const RayD& r, size_t i) { return record_of<RayDRecord>(path, r, i); });
}

std::vector<SceneHit> read_scene_hits(const std::string& path) {
  std::vector<SceneHit> hits;
  for (const SceneHitRecord& r : read_records<SceneHitRecord>(path, "HITI")) hits.push_back({r.t, r.instance, r.triangle});
  return hits;
}

void write_scene_hits(const std::string& path, const std::vector<SceneHit>& hits) {
  write_records<SceneHitRecord>(path, "HITI", hits,
                                [](const SceneHit& h, size_t) { return SceneHitRecord{h.t, h.instance, h.triangle}; });
}

bool is_scene_rays_file(const std::string& path) {
  char magic[4] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(magic, 4);  // unreadable: read_rays says why
  // Too short to tell by its bytes: by its name, so that an empty .rayd
  // file is refused as a short RAYD file, not as something else.
  if (in.gcount() < 4) return std::filesystem::path(path).extension() == ".rayd";
  return std::memcmp(magic, "RAYD", 4) == 0;
}

}  // namespace meshcast
