// The C API's handles: what each holds, and the registry that tells a
// live handle from a released one (or a pointer never made here) without
// reading it. A call holds the handle it was given until it returns, so a
// release on another thread meanwhile frees it after that call, not under it.
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

// Every live handle, with its kind; the registry holds `handle` until it
// is released.
void register_handle(std::shared_ptr<void> handle, Kind kind);
// The handle, held for the caller, unless it is not live or not of `kind`
// (UsageError naming `what` and its type).
std::shared_ptr<void> hold_handle(const void* handle, Kind kind, const char* what);
// Takes a live handle out of the registry (UsageError as hold_handle's):
// later calls refuse it; the calls holding it keep it until they return.
std::shared_ptr<void> forget_handle(const void* handle, Kind kind, const char* what);

template <class T> constexpr Kind kind_of();
template <> constexpr Kind kind_of<meshcast_blob>() { return Kind::Blob; }
template <> constexpr Kind kind_of<meshcast_scene>() { return Kind::Scene; }
template <> constexpr Kind kind_of<meshcast_caster>() { return Kind::Caster; }

// The handle, checked live and held until the returned pointer goes: keep
// it for the whole call.
template <class T>
std::shared_ptr<T> live(T* handle, const char* what) {
  return std::static_pointer_cast<T>(hold_handle(handle, kind_of<std::remove_const_t<T>>(), what));
}

// A new handle, registered; the caller's *out set to it.
template <class T>
void hand_out(std::unique_ptr<T> made, T** out) {
  T* raw = made.get();
  register_handle(std::shared_ptr<T>(std::move(made)), kind_of<T>());
  *out = raw;
}

// Releases a handle (null: nothing): freed now, or when the last call
// still using it returns.
template <class T>
void release(T* handle, const char* what) {
  if (handle) forget_handle(handle, kind_of<T>(), what);
}

}  // namespace meshcast::capi
