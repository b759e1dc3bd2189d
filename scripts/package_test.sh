#!/usr/bin/env bash
# The package as users meet it:
#  1. the Release build in build/ installed to a scratch prefix; the README's
#     first program (the text between its markers) built with nothing but
#     find_package(meshcast REQUIRED), while every package meshcast's other
#     parts use is disabled (Assimp, Vulkan, CLI11, libpng, JSON,
#     GoogleTest); the reader component, asked for, finds Assimp and reads
#     a mesh file; an unknown component is refused;
#     the README's C example built against the C API through find_package
#     (COMPONENTS c) and through pkg-config (meshcast-c);
#  2. examples/ configured as a separate project against the same prefix,
#     built and run (each checks its own hits and exits non-zero if wrong),
#     and compiled by hand with pkg-config's flags;
#  3. a library-only build (no reader, Vulkan, tools or tests; those
#     packages disabled) installed to a prefix of its own, as a user without
#     root would, and the README's program built against it; the reader
#     component is refused there, naming the option that builds it; the C
#     example of step 1, not rebuilt, runs on this build's libmeshcast_c;
#  4. tests/consumer: meshcast through add_subdirectory with every package
#     but the core's disabled (configuring fails if it reaches for one);
#  5. the Python package: imported from where step 1's cmake --install put
#     it; the README's install lines (a venv, pip install ./python) and its
#     Python examples (a scan, a signed-distance grid) run in that venv.
# The library-only build compiles the scalar walkers alone: what it checks
# is configuration, installation and targets (the installed package of
# step 1 has every instruction set), at a third of the time.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
disabled=()
for pkg in assimp Vulkan VulkanHeaders CLI11 PNG nlohmann_json GTest embree; do
  disabled+=("-DCMAKE_DISABLE_FIND_PACKAGE_$pkg=ON")
done

# The README's first program and a scratch project that asks for
# `components` (a CMake list; empty: none named).
awk '/<!-- first program begins/ {on = 1; next} /<!-- first program ends/ {on = 0} on && !/^```/' README.md > "$tmp/first.cpp"
[[ $(wc -l < "$tmp/first.cpp") -ge 10 ]] || { echo "FAIL: no first program between the README's markers"; exit 1; }
scratch() {  # scratch DIR COMPONENTS TARGETS SOURCE...
  local dir=$1 components=$2 targets=$3
  shift 3
  mkdir -p "$dir"
  cp "$@" "$dir/"
  local find="find_package(meshcast REQUIRED)"
  [[ -n $components ]] && find="find_package(meshcast REQUIRED COMPONENTS $components)"
  {
    echo "cmake_minimum_required(VERSION 3.25)"
    echo "project(scratch LANGUAGES CXX)"
    echo "$find"
    for s in "$@"; do
      echo "add_executable($(basename "${s%.cpp}") $(basename "$s"))"
      echo "target_link_libraries($(basename "${s%.cpp}") PRIVATE $targets)"
    done
  } > "$dir/CMakeLists.txt"
}
run_first() {  # run_first BUILD_DIR LABEL: the program saves a blob in its folder
  (cd "$1" && ./first > first.out) || { echo "FAIL: the README's first program ($2)"; cat "$1/first.out"; exit 1; }
  echo "  $2: the README's first program: $(tail -1 "$1/first.out")"
}

# 1. The whole package, used for its core alone with the other packages gone.
prefix=$tmp/prefix
cmake --install build --prefix "$prefix" >/dev/null
scratch "$tmp/core" "" meshcast::meshcast "$tmp/first.cpp"
cmake --no-warn-unused-cli -S "$tmp/core" -B "$tmp/core/build" -DCMAKE_PREFIX_PATH="$prefix" "${disabled[@]}" >/dev/null
cmake --build "$tmp/core/build" -j"$jobs" >/dev/null
run_first "$tmp/core/build" "find_package, no Assimp, Vulkan, CLI11, libpng"
# The reader component: Assimp is looked for (and refused while disabled).
cat > "$tmp/read_off.cpp" <<'CPP'
#include <meshcast/meshcast.h>
#include <meshcast/read.h>

#include <cstdio>

