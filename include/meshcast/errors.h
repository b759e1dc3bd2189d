// Every error meshcast throws is a meshcast::Error; its message names the
// input (a file, a mesh, a blob, an option, a ticket) and the limit it broke.
// Errors surface at load, build, validation and submission time; a walk that
// has begun neither throws nor allocates (Query::All's compact rows grow
// between rays with the hits found: std::bad_alloc only when the hits
// themselves do not fit).
#pragma once
#include <stdexcept>
#include <string>

namespace meshcast {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bad input: a mesh (NaN or infinite vertices, out-of-range indices, beyond a
// format's limits), a mesh, blob or rays file (malformed, truncated,
// corrupted), an option out of range.
struct InputError : Error {
  using Error::Error;
};

// A file that could not be written whole (a full disk, a folder that is not
// writable): nothing is left under the file's name.
struct OutputError : Error {
  using Error::Error;
};

// A call the API does not allow: a hits span shorter than the rays, a ticket
// this caster did not issue (another caster's) or already collected, every
// frame slot busy, a batch larger than the machine's memory holds, an
// engine's Vulkan objects that lack (or do not state) a version or feature
// meshcast needs (caster.h, VulkanObjects).
struct UsageError : Error {
  using Error::Error;
};

// No Vulkan, no device, or a Vulkan call that failed. `lost`: the device is
// gone (VK_ERROR_DEVICE_LOST); other errors concern one request.
struct GpuError : Error {
  explicit GpuError(const std::string& what, bool lost = false) : Error(what), lost(lost) {}
  bool lost;
};

}  // namespace meshcast
