#include "capi/handles.h"

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

}  // namespace

void register_handle(const void* handle, Kind kind) {
  std::lock_guard<std::mutex> lock(registry_lock);
  registry()[handle] = kind;
}

void check_handle(const void* handle, Kind kind, const char* what) {
  if (!handle) throw UsageError(std::string(what) + " is a null " + type_name(kind));
  std::lock_guard<std::mutex> lock(registry_lock);
  const auto it = registry().find(handle);
  if (it == registry().end())
    throw UsageError(std::string(what) + " is not a live " + type_name(kind) + " (released already, or not made by meshcast)");
  if (it->second != kind)
    throw UsageError(std::string(what) + " is a " + type_name(it->second) + ", not a " + type_name(kind));
}

void forget_handle(const void* handle) {
  std::lock_guard<std::mutex> lock(registry_lock);
  registry().erase(handle);
}

}  // namespace meshcast::capi