int main(int argc, char** argv) {
  const meshcast::Mesh mesh = meshcast::read_mesh(argv[1]);
  const std::vector<uint8_t> blob = meshcast::build_blob(mesh, {}, argv[1]);
  const meshcast::Ray down{.org = {0.25f, 0.25f, 1}, .dir = {0, 0, -1}, .tmax = INFINITY};
  meshcast::Hit hit;
  meshcast::BlobView(blob, argv[1]).trace({&down, 1}, {&hit, 1});
  std::printf("%zu triangles read; the ray hits triangle %u\n", mesh.triangles.size(), hit.triangle);
  return mesh.triangles.size() == 2 && hit.triangle == 0 ? 0 : 1;
}
CPP
printf 'OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n' > "$tmp/two.off"
scratch "$tmp/reader" reader meshcast::reader "$tmp/read_off.cpp"
if cmake -S "$tmp/reader" -B "$tmp/reader/off" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_DISABLE_FIND_PACKAGE_assimp=ON \
     > "$tmp/reader.log" 2>&1 || ! grep -q "needs Assimp" "$tmp/reader.log"; then
  echo "FAIL: the reader component was not refused for want of Assimp"; cat "$tmp/reader.log"; exit 1
fi
# Asked for as optional, a reader without Assimp leaves the core found.
mkdir -p "$tmp/optional"
cp "$tmp/first.cpp" "$tmp/optional/"
cat > "$tmp/optional/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(optional LANGUAGES CXX)
find_package(meshcast REQUIRED OPTIONAL_COMPONENTS reader)
if(meshcast_reader_FOUND)
  message(FATAL_ERROR "the reader was found with Assimp disabled")
endif()
add_executable(first first.cpp)
target_link_libraries(first PRIVATE meshcast::meshcast)
CMAKE
cmake --no-warn-unused-cli -S "$tmp/optional" -B "$tmp/optional/build" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_DISABLE_FIND_PACKAGE_assimp=ON > "$tmp/optional.log" 2>&1 ||
  { echo "FAIL: an optional reader without Assimp took the package down"; cat "$tmp/optional.log"; exit 1; }
echo "  find_package OPTIONAL_COMPONENTS reader without Assimp: the core found, the reader not"
cmake -S "$tmp/reader" -B "$tmp/reader/build" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$tmp/reader/build" -j"$jobs" >/dev/null
echo "  find_package COMPONENTS reader: $("$tmp/reader/build/read_off" "$tmp/two.off")"
scratch "$tmp/unknown" "bogus" meshcast::meshcast "$tmp/first.cpp"
if cmake -S "$tmp/unknown" -B "$tmp/unknown/build" -DCMAKE_PREFIX_PATH="$prefix" > "$tmp/unknown.log" 2>&1 ||
   ! grep -q "no component 'bogus'" "$tmp/unknown.log"; then
  echo "FAIL: an unknown component was not refused by name"; cat "$tmp/unknown.log"; exit 1
fi

# The C API: the README's C example built against meshcast::c (find_package
# COMPONENTS c) and by hand with pkg-config's flags, run from the prefix.
awk '/<!-- C example begins/ {on = 1; next} /<!-- C example ends/ {on = 0} on && !/^```/' README.md > "$tmp/floor.c"
[[ $(wc -l < "$tmp/floor.c") -ge 10 ]] || { echo "FAIL: no C example between the README's markers"; exit 1; }
mkdir -p "$tmp/c_api"
cp "$tmp/floor.c" "$tmp/c_api/"
cat > "$tmp/c_api/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(c_api LANGUAGES C CXX)  # CXX: the static library's archives need the C++ runtime
find_package(meshcast REQUIRED COMPONENTS c)
add_executable(floor floor.c)
set_target_properties(floor PROPERTIES C_STANDARD 11)
target_link_libraries(floor PRIVATE meshcast::c m)
add_executable(floor_static floor.c)
set_target_properties(floor_static PROPERTIES C_STANDARD 11)
target_link_libraries(floor_static PRIVATE meshcast::c_static m)
CMAKE
cmake --no-warn-unused-cli -S "$tmp/c_api" -B "$tmp/c_api/build" -DCMAKE_PREFIX_PATH="$prefix" "${disabled[@]}" >/dev/null
cmake --build "$tmp/c_api/build" >/dev/null
c_out=$("$tmp/c_api/build/floor")
grep -q "ray 0: triangle 1 at t 1" <<<"$c_out" && grep -q "ray 1: triangle 4294967295 at t inf" <<<"$c_out" ||
  { echo "FAIL: the README's C example printed:"; echo "$c_out"; exit 1; }
! ldd "$tmp/c_api/build/floor_static" | grep -q libmeshcast_c && [[ $("$tmp/c_api/build/floor_static") == "$c_out" ]] ||
  { echo "FAIL: the C example linked with libmeshcast_c.a answers otherwise, or loads the shared library"; exit 1; }
