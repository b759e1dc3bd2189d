// A built blob, validated once and then walked on the calling thread; and a
// blob's file: loaded whole, memory-mapped, or saved.
//
//   meshcast::MappedBlob file("level.mcb");                 // or load_blob(...)
//   meshcast::BlobView view(file.bytes(), "level.mcb");     // validates
//   view.trace(rays, hits);                                 // this thread
//
// A BlobView does not copy the bytes: they must outlive it and stay
// unchanged, and they must start at a 4-byte aligned address (as a
// std::vector<uint8_t>, load_blob and MappedBlob give them). It is only
// ever read, so any number of threads may trace through one view at once.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "meshcast/build.h"
#include "meshcast/closest_point.h"
#include "meshcast/ray.h"

namespace meshcast {

struct WalkRequest;  // what a batch asks of a walker (internal: cpu/walk.h)

class BlobView {
 public:
  // Proves every offset and index of the blob in range (the header, its
  // checksum, every section) before any walk; InputError naming `name` and
  // what is wrong. The bytes must start at a 4-byte aligned address (the
  // walkers read the header's and the sections' 32-bit words in place): a
  // blob copied to an odd offset inside a buffer of one's own is refused
  // with InputError naming the address, never read misaligned.
  BlobView(std::span<const uint8_t> bytes, const std::string& name);

  // The closest hit of each ray (or with Query::Any, any hit), written to
  // hits[i]; returns how many rays were not walkable (ray_is_walkable:
  // answered as misses). `outputs`: what else each hit carries; `cull`:
  // which faces the rays see; `packets`: whether a batch of rays of one
  // origin may walk as packets (meshcast/ray.h; the same answers). UsageError
  // when hits is shorter than rays, or for Query::All (trace_all_hits
  // answers it).
  uint64_t trace(std::span<const Ray> rays, std::span<Hit> hits, HitOutputs outputs = HitOutputs::None,
                 Query query = Query::Closest, Cull cull = Cull::None, Packets packets = Packets::Auto) const;

  // Query::All: every hit of each ray along its segment into `lists`,
  // compact rows (meshcast/ray.h: cleared, then a row a ray holding its
  // kept hits alone; lists.max_hits, 1 to kMaxHitsLimit, says how many each
  // row keeps). Memory and time follow the hits found: lists reused from
  // frame to frame keep their capacity, and the walk needs a thread's
  // scratch of at most 16384 records besides. Returns the rays not
  // walkable, as trace() does. UsageError for max_hits out of range.
  uint64_t trace_all_hits(std::span<const Ray> rays, HitLists& lists, HitOutputs outputs = HitOutputs::None,
                          Cull cull = Cull::None) const;

  // Point queries (meshcast/closest_point.h): the nearest point of the
  // stored mesh to each of `points`, no farther than `max_distance` (the
  // limit included), written to out[i]; a point with none that near gets
  // ClosestPoint{} (distance INFINITY, triangle kNoHit). At one distance
  // the lower triangle number. Returns how many points had a NaN or
  // infinite coordinate (answered as none found). Walks OctTreeCompressed
  // blobs: the recommended layout and the exact one the automatic layout
  // picks under an error limit; UsageError naming any other layout, when
  // out is shorter than points, or for a negative or NaN max_distance.
  uint64_t closest_points(std::span<const Vec3> points, std::span<ClosestPoint> out,
                          float max_distance = INFINITY) const;

  std::span<const uint8_t> bytes() const { return bytes_; }
  Layout layout() const;
  uint32_t triangle_count() const;  // of the input mesh

 private:
  std::span<const uint8_t> bytes_;
  using Walk = void (*)(const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
  Walk walk_ = nullptr;
  bool walks_packets_ = false;  // the layout's walker has a packet walk
};

// The instruction set the CPU walkers run on, chosen once per process: the
// widest this processor has among those built (AVX-512, AVX2, scalar on
// x86-64; scalar elsewhere), or the one the environment variable
// MESHCAST_ISA names (scalar, avx2, avx512); UsageError on first use when it
// names one the processor or build lacks.
enum class WalkerIsa { Scalar, Avx2, Avx512 };
WalkerIsa walker_isa();
std::string_view walker_isa_name(WalkerIsa isa);

// A blob file read whole into memory (not validated: give it to a BlobView
// or a Caster). InputError naming the path for a missing, unreadable or
// non-regular file.
std::vector<uint8_t> load_blob(const std::string& path);

// Writes the blob beside `path`, then renames it over `path`, so a failed
// write (a full disk) leaves no partial file under that name. OutputError
// naming the path and the reason.
void save_blob(const std::string& path, std::span<const uint8_t> blob);

// A blob file mapped read-only into memory: no copy, the pages shared with
// every process that maps it. InputError naming the path when it cannot be
// opened or mapped. The bytes live as long as the MappedBlob, and are the
// file's as it is now: a BlobView validates them once, so the file must not
// be rewritten in place while it is mapped (its new bytes would be walked
// unvalidated), and a file truncated under the map raises SIGBUS on the
// next read. save_blob() renames a new file over the old name, which a
// mapping of the old file never sees; load_blob() keeps a copy instead.
class MappedBlob {
 public:
  explicit MappedBlob(const std::string& path);
  ~MappedBlob();
  MappedBlob(MappedBlob&& other) noexcept;
  MappedBlob& operator=(MappedBlob&& other) noexcept;
  MappedBlob(const MappedBlob&) = delete;
  MappedBlob& operator=(const MappedBlob&) = delete;
  std::span<const uint8_t> bytes() const { return {static_cast<const uint8_t*>(data_), size_}; }

 private:
  void* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace meshcast
