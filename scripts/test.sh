#!/usr/bin/env bash
# The whole test suite: the Release build, then every CPU suite under
# AddressSanitizer/UBSan, the host layer under ThreadSanitizer,
# the CPU suites on the portable scalar build (MESHCAST_SCALAR), and last the
# fuzz targets under libFuzzer for a bounded time (scripts/fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)

# The CPU suites (CTest label `cpu`), run one process a suite, $jobs at a
# time: CTest's one process a test would load the meshes and compute the
# oracle's answers again for each of its 2,000-odd tests (5 of Release's 9
# minutes). `run_suites DIR quick` sets MESHCAST_TEST_QUICK: bunny00 and the
# generated meshes only, fewer rays a set (the sanitizer and scalar builds;
# Release walks everything). A failing suite prints its log; xargs waits for
# the others and fails the pipeline.
cpu_suites=(walker_test robustness_test auto_test build_test layout_test oracle_test io_test pairing_test zerobyte_test
            limits_test hostile_test)
run_suites() {  # run_suites BUILD_DIR [quick]
  local quick=()
  [[ ${2:-} == quick ]] && quick=(MESHCAST_TEST_QUICK=1)
  printf '%s\n' "${cpu_suites[@]}" |
    env MESHCAST_DATA="$PWD/data" "${quick[@]}" LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp" \
      xargs -P"$jobs" -I{} sh -c "$1"'/bin/{} --gtest_brief=1 > '"$1"'/{}.log 2>&1 && echo "  {}: passed" ||
                                 { echo "  {}: FAILED"; tail -50 '"$1"'/{}.log; exit 1; }'
}
stage() { echo "== $* ($((SECONDS / 60)) min $((SECONDS % 60)) s in)"; }
# The sanitizer builds: -O2 with line tables only (-g1): reports keep their
# files, lines and functions; full debug info of the walkers' templates
# doubled these builds' time.
sanitizer_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG")

stage "Release (AVX2): the CPU suites"
run_suites build
stage "Release: the Vulkan suites, the host layer, the command line and the fuzz corpora (CTest)"
ctest --test-dir build --output-on-failure -j"$jobs" --timeout 900 -LE cpu

stage "AddressSanitizer + UBSan: every CPU test suite"
# The Vulkan suites stay out of this build: lavapipe and the loader are not
# instrumented (their own allocations would read as leaks); they run in the
# Release build above and the host layer under TSan below.
# The fuzz corpora replay under clang's ASan and UBSan at the start of the
# libFuzzer stage (and without sanitizers in Release's CTest).
cmake -S . -B build-asan "${sanitizer_flags[@]}" -DMESHCAST_SANITIZE=ON >/dev/null
cmake --build build-asan -j"$jobs" --target "${cpu_suites[@]}"
run_suites build-asan quick

stage "ThreadSanitizer: the host layer, several threads submitting at once (CPU and Vulkan)"
# MESHCAST_HOST_CPU_ONLY=1 would keep lavapipe out, should its own
# (uninstrumented) threads ever make TSan report what it cannot see.
cmake -S . -B build-tsan "${sanitizer_flags[@]}" -DMESHCAST_TSAN=ON >/dev/null
cmake --build build-tsan -j"$jobs" --target host_test
MESHCAST_DATA="$PWD/data" TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build-tsan/bin/host_test

stage "Portable scalar path, with the box and triangle test counters compiled in: the CPU suites"
# The scalar build changes only cpu/simd.h's lanes: the CPU suites (quick, as
# under ASan) cover it; the Vulkan suites read the same shaders as Release.
cmake -S . -B build-scalar -DCMAKE_BUILD_TYPE=Release -DMESHCAST_SCALAR=ON -DMESHCAST_COUNT_TESTS=ON >/dev/null
cmake --build build-scalar -j"$jobs" --target "${cpu_suites[@]}"
run_suites build-scalar quick

stage "libFuzzer: the blob validator + walker and the mesh reader + builder"
bash scripts/fuzz.sh
stage "done"