# shellcheck disable=SC2046
cc -std=c11 -o "$tmp/c_api/floor_pc" "$tmp/floor.c" $(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs meshcast-c) -lm
[[ $(LD_LIBRARY_PATH="$prefix/lib" "$tmp/c_api/floor_pc") == "$c_out" ]] ||
  { echo "FAIL: the C example built with pkg-config answers otherwise"; exit 1; }
echo "  find_package COMPONENTS c (shared and static) and pkg-config meshcast-c: the README's C example: $(head -1 <<<"$c_out")"

# The Python package, as cmake --install put it: PREFIX/lib/python3.X/site-packages.
pyver=$(/usr/bin/python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])')
PYTHONPATH="$prefix/lib/python$pyver/site-packages" /usr/bin/python3 -c '
import meshcast, numpy as np
blob = meshcast.build(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), np.array([[0, 1, 2]]))
hit = blob.cast(np.array([0.25, 0.25, 1.0]), np.array([[0, 0, -1.0]]))
assert hit["triangle"][0] == 0 and hit["t"][0] == 1, hit' ||
  { echo "FAIL: the Python package installed by cmake --install"; exit 1; }
echo "  cmake --install: the Python package imported from PREFIX/lib/python$pyver/site-packages, a ray cast"

# 2. The examples, through CMake and through pkg-config.
cmake -S examples -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/examples" -j"$jobs" >/dev/null
for e in build_and_trace frame_ahead; do echo "  find_package: $("$tmp/examples/$e" | tail -1)"; done
echo "  find_package: $(cd "$tmp" && "$tmp/examples/saved_blob" | tail -1)"
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
g++ -O2 -o "$tmp/pc_build_and_trace" examples/build_and_trace.cpp $(pkg-config --cflags --libs meshcast)
g++ -O2 -o "$tmp/pc_frame_ahead" examples/frame_ahead.cpp $(pkg-config --cflags --libs meshcast-host)
g++ -O2 -o "$tmp/pc_read_off" "$tmp/read_off.cpp" $(pkg-config --cflags --libs meshcast-reader)
for e in build_and_trace frame_ahead; do echo "  pkg-config: $("$tmp/pc_$e" | tail -1)"; done
echo "  pkg-config meshcast-reader: $("$tmp/pc_read_off" "$tmp/two.off")"
unset PKG_CONFIG_PATH

# 3. The library alone, built and installed without root.
home=$tmp/home
# With the Python package: step 5 builds it again through pip with these
# options (and the reader), and where ccache is installed most of its
# compiles are this step's.
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# Absolute paths hashed as they are: a base_dir in a machine's ccache.conf
# would make them relative to each build's folder, and the two builds'
# folders differ.
export CCACHE_BASEDIR=
# Unoptimized (-O0, no debug information): what these builds check is
# configuration, installation and the programs' answers, not speed, and
# the optimizer was most of the stage's time (step 5 passes the same flags
# to pip, for ccache's sake).
unoptimized=(-DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O0)
libonly_options=(-DMESHCAST_ISAS=scalar -DMESHCAST_VULKAN=OFF -DMESHCAST_READER=OFF "${unoptimized[@]}" "${launcher[@]}")
cmake --no-warn-unused-cli -S . -B "$tmp/libonly" "${libonly_options[@]}" \
      -DMESHCAST_TOOLS=OFF -DMESHCAST_TESTS=OFF -DMESHCAST_PYTHON=ON -DPython3_EXECUTABLE=/usr/bin/python3 \
      "${disabled[@]}" >/dev/null
cmake --build "$tmp/libonly" -j"$jobs" > "$tmp/libonly.log" 2>&1 || { cat "$tmp/libonly.log"; exit 1; }
cmake --install "$tmp/libonly" --prefix "$home/.local" >/dev/null
scratch "$tmp/alone" "" meshcast::meshcast "$tmp/first.cpp"
cmake --no-warn-unused-cli -S "$tmp/alone" -B "$tmp/alone/build" -DCMAKE_PREFIX_PATH="$home/.local" "${disabled[@]}" >/dev/null
cmake --build "$tmp/alone/build" -j"$jobs" >/dev/null
run_first "$tmp/alone/build" "a library-only build in ~/.local"
# The C example step 1 built against the first library, run unchanged on
# this rebuilt one (scalar walkers, no Vulkan, -O0): its soname and its
# versioned symbols keep a program built earlier running.
LD_LIBRARY_PATH="$home/.local/lib" ldd "$tmp/c_api/floor_pc" | grep -q "$home/.local/lib/libmeshcast_c.so.2" ||
  { echo "FAIL: the C example did not load the rebuilt libmeshcast_c.so.2"; exit 1; }
