#!/usr/bin/env bash
# Builds pack_before_after.cpp against the GPU ray packing as it was
# before the shaders prepared their own rays (commit fa38a9b) and runs it.
# Usage: bench/results/gpu_scale/pack_before_after.sh [BUILD_DIR]
set -euo pipefail
root=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
build=${1:-$root/build}
old=$(mktemp -d)
trap 'rm -rf "$old"' EXIT
mkdir -p "$old/gpu" "$old/layout"
git -C "$root" show fa38a9b:gpu/rays.h >"$old/gpu/rays.h"
git -C "$root" show fa38a9b:gpu/rays.cpp >"$old/gpu/rays.cpp"
git -C "$root" show fa38a9b:layout/ray_record.h >"$old/layout/ray_record.h"
g++ -std=c++20 -O3 -march=native -I"$old" -I"$root" -I"$root/include" "$(dirname "$0")/pack_before_after.cpp" \
  "$old/gpu/rays.cpp" "$build/libmeshcast.a" -o "$old/pack" -lpthread
"$old/pack"
