#include "check/ray_files.h"

#include <bit>
#include <cstring>
#include <fstream>

namespace meshcast {

namespace {

template <class Record>
std::vector<Record> read_records(const std::string& path, const char magic[4], size_t record_bytes) {
  std::vector<uint8_t> b = read_file(path);
  if (b.size() < 8 || std::memcmp(b.data(), magic, 4) != 0)
    throw InputError(path + ": not a " + std::string(magic, 4) + " file (bad magic or shorter than 8 bytes)");
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

struct HitRecord {
  float t;
  uint32_t triangle;
};

struct SceneHitRecord {
  float t;
  uint32_t instance, triangle;
};

}  // namespace

std::vector<Ray> read_rays(const std::string& path) { return read_records<Ray>(path, "RAYS", 28); }

void write_rays(const std::string& path, const std::vector<Ray>& rays) {
  if (rays.size() > kMaxRayCount)
    throw InputError(path + ": " + std::to_string(rays.size()) + " rays, more than a rays file may hold (" +
                     std::to_string(kMaxRayCount) + ")");
  const uint32_t n = uint32_t(rays.size());
  static_assert(sizeof(Ray) == 28 && std::endian::native == std::endian::little, "a Ray is its record");
  write_file(path, {{"RAYS", 4}, {&n, 4}, {rays.data(), rays.size() * sizeof(Ray)}});
}

std::vector<Hit> read_hits(const std::string& path) {
  std::vector<Hit> hits;
  for (const HitRecord& r : read_records<HitRecord>(path, "HITS", 8)) hits.push_back({r.t, r.triangle});
  return hits;
}

void write_hits(const std::string& path, const std::vector<Hit>& hits) {
  std::vector<uint8_t> b(8 + hits.size() * 8);
  uint32_t n = uint32_t(hits.size());
  std::memcpy(b.data(), "HITS", 4), std::memcpy(b.data() + 4, &n, 4);
  for (size_t i = 0; i < hits.size(); ++i) {
    HitRecord r{hits[i].t, hits[i].triangle};
    std::memcpy(b.data() + 8 + i * 8, &r, 8);
  }
  write_file(path, b.data(), b.size());
}

HitLists read_hit_lists(const std::string& path) {
  std::vector<uint8_t> b = read_file(path);
  if (b.size() < 12 || std::memcmp(b.data(), "HITN", 4) != 0)
    throw InputError(path + ": not a HITN file (bad magic or shorter than 12 bytes)");
  uint32_t n, width;
  std::memcpy(&n, b.data() + 4, 4), std::memcpy(&width, b.data() + 8, 4);
  if (width < 1 || width > kMaxHitsLimit)
    throw InputError(path + ": " + std::to_string(width) + " records a ray, not in 1.." + std::to_string(kMaxHitsLimit));
  const uint64_t row = 4 + 8 * uint64_t(width);
  if (b.size() != 12 + n * row)
    throw InputError(path + ": header says " + std::to_string(n) + " rays of " + std::to_string(width) + " records (" +
                     std::to_string(12 + n * row) + " bytes) but the file has " + std::to_string(b.size()) + " bytes");
  HitLists lists;
  lists.max_hits = width;
  lists.found.resize(n);
  lists.hits.resize(size_t(n) * width);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = b.data() + 12 + i * row;
    std::memcpy(&lists.found[i], p, 4);
    for (size_t k = 0; k < width; ++k) {
      HitRecord r;
      std::memcpy(&r, p + 4 + 8 * k, 8);
      lists.hits[i * width + k] = {r.t, r.triangle};
    }
  }
  return lists;
}

void write_hit_lists(const std::string& path, const HitLists& lists) {
  const size_t n = lists.found.size(), width = lists.max_hits, row = 4 + 8 * width;
  std::vector<uint8_t> b(12 + n * row);
  const uint32_t header[2] = {uint32_t(n), uint32_t(width)};
  std::memcpy(b.data(), "HITN", 4), std::memcpy(b.data() + 4, header, 8);
  for (size_t i = 0; i < n; ++i) {
    uint8_t* p = b.data() + 12 + i * row;
    std::memcpy(p, &lists.found[i], 4);
    for (size_t k = 0; k < width; ++k) {
      const Hit& h = lists.hits[i * width + k];
      HitRecord r{h.t, h.triangle};
      std::memcpy(p + 4 + 8 * k, &r, 8);
    }
  }
  write_file(path, b.data(), b.size());
}

std::vector<RayD> read_scene_rays(const std::string& path) { return read_records<RayD>(path, "RAYD", 40); }

void write_scene_rays(const std::string& path, const std::vector<RayD>& rays) {
  if (rays.size() > kMaxRayCount)
    throw InputError(path + ": " + std::to_string(rays.size()) + " rays, more than a rays file may hold (" +
                     std::to_string(kMaxRayCount) + ")");
  const uint32_t n = uint32_t(rays.size());
  static_assert(sizeof(RayD) == 40 && std::endian::native == std::endian::little, "a RayD is its record");
  write_file(path, {{"RAYD", 4}, {&n, 4}, {rays.data(), rays.size() * sizeof(RayD)}});
}

std::vector<SceneHit> read_scene_hits(const std::string& path) {
  std::vector<SceneHit> hits;
  for (const SceneHitRecord& r : read_records<SceneHitRecord>(path, "HITI", 12)) hits.push_back({r.t, r.instance, r.triangle});
  return hits;
}

void write_scene_hits(const std::string& path, const std::vector<SceneHit>& hits) {
  std::vector<uint8_t> b(8 + hits.size() * 12);
  const uint32_t n = uint32_t(hits.size());
  std::memcpy(b.data(), "HITI", 4), std::memcpy(b.data() + 4, &n, 4);
  for (size_t i = 0; i < hits.size(); ++i) {
    const SceneHitRecord r{hits[i].t, hits[i].instance, hits[i].triangle};
    std::memcpy(b.data() + 8 + i * 12, &r, 12);
  }
  write_file(path, b.data(), b.size());
}

bool is_scene_rays_file(const std::string& path) {
  char magic[4] = {};
  std::ifstream(path, std::ios::binary).read(magic, 4);  // unreadable: read_rays says why
  return std::memcmp(magic, "RAYD", 4) == 0;
}

}  // namespace meshcast