[[ $(LD_LIBRARY_PATH="$home/.local/lib" "$tmp/c_api/floor_pc") == "$c_out" ]] ||
  { echo "FAIL: the C example built against the first library answers otherwise on the rebuilt one"; exit 1; }
echo "  the C example built against the first library, run on the rebuilt one: the same answers"
scratch "$tmp/alone_reader" reader meshcast::reader "$tmp/read_off.cpp"
if cmake -S "$tmp/alone_reader" -B "$tmp/alone_reader/build" -DCMAKE_PREFIX_PATH="$home/.local" \
     > "$tmp/alone_reader.log" 2>&1 || ! grep -q "MESHCAST_READER=ON" "$tmp/alone_reader.log"; then
  echo "FAIL: a library-only package did not refuse the reader component by name"; cat "$tmp/alone_reader.log"; exit 1
fi

# 4. The subproject: configured and generated with every other package
# disabled (generating fails if a target the examples link is missing).
# Its compile is step 3's (the same sources, options and walkers).
cmake -S tests/consumer -B "$tmp/consumer" -DMESHCAST_SOURCE="$PWD" -DCMAKE_BUILD_TYPE=Release -DMESHCAST_ISAS=scalar \
      > "$tmp/consumer.log" 2>&1 || { echo "FAIL: meshcast as a subproject"; cat "$tmp/consumer.log"; exit 1; }
echo "  add_subdirectory: configured with only the core's packages; meshcast::meshcast and meshcast::host linked"

# 5. Python: the README's install lines as written (a venv that sees
# Debian's numpy, pip without build isolation, offline), step 3's scalar
# walkers and no Vulkan passed through MESHCAST_CMAKE_ARGS (the reader is
# built: Assimp is installed); then the README's Python examples run in the
# venv on bunny00, their PNGs and the distance grid checked.
awk '/<!-- python install begins/ {on = 1; next} /<!-- python install ends/ {on = 0} on && !/^```/' README.md > "$tmp/install.sh"
awk '/<!-- python example begins/ {on = 1; next} /<!-- python example ends/ {on = 0} on && !/^```/' README.md > "$tmp/scan.py"
awk '/<!-- python distance example begins/ {on = 1; next} /<!-- python distance example ends/ {on = 0} on && !/^```/' \
  README.md > "$tmp/sdf.py"
[[ $(wc -l < "$tmp/install.sh") -ge 3 && $(wc -l < "$tmp/scan.py") -ge 10 && $(wc -l < "$tmp/sdf.py") -ge 10 ]] ||
  { echo "FAIL: no Python install lines or examples between the README's markers"; exit 1; }
# The venv in the scratch folder, not the repository's .venv (a
# developer's own, perhaps); the Debian packages the lines install are
# setup.sh's, installed already.
sed -i "s|\.venv|$tmp/venv|g; /^apt-get /d" "$tmp/install.sh"
MESHCAST_CMAKE_ARGS="-DMESHCAST_ISAS=scalar -DMESHCAST_VULKAN=OFF ${unoptimized[*]} ${launcher[*]}" bash -e "$tmp/install.sh" > "$tmp/pip.log" 2>&1 ||
  { echo "FAIL: the README's Python install lines"; tail -40 "$tmp/pip.log"; exit 1; }
echo "  pip install ./python into a venv: $(tail -1 "$tmp/pip.log")"
mkdir -p "$tmp/scan" && ln -s "$PWD/data" "$tmp/scan/data"
for example in scan sdf; do
  (cd "$tmp/scan" && "$tmp/venv/bin/python" "$tmp/$example.py" > $example.txt 2>&1) ||
    { echo "FAIL: the README's Python example $example.py"; cat "$tmp/scan/$example.txt"; exit 1; }
  echo "  the README's Python example $example.py: $(tail -1 "$tmp/scan/$example.txt")"
done
for png in scan.png bunny_sdf.png; do
  [[ $(head -c 8 "$tmp/scan/out/$png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]] ||
    { echo "FAIL: the README's Python examples wrote no out/$png"; exit 1; }
done
"$tmp/venv/bin/python" -c "import numpy; assert numpy.load('$tmp/scan/out/bunny_sdf.npy').shape == (64, 64, 64)" ||
  { echo "FAIL: the README's distance example saved no 64^3 grid"; exit 1; }
