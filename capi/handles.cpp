#include "capi/handles.h"

#include <atomic>
#include <mutex>
#include <string>
#include <unordered_map>

#include "meshcast/errors.h"

namespace meshcast::capi {

namespace {

const char* type_name(Kind kind) {
  return kind == Kind::Blob ? "meshcast_blob" : kind == Kind::Scene ? "meshcast_scene" : "meshcast_caster";
}

std::mutex registry_lock;
std::unordered_map<const void*, Kind>& registry() {
  static auto* live = new std::unordered_map<const void*, Kind>;  // never destroyed: handles may be released at exit
  return *live;
}

// The handle this thread checked last, with the count of releases then: a
// call on the same handle, with no release anywhere since, needs no lock
// (a one-ray call's check falls from about 50 ns to a few).
std::atomic<uint64_t> releases{0};
struct Checked {
  const void* handle = nullptr;
  Kind kind = Kind::Blob;
  uint64_t releases = ~uint64_t(0);
};
thread_local Checked last_checked;

}  // namespace

void register_handle(const void* handle, Kind kind) {
  std::lock_guard<std::mutex> lock(registry_lock);
  registry()[handle] = kind;
}

void check_handle(const void* handle, Kind kind, const char* what) {
  if (!handle) throw UsageError(std::string(what) + " is a null " + type_name(kind));
  const uint64_t released = releases.load(std::memory_order_acquire);
  if (last_checked.handle == handle && last_checked.kind == kind && last_checked.releases == released) return;
  std::lock_guard<std::mutex> lock(registry_lock);
  const auto it = registry().find(handle);
  if (it == registry().end())
    throw UsageError(std::string(what) + " is not a live " + type_name(kind) + " (released already, or not made by meshcast)");
  if (it->second != kind)
    throw UsageError(std::string(what) + " is a " + type_name(it->second) + ", not a " + type_name(kind));
  last_checked = {handle, kind, released};
}

void forget_handle(const void* handle) {
  std::lock_guard<std::mutex> lock(registry_lock);
  registry().erase(handle);
  releases.fetch_add(1, std::memory_order_acq_rel);
}

}  // namespace meshcast::capi
