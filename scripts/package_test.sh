#!/usr/bin/env bash
# The package as users meet it, from the Release build in build/:
#  1. `cmake --install` into a scratch prefix; examples/ configured as a
#     separate project against it (find_package(meshcast CONFIG REQUIRED)),
#     built and run (each checks its own hits and exits non-zero if wrong);
#  2. the same examples compiled by hand with pkg-config's flags, and run;
#  3. tests/consumer: meshcast through add_subdirectory with every package
#     but the core's disabled (configuring fails if it reaches for one),
#     built and run.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix

cmake --install build --prefix "$prefix" >/dev/null
cmake -S examples -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/examples" -j"$jobs" >/dev/null
for e in build_and_trace frame_ahead; do echo "  find_package: $("$tmp/examples/$e" | tail -1)"; done
echo "  find_package: $(cd "$tmp" && "$tmp/examples/saved_blob" | tail -1)"

export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
g++ -O2 -o "$tmp/pc_build_and_trace" examples/build_and_trace.cpp $(pkg-config --cflags --libs meshcast)
g++ -O2 -o "$tmp/pc_frame_ahead" examples/frame_ahead.cpp $(pkg-config --cflags --libs meshcast-host)
for e in build_and_trace frame_ahead; do echo "  pkg-config: $("$tmp/pc_$e" | tail -1)"; done

# The subproject with the scalar walkers alone: what is checked here is the
# subproject's configuration and targets (the installed package above has
# every instruction set), and one set compiles in a third of the time.
cmake -S tests/consumer -B "$tmp/consumer" -DMESHCAST_SOURCE="$PWD" -DCMAKE_BUILD_TYPE=Release -DMESHCAST_ISAS=scalar >/dev/null
cmake --build "$tmp/consumer" -j"$jobs" >/dev/null
for e in build_and_trace frame_ahead; do echo "  add_subdirectory: $("$tmp/consumer/$e" | tail -1)"; done
