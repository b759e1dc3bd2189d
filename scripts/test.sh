#!/usr/bin/env bash
# The whole test suite: the Release build, then the corrupted-blob and
# robustness suites under AddressSanitizer/UBSan, then the portable scalar
# build (MESHCAST_SCALAR) through the same tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)

echo "== Release (AVX2)"
ctest --test-dir build --output-on-failure -j"$jobs" --timeout 900

echo "== AddressSanitizer + UBSan: corrupted blobs, robustness corpus"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMESHCAST_SANITIZE=ON >/dev/null
cmake --build build-asan -j"$jobs" --target layout_test robustness_test
ctest --test-dir build-asan --output-on-failure -j"$jobs" --timeout 900 -R "Blob|Robustness|Half|BitPack|Corruption"

echo "== Portable scalar path"
cmake -S . -B build-scalar -DCMAKE_BUILD_TYPE=Release -DMESHCAST_SCALAR=ON >/dev/null
cmake --build build-scalar -j"$jobs"
ctest --test-dir build-scalar --output-on-failure -j"$jobs" --timeout 900
