#!/usr/bin/env bash
# The whole test suite (docs/testing.md lists the stages and their time):
# the Release build (its walkers on every instruction set the processor
# has), the CPU suites that read hostile input and walk under
# AddressSanitizer/UBSan with the fuzz targets under libFuzzer for a bounded
# time (scripts/fuzz.sh) in the same build, the host layer under
# ThreadSanitizer, and the installed package.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)
# meshcast.dask's tests (pytest, below) run on Debian's Dask, the C#
# binding's on Debian's Mono: installed while the CPU suites run (a
# download, mostly waiting).
source scripts/packages.sh
install_missing python3-dask python3-distributed mono-mcs mono-runtime > build/package_install.log 2>&1 &
package_install_job=$!

# The CPU suites (CTest label `cpu`), run one process a suite, $jobs at a
# time: CTest's one process a test would load the meshes and compute the
# oracle's answers again for each of its 2,000-odd tests. `quick` sets
# MESHCAST_TEST_QUICK: bunny00, the sphere and the grid only, fewer rays a
# set (the sanitizer builds and the other instruction sets; Release walks
# everything). A failing
# suite prints its log; xargs waits for the others and fails the pipeline.
# The longest first; those of `sharded` (below) in two shards each.
cpu_suites=(walker_test robustness_test auto_test limits_test layout_test build_test pairing_test zerobyte_test scene_test point_test
            hostile_test oracle_test io_test)
