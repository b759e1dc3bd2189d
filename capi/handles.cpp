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

// Each live handle: its kind, and the registry's hold on it.
struct Entry {
  Kind kind;
  std::shared_ptr<void> held;
};
std::mutex registry_lock;
std::unordered_map<const void*, Entry>& registry() {
  static auto* live = new std::unordered_map<const void*, Entry>;  // never destroyed: handles may be released at exit
  return *live;
}

// The handle this thread checked last, with the count of releases then: a
// call on the same handle, with no release anywhere since, takes its hold
// without the lock (a one-ray call's check falls from about 50 ns to a
// few). The weak pointer keeps no handle alive: a handle released since
// (and freed, its last call returned) fails to lock and is looked up.
std::atomic<uint64_t> releases{0};
struct Checked {
  const void* handle = nullptr;
  Kind kind = Kind::Blob;
  uint64_t releases = ~uint64_t(0);
  std::weak_ptr<void> held;
};
thread_local Checked last_checked;

// The registry's entry of a live handle of `kind` (under registry_lock).
std::unordered_map<const void*, Entry>::iterator find_live(const void* handle, Kind kind, const char* what) {
  const auto it = registry().find(handle);
  if (it == registry().end())
    throw UsageError(std::string(what) + " is not a live " + type_name(kind) + " (released already, or not made by meshcast)");
  if (it->second.kind != kind)
    throw UsageError(std::string(what) + " is a " + type_name(it->second.kind) + ", not a " + type_name(kind));
  return it;
}

}  // namespace

void register_handle(std::shared_ptr<void> handle, Kind kind) {
  std::lock_guard<std::mutex> lock(registry_lock);
  const void* key = handle.get();
  registry()[key] = {kind, std::move(handle)};
}

std::shared_ptr<void> hold_handle(const void* handle, Kind kind, const char* what) {
  if (!handle) throw UsageError(std::string(what) + " is a null " + type_name(kind));
  const uint64_t released = releases.load(std::memory_order_acquire);
  if (last_checked.handle == handle && last_checked.kind == kind && last_checked.releases == released)
    if (std::shared_ptr<void> held = last_checked.held.lock()) return held;
  std::lock_guard<std::mutex> lock(registry_lock);
  std::shared_ptr<void> held = find_live(handle, kind, what)->second.held;
  last_checked = {handle, kind, released, held};
  return held;
}

std::shared_ptr<void> forget_handle(const void* handle, Kind kind, const char* what) {
  std::lock_guard<std::mutex> lock(registry_lock);
  const auto it = find_live(handle, kind, what);
  std::shared_ptr<void> held = std::move(it->second.held);
  registry().erase(it);
  releases.fetch_add(1, std::memory_order_acq_rel);
  return held;  // let go by the caller, outside the lock: a caster's end waits for its threads
}

}  // namespace meshcast::capi
