// Which ray/triangle test a walker is instantiated with: a template
// parameter carried from each walker's entry down to triangle_test
// (cpu/intersect.h), so the test is fixed when the walker is compiled and
// no walk reads a choice at run time. The library's walkers take the
// watertight test alone; the plain Möller–Trumbore test is instantiated
// only in the walkers `meshcast bench robustness` and its test link
// (CMakeLists.txt: meshcast_triangle_tests, cpu/trace_with_triangle_test.h).
#pragma once

namespace meshcast {

enum class TriangleTest { Watertight, MollerTrumbore };

// The test the walker sources being compiled instantiate: the watertight
// one, unless the build compiles them once more for the other
// (MESHCAST_WALKERS_TRIANGLE_TEST=MollerTrumbore).
#ifndef MESHCAST_WALKERS_TRIANGLE_TEST
#define MESHCAST_WALKERS_TRIANGLE_TEST Watertight
#endif
constexpr TriangleTest kWalkersTriangleTest = TriangleTest::MESHCAST_WALKERS_TRIANGLE_TEST;

}  // namespace meshcast