# Under AddressSanitizer: the suites that read hostile input, walk points, place
# instances and allocate per frame. The layouts' own suites (layout_test,
# pairing_test, auto_test), the builder's (build_test: its threads run
# under TSan below), the oracle's and the stiff and extreme inputs'
# (robustness_test: the walks walker_test and hostile_test drive here, on
# rays of extreme range) run in Release alone, on every instruction set:
# their encoders are the builds the suites below make, and the fuzz
# targets' ASan builds read, build and walk every layout on arbitrary
# bytes and rays again.
# walker_test is not among them: the fuzz targets walk every layout under
# the sanitizers, and the walks run on three instruction sets in Release.
asan_suites=(limits_test zerobyte_test scene_test hostile_test io_test point_test)
# What another instruction set changes (cpu/simd.h's lanes): the suites that walk.
walk_suites=(walker_test robustness_test limits_test pairing_test zerobyte_test scene_test point_test)
# The suites long enough to run in two shards, so the two cores finish together.
sharded=(walker_test robustness_test gpu_test gpu_robustness_test)
# The host layer and the Vulkan suites (CTest label `gpu`), one process a
# suite as the CPU suites, with the validation layers on: a test fails on
# any message they send. The longest first.
gpu_suites=(gpu_robustness_test gpu_test host_test gpu_scene_test)
run_suites() {  # run_suites BUILD_DIR quick|full SUITE...
  local dir=$1 quick=()
  [[ $2 == quick ]] && quick=(MESHCAST_TEST_QUICK=1)
  shift 2
  local items=() s
  for s in "$@"; do
    if [[ " ${sharded[*]} " == *" $s "* ]]; then items+=("$s#0" "$s#1"); else items+=("$s"); fi
  done
  printf '%s\n' "${items[@]}" |
    env MESHCAST_DATA="$PWD/data" "${quick[@]}" LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp" \
      xargs -P"$jobs" -I{} sh -c '
        dir=$0 item=$1 suite=${1%#*}
        if [ "$suite" != "$item" ]; then export GTEST_TOTAL_SHARDS=2 GTEST_SHARD_INDEX=${item#*#}; fi
        "$dir/bin/$suite" --gtest_brief=1 > "$dir/$item.log" 2>&1 && echo "  $item: passed" ||
          { echo "  $item: FAILED"; tail -50 "$dir/$item.log"; exit 1; }' "$dir" {}
}
stage() { echo "== $* ($((SECONDS / 60)) min $((SECONDS % 60)) s in)"; }
# A job run beside a stage (one that leaves a core idle much of its time):
# its output printed when it is waited for, its failure failing the run.
finish() {  # finish PID LABEL LOG
  if wait "$1"; then cat "$3"; else cat "$3"; echo "FAILED: $2"; exit 1; fi
}

# The ThreadSanitizer build: -O1 with line tables only (-g1): reports keep their
# files, lines and functions; full debug info of the walkers' templates
# doubled these builds' time, and -O2 took 5.8 min to build the ASan stage
# where -O1 takes 4.4 (its suites ran 3.3 min either way).
tsan_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG")

# The walkers' instruction sets (cpu/isa.h): the Release build has them all
# and runs the widest this processor has, then the suites that walk again
# on AVX2 (where the widest is AVX-512) and on the scalar set, quick; the
# sanitizer builds compile the widest set alone (one walker set is most of
# their build time).
source scripts/isa.sh
widest=$(widest_isa)

stage "Release ($widest walkers): the CPU suites"
run_suites build full "${cpu_suites[@]}"
if [[ $widest == avx512 ]]; then
  stage "Release, the AVX2 walkers this processor also runs (MESHCAST_ISA=avx2): the suites that walk"
  MESHCAST_ISA=avx2 run_suites build quick "${walk_suites[@]}"
fi
if [[ $widest != scalar ]]; then
  stage "Release, the portable scalar walkers (MESHCAST_ISA=scalar): the suites that walk"
  MESHCAST_ISA=scalar run_suites build quick "${walk_suites[@]}"
fi
stage "Release: the Vulkan suites and the host layer, one process a suite, beside the command line, the C API, the headers and the fuzz corpora (CTest)"
# CTest's tests here are one long script (the command line's, two minutes)
# and many short ones: on one core beside the suites, the cores finish
# together.
ctest --test-dir build --output-on-failure -j1 --timeout 900 -LE "cpu|gpu" > build/ctest.log 2>&1 &
ctest_job=$!
MESHCAST_VK_VALIDATION=1 run_suites build full "${gpu_suites[@]}"
finish $ctest_job "CTest" build/ctest.log

finish $package_install_job "installing Dask and Mono" build/package_install.log
stage "C#: the binding (bindings/csharp) under Mono, its answers against the C++ library's"
mcs -nologo -target:exe -out:build/MeshcastTest.exe bindings/csharp/Meshcast.cs bindings/csharp/test/MeshcastTest.cs
LD_LIBRARY_PATH="$PWD/build" mono build/MeshcastTest.exe build/bin/meshcast data/bunny00.off build
stage "Rust: meshcast-sys's declarations against the header, the safe crate's answers against the C++ library's (cargo test --offline)"
command -v cargo >/dev/null || install_missing cargo  # the machine's own cargo where there is one, else Debian's
(cd bindings/rust && MESHCAST_LIB_DIR="$OLDPWD/build" LD_LIBRARY_PATH="$OLDPWD/build" \
   MESHCAST_PROGRAM="$OLDPWD/build/bin/meshcast" MESHCAST_MESH="$OLDPWD/data/bunny00.off" \
   CARGO_TARGET_DIR="$OLDPWD/build/rust" cargo test --offline -q 2>&1 | grep -v '^$')
stage "Python: the package (build/python) against its own double-precision brute force, and meshcast.dask on a local cluster (pytest), beside the sanitizer build"
# pytest keeps one core busy about half its time (the cluster's processes
# starting, the spawned children): the sanitizer build takes the rest.
PYTHONPATH="$PWD/build/python" MESHCAST_DATA="$PWD/data" /usr/bin/python3 -m pytest -q -p no:cacheprovider python/tests \
  > build/pytest.log 2>&1 &
pytest_job=$!

stage "AddressSanitizer + UBSan (clang, $widest walkers), the test counters compiled in, without the Vulkan backend: the CPU suites of asan_suites, the CPU host layer and the C API, then the fuzz targets"
# One sanitizer build (scripts/sanitizer_build.sh, build-fuzz/) serves the
# suites and the libFuzzer targets: the walkers' templates, most of a
# build's time, are compiled once for both. The Vulkan suites stay out of
# it: lavapipe and the loader are not instrumented (their own allocations
# would read as leaks); they run in the Release build above and the host
# layer under TSan below. The test counters (MESHCAST_COUNT_TESTS) are
# compiled in there: the suites' counted-test checks run in that build
# alone. The fuzz corpora replay under ASan and UBSan at the start of each
# fuzz target's run (and without sanitizers in Release's CTest).
bash scripts/sanitizer_build.sh "${asan_suites[@]}" host_test c_api_test blob_fuzz mesh_fuzz
finish $pytest_job pytest build/pytest.log
run_suites build-fuzz quick "${asan_suites[@]}" host_test c_api_test
bash scripts/fuzz.sh

stage "ThreadSanitizer: the host layer, several threads submitting at once (CPU and Vulkan), and the builder's threads, beside the package's test"
# MESHCAST_HOST_CPU_ONLY=1 would keep lavapipe out, should its own
# (uninstrumented) threads ever make TSan report what it cannot see.
source scripts/ninja.sh
ninja_dir build-tsan
cmake -S . -B build-tsan -G Ninja "${tsan_flags[@]}" -DMESHCAST_TSAN=ON "-DMESHCAST_ISAS=$widest" >/dev/null
cmake --build build-tsan -j"$jobs" --target host_test build_test
# The runs under TSan keep about one core busy: the package's test (its
# configure steps one core too) runs beside them.
# tests/tsan.supp leaves out races inside the Vulkan validation layer's own threads.
{
  MESHCAST_DATA="$PWD/data" TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/tests/tsan.supp" \
    build-tsan/bin/host_test &&
  MESHCAST_DATA="$PWD/data" MESHCAST_TEST_QUICK=1 TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
    build-tsan/bin/build_test --gtest_brief=1 --gtest_filter='Build.AnyNumberOfThreadsBuildsTheSameBytes:BuildThreads.*'
} > build-tsan/tsan.log 2>&1 &
tsan_job=$!

stage "The package: installed and used by the examples (CMake and pkg-config), and as a subproject"
bash scripts/package_test.sh
stage "ThreadSanitizer's runs"
finish $tsan_job "the ThreadSanitizer runs" build-tsan/tsan.log
stage "done"
