#!/usr/bin/env bash
# The one sanitizer build of clang's AddressSanitizer and UBSan, in
# build-fuzz/: the fuzz targets (scripts/fuzz.sh) and the CPU suites that
# test.sh runs under ASan share its library, so the walkers' templates are
# compiled once for both. Every library is instrumented for libFuzzer's
# coverage as well (MESHCAST_FUZZ); the suites link without libFuzzer, and
# the sanitizer runtime answers the coverage hooks.
#   bash scripts/sanitizer_build.sh TARGET...   configures and builds TARGETs
# The widest walker set alone and line tables only (-g1): full debug info of
# the walkers' templates is most of a build's time; reports keep their
# files, lines and functions. -O2: at -O1 the build took as long (5.1
# minutes against 4.6 on the 2-core Xeon) and the suites and fuzz targets
# ran slower. The test counters are compiled in (the suites'
# counted-test checks run in this build alone); the Vulkan backend is left
# out (lavapipe and the loader are not instrumented: their allocations would
# read as leaks; the Vulkan suites run in Release and under TSan).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/packages.sh
install_missing clang libclang-rt-14-dev
source scripts/isa.sh
source scripts/ninja.sh
ninja_dir build-fuzz
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" \
      -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DMESHCAST_FUZZ=ON "-DMESHCAST_ISAS=$(widest_isa)" \
      -DMESHCAST_COUNT_TESTS=ON -DMESHCAST_VULKAN=OFF -DMESHCAST_TOOLS=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target "$@"
