#include "capi/status.h"

#include <atomic>
#include <cctype>
#include <mutex>
#include <string_view>

#include "host/shared_pool.h"

namespace meshcast::capi {

namespace {

thread_local std::string last_message;

struct Callback {
  meshcast_error_callback function = nullptr;
  void* user = nullptr;
};
std::mutex callback_lock;
Callback callback;

// The C++ library's names in a message, and what a C caller knows them
// as: the C API's own names, or nothing where the call's name says it.
struct Words {
  std::string_view cpp, c;
};
constexpr Words kCWords[] = {
    {"(CasterOptions::device, $MESHCAST_VK_DEVICE)", "($MESHCAST_VK_DEVICE)"},
    {"CasterOptions::", "options->"},
    {"Backend::Cpu", "MESHCAST_BACKEND_CPU"},
    {"Backend::Vulkan", "MESHCAST_BACKEND_VULKAN"},
    {"Backend::Automatic", "MESHCAST_BACKEND_AUTOMATIC"},
    {"HitOutputs::Uv", "MESHCAST_HIT_UV"},
    {"HitOutputs::Point", "MESHCAST_HIT_POINT"},
    {"as a std::vector<uint8_t>, load_blob and MappedBlob give it",
     "as meshcast_blob_load and MESHCAST_MEMORY_COPY give it"},
    {"meshcast::", ""},
};
// A C++ method's name opening a message ("Scene::add_instance: "): the C
// call's name, already before it, says which.
constexpr std::string_view kMethodOwners[] = {"Scene::", "Caster::"};

// The end of the name that starts at `at` (letters, digits, _).
size_t run_of(const std::string& text, size_t at) {
  while (at < text.size() && (std::isalnum(static_cast<unsigned char>(text[at])) || text[at] == '_')) ++at;
  return at;
}

}  // namespace

std::string c_api_words(std::string text) {
  for (const Words& w : kCWords)
    for (size_t at = text.find(w.cpp); at != std::string::npos; at = text.find(w.cpp, at + w.c.size()))
      text.replace(at, w.cpp.size(), w.c);
  for (std::string_view owner : kMethodOwners)
    for (size_t at = text.find(owner); at != std::string::npos; at = text.find(owner, at)) {
      const size_t end = run_of(text, at + owner.size());
      if (text.compare(end, 2, ": ") == 0) text.erase(at, end + 2 - at);
      else at = end;
    }
  return text;
}

meshcast_status fail(const char* call, meshcast_status status, const char* message) noexcept {
  // The callback gets a copy of its own: a failing call it makes sets this
  // thread's message again, and the copy lives until it returns.
  std::string text;
  try {
    text = std::string(call) + ": " + c_api_words(message);
    last_message = text;
  } catch (...) {  // no memory for the message: the call's name at least
    text.clear();
    last_message.clear();
  }
  Callback c;
  {
    std::lock_guard<std::mutex> lock(callback_lock);
    c = callback;
  }
  if (c.function) {
    c.function(c.user, status, text.empty() ? call : text.c_str());
    // The failed call's message is this call's, whatever the callback's
    // own calls left.
    last_message = std::move(text);
  }
  return status;
}

void succeed() noexcept { last_message.clear(); }

void check_capacity(uint64_t capacity, uint64_t needed, const char* what) {
  if (capacity < needed)
    throw UsageError(std::string(what) + " holds " + std::to_string(capacity) + " answers, fewer than the " +
                     std::to_string(needed) + " asked for");
}

uint32_t threads_of(uint32_t threads) {
  if (threads > 1024) throw UsageError("threads " + std::to_string(threads) + ": from 0 (every core) to 1024");
  return threads ? threads : host::every_core();
}

}  // namespace meshcast::capi

extern "C" {

uint32_t meshcast_api_version(void) { return MESHCAST_C_API_VERSION; }

const char* meshcast_last_error(void) { return meshcast::capi::last_message.c_str(); }

const char* meshcast_status_name(meshcast_status status) {
  switch (status) {
    case MESHCAST_OK: return "MESHCAST_OK";
    case MESHCAST_ERROR_INPUT: return "MESHCAST_ERROR_INPUT";
    case MESHCAST_ERROR_USAGE: return "MESHCAST_ERROR_USAGE";
    case MESHCAST_ERROR_OUTPUT: return "MESHCAST_ERROR_OUTPUT";
    case MESHCAST_ERROR_GPU: return "MESHCAST_ERROR_GPU";
    case MESHCAST_ERROR_OUT_OF_MEMORY: return "MESHCAST_ERROR_OUT_OF_MEMORY";
    case MESHCAST_ERROR_INTERNAL: return "MESHCAST_ERROR_INTERNAL";
  }
  return "an unknown meshcast_status";
}

void meshcast_set_error_callback(meshcast_error_callback callback, void* user) {
  std::lock_guard<std::mutex> lock(meshcast::capi::callback_lock);
  meshcast::capi::callback = {callback, user};
}

}  // extern "C"
