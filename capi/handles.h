// The C API's handles: what each holds, and the registry that tells a
// live handle from a released one (or a pointer never made here) without
// reading it.
#pragma once
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/caster.h"
#include "meshcast/meshcast_c.h"
#include "meshcast/scene.h"

// A blob: its validated view, and what keeps its bytes (a vector, a
// mapping, or nothing for the caller's borrowed memory).
struct meshcast_blob {
  std::shared_ptr<const void> owner;
  std::shared_ptr<const meshcast::MappedBlob> mapped;  // when mapped: scenes share the mapping
  meshcast::BlobView view;
  std::string name, layout;
};

// A scene, and the bytes of the blobs it walks where it only references
// them.
struct meshcast_scene {
  meshcast::Scene scene;
  std::vector<std::shared_ptr<const void>> owners;
};

// A caster, the bytes of its blob, and for each scene batch in flight the
// bytes its scene walks (a scene released meanwhile leaves them alive).
struct meshcast_caster {
  std::shared_ptr<const void> blob_owner;
  std::unique_ptr<meshcast::host::Caster> caster;
  std::mutex held_lock;
  std::unordered_map<uint64_t, std::vector<std::shared_ptr<const void>>> held;
};

namespace meshcast::capi {

enum class Kind { Blob, Scene, Caster };

// Every live handle, with its kind.
void register_handle(const void* handle, Kind kind);
// UsageError naming `what` and `type` unless `handle` is live and of `kind`.
void check_handle(const void* handle, Kind kind, const char* what);
// Forgets a live handle (check_handle first).
void forget_handle(const void* handle);

template <class T> constexpr Kind kind_of();
template <> constexpr Kind kind_of<meshcast_blob>() { return Kind::Blob; }
template <> constexpr Kind kind_of<meshcast_scene>() { return Kind::Scene; }
template <> constexpr Kind kind_of<meshcast_caster>() { return Kind::Caster; }

// The handle, checked live.
template <class T>
T& live(T* handle, const char* what) {
  check_handle(handle, kind_of<std::remove_const_t<T>>(), what);
  return *handle;
}

// A new handle, registered; the caller's *out set to it.
template <class T>
void hand_out(std::unique_ptr<T> made, T** out) {
  register_handle(made.get(), kind_of<T>());
  *out = made.release();
}

// Releases a handle (null: nothing).
template <class T>
void release(T* handle, const char* what) {
  if (!handle) return;
  check_handle(handle, kind_of<T>(), what);
  forget_handle(handle);
  delete handle;
}

}  // namespace meshcast::capi
