// What every call of the C API (meshcast/meshcast_c.h) shares: the C++
// exception a call throws becomes its status and this thread's message,
// and the caller's structs are read up to the size the caller declared.
#pragma once
#include <cstdint>
#include <cstring>
#include <new>
#include <string>

#include "meshcast/errors.h"
#include "meshcast/meshcast_c.h"

namespace meshcast::capi {

// Records a failure of `call` (this thread's message, the callback) and
// returns its status.
meshcast_status fail(const char* call, meshcast_status status, const char* message) noexcept;
// Clears this thread's message after a call that succeeded.
void succeed() noexcept;
// A C++ message in the C API's words: its names where the C++ library's
// types and methods are named.
std::string c_api_words(std::string text);

// Runs body(), the whole of a call: MESHCAST_OK, or the status of what it
// threw, its message prefixed with the call's name. Nothing escapes.
template <class Body>
meshcast_status guarded(const char* call, Body&& body) noexcept {
  try {
    body();
    succeed();
    return MESHCAST_OK;
  } catch (const UsageError& e) {
    return fail(call, MESHCAST_ERROR_USAGE, e.what());
  } catch (const InputError& e) {
    return fail(call, MESHCAST_ERROR_INPUT, e.what());
  } catch (const OutputError& e) {
    return fail(call, MESHCAST_ERROR_OUTPUT, e.what());
  } catch (const GpuError& e) {
    return fail(call, MESHCAST_ERROR_GPU, e.what());
  } catch (const std::bad_alloc&) {
    return fail(call, MESHCAST_ERROR_OUT_OF_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    return fail(call, MESHCAST_ERROR_INTERNAL, e.what());
  } catch (...) {
    return fail(call, MESHCAST_ERROR_INTERNAL, "an unknown exception");
  }
}

// `p`, or UsageError naming the argument when it is null.
template <class T>
T* required(T* p, const char* what) {
  if (!p) throw UsageError(std::string(what) + " is null");
  return p;
}

// An array argument of `count` elements: null only when count is 0.
template <class T>
T* array(T* p, uint64_t count, const char* what) {
  if (!p && count) throw UsageError(std::string(what) + " is null for " + std::to_string(count) + " elements");
  return p;
}

// Room for `needed` answers in a buffer of `capacity`.
void check_capacity(uint64_t capacity, uint64_t needed, const char* what);

// A struct the caller sized (struct_size first): `defaults` with the
// caller's fields over them, as many bytes as its struct_size declares (a
// newer header's extra fields are left out, an older one's missing fields
// keep their defaults); UsageError for a size under `first_size`, the
// struct's size in the API's first version. Null: the defaults.
template <class T>
T sized(const T* given, T defaults, size_t first_size, const char* what) {
  if (!given) return defaults;
  if (given->struct_size < first_size)
    throw UsageError(std::string(what) + "->struct_size " + std::to_string(given->struct_size) + " is less than the " +
                     std::to_string(first_size) + " bytes of its first version: set it to sizeof(" + what +
                     "'s type), or call its _init");
  std::memcpy(static_cast<void*>(&defaults), given, std::min<size_t>(given->struct_size, sizeof(T)));
  defaults.struct_size = uint32_t(sizeof(T));
  return defaults;
}

// The threads a call's `threads` asks for: 0 every core, else itself
// (UsageError past 1024).
uint32_t threads_of(uint32_t threads);

}  // namespace meshcast::capi
