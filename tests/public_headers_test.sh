#!/usr/bin/env bash
# Each header of include/meshcast/ compiles alone (nothing it needs comes
# from another include first), and its preprocessed text holds nothing a
# user should not get: no SIMD intrinsics, no Vulkan, no Assimp, no test
# framework, no internal header of the repository.
# Usage: public_headers_test.sh CXX INCLUDE_DIR
set -euo pipefail
cxx=$1 include=$(realpath "$2")
repo=$(dirname "$include")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0 count=0
for h in "$include"/meshcast/*.h; do
  name=meshcast/$(basename "$h")
  count=$((count + 1))
  printf '#include <%s>\n' "$name" > "$tmp/one.cpp"
  if ! "$cxx" -std=c++20 -Wall -Wextra -Werror -fsyntax-only -I"$include" "$tmp/one.cpp" 2> "$tmp/err"; then
    echo "FAIL: $name does not compile alone:"; head -20 "$tmp/err"; failed=1; continue
  fi
  # Every file the preprocessor opened, from its line markers.
  "$cxx" -std=c++20 -E -I"$include" "$tmp/one.cpp" | sed -n 's/^# [0-9]* "\([^"]*\)".*/\1/p' | sort -u > "$tmp/files"
  if bad=$(grep -E 'immintrin|mmintrin|vulkan|volk|assimp|gtest|gmock|/(cpu|gpu|layout|host|io|tests|bench|tools)/' "$tmp/files"); then
    echo "FAIL: $name brings in:"; echo "$bad" | sed 's/^/  /'; failed=1
  fi
  # The repository's other folders stay out (the system's and compiler's
  # own headers are the standard library).
  if grep "^$repo/" "$tmp/files" | grep -v "^$include/meshcast/" > "$tmp/other"; then
    echo "FAIL: $name opens the repository's internal files:"; sed 's/^/  /' "$tmp/other"; failed=1
  fi
done
# The Caster is a small class over a private implementation
# (host/caster_impl.h): the threads, queues, maps and locks it is made of
# are not the user's to compile, and a change to them rebuilds no user.
if bad=$(grep -E '^[[:space:]]*#[[:space:]]*include[[:space:]]*<(thread|deque|map|condition_variable|atomic|mutex)>' \
         "$include/meshcast/caster.h"); then
  echo "FAIL: meshcast/caster.h includes what only its implementation needs:"; echo "$bad" | sed 's/^/  /'; failed=1
fi
[[ $count -gt 0 ]] || { echo "FAIL: no header in $include/meshcast"; exit 1; }
[[ $failed == 0 ]] && echo "public headers: $count compile alone and bring in nothing but the standard library"
exit $failed
