// The one table of GPU methods: each method, every layout it reads, and the
// shaders it runs on that layout. Everything else that needs to know which
// layouts the GPU reads (method_layouts, method_reading, the automatic
// layout choice's readers, the tests' and benchmarks' lists, each method's
// refusal of a blob) is derived from it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "gpu/method.h"

namespace meshcast::gpu {

// A shader compiled to SPIR-V at build time (shaders/*.h in the build folder).
struct Spirv {
  const uint32_t* words = nullptr;
  size_t bytes = 0;
};

struct MethodReading;
using MakeMethod = std::unique_ptr<Method> (*)(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                               const MethodReading& line, uint32_t slots, uint32_t flags,
                                               uint32_t max_hits);

// One line of the table.
struct MethodReading {
  MethodLayout what;
  // The tree walkers' walk; brute force's and AABBList's per-record test.
  Spirv test;
  // Brute force's and AABBList's pass that turns keys into hits; none for
  // the tree walkers, which write hits as they go.
  Spirv resolve;
  MakeMethod make;
};

std::span<const MethodReading> method_table();

// The line of `method` for the blob's layout; the method's first line when
// the blob is too short to say or is of a layout the method does not read
// (the method's constructor refuses it then, naming layouts_read_by:
// gpu/method.h).
// InputError listing the methods for an unknown one.
const MethodReading& method_line(const std::string& method, std::span<const uint8_t> blob);

// The factories the table's lines name (gpu/walkers.cpp, gpu/bruteforce.cpp,
// gpu/aabblist.cpp).
std::unique_ptr<Method> make_walker(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                    const MethodReading& line, uint32_t slots, uint32_t flags, uint32_t max_hits);
std::unique_ptr<Method> make_bruteforce(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                        const MethodReading& line, uint32_t slots, uint32_t flags, uint32_t max_hits);
std::unique_ptr<Method> make_aabblist_method(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                             const MethodReading& line, uint32_t slots, uint32_t flags,
                                             uint32_t max_hits);

}  // namespace meshcast::gpu
