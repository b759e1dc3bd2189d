#!/usr/bin/env bash
# Embree's own traversal counts beside meshcast's, on the same rays:
# inner nodes, leaves and triangles a ray for every mesh, ray kind and
# query of `meshcast bench peers`, in one Markdown table; with meshcast's
# walker on Embree's tree too (the layout laid out over the binary tree
# Embree's builder makes, `LAYOUT:embree`), so a gap in counts splits into
# the tree's share and the walk's.
#
#   bash bench/embree_counts.sh [OUT_DIR]        (default: out/embree_counts)
#
# Builds, in build-embree-counts/ (none of it the library's: Embree is a
# peer, never a dependency):
#  - Embree 3.13.5, the version Debian ships, from its public source with
#    EMBREE_STAT_COUNTERS=ON, triangles only, no tutorials, no ISPC, the
#    SSE2 kernels and the widest this processor runs (AVX2, with AVX's, or
#    AVX-512, as Debian's library picks here), installed to a prefix of its
#    own. Put in
#    front of Debian's with LD_LIBRARY_PATH, it counts for a program linked
#    against Debian's libembree3.so.3, unchanged; it prints its counters
#    when the process ends (one process per mesh and ray kind below: closest
#    hits are its "normal" traversals, rtcOccluded1 its "shadow" ones).
#  - meshcast with MESHCAST_COUNT_TESTS=ON (the command-line program alone),
#    whose `bench peers` walks each set once more counting.
# Environment: EMBREE_GIT (the repository to clone the tag from; default
# GitHub's), MESHES, KINDS, QUERIES, LAYOUT, RAYS (as `bench peers` takes them).
#
# What the columns count. meshcast: inner nodes whose children a walk
# tested together (8 boxes a node in the oct trees), leaves tested, and
# triangle lanes tested. Embree (its stat counters, "code" counts a
# traversal): inner nodes entered whose children it tested, leaves, and
# primitive blocks tested (a Triangle4 block: up to four triangles tested
# together, so four times the blocks bounds its triangles from above).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/embree_counts}
jobs=$(nproc)
tag=v3.13.5
meshes=${MESHES:-data/bunny00.off,data/armadillo.off,data/refined_elephant.off,data/ChineseDragon-10kv.off,terrain_2M,city_1M}
kinds=${KINDS:-long,probe,radial,segment}
queries=${QUERIES:-closest,any}
layout=${LAYOUT:-OctTreeCompressed/ClusterBitPackSOA8}
rays=${RAYS:-10000}
work=$PWD/build-embree-counts
prefix=$work/prefix
source scripts/isa.sh
widest=$(widest_isa)

# 1. Embree, counting.
if [[ ! -f $prefix/lib/libembree3.so.3 ]]; then
  if [[ ! -f $work/src/CMakeLists.txt ]]; then
    rm -rf "$work/src"
    git clone --quiet --branch "$tag" --depth 1 "${EMBREE_GIT:-https://github.com/embree/embree.git}" "$work/src"
  fi
  version=$(awk '/SET\(EMBREE_VERSION_(MAJOR|MINOR|PATCH)/ {gsub(/\)/, "", $2); v = v (v ? "." : "") $2} END {print v}' \
            "$work/src/CMakeLists.txt")
  [[ $version == "${tag#v}" ]] || { echo "embree_counts: $work/src is Embree $version, not ${tag#v}"; exit 1; }
  geometries=()
  for g in QUAD CURVE SUBDIVISION USER INSTANCE GRID POINT; do geometries+=("-DEMBREE_GEOMETRY_$g=OFF"); done
  # AVX's kernels with AVX2's: the SSE2 library's 8-wide factory links to
  # the BVHN<8> they hold (SSE2 and AVX2 alone fail to link).
  isas=(-DEMBREE_MAX_ISA=NONE -DEMBREE_ISA_SSE2=ON -DEMBREE_ISA_SSE42=OFF
        "-DEMBREE_ISA_AVX=$([[ $widest == avx2 ]] && echo ON || echo OFF)"
        "-DEMBREE_ISA_AVX2=$([[ $widest == avx2 ]] && echo ON || echo OFF)"
        "-DEMBREE_ISA_AVX512=$([[ $widest == avx512 ]] && echo ON || echo OFF)")
  cmake -S "$work/src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCMAKE_INSTALL_PREFIX=$prefix" \
        -DEMBREE_STAT_COUNTERS=ON -DEMBREE_TUTORIALS=OFF -DEMBREE_ISPC_SUPPORT=OFF -DEMBREE_TESTING_INTENSITY=0 \
        -DEMBREE_TASKING_SYSTEM=TBB "${geometries[@]}" "${isas[@]}" > "$work/embree-cmake.log" 2>&1 ||
    { tail -30 "$work/embree-cmake.log"; exit 1; }
  cmake --build "$work/build" -j"$jobs" > "$work/embree-build.log" 2>&1 || { tail -30 "$work/embree-build.log"; exit 1; }
  cmake --install "$work/build" > /dev/null
fi

# 2. meshcast, counting: the command-line program alone.
cmake -S . -B "$work/meshcast" -G Ninja -DCMAKE_BUILD_TYPE=Release -DMESHCAST_COUNT_TESTS=ON -DMESHCAST_TESTS=OFF \
      -DMESHCAST_PYTHON=OFF -DMESHCAST_C_API=OFF -DMESHCAST_VULKAN=ON "-DMESHCAST_ISAS=$widest" \
      > "$work/meshcast-cmake.log" 2>&1 ||
  { tail -30 "$work/meshcast-cmake.log"; exit 1; }
cmake --build "$work/meshcast" -j"$jobs" --target meshcast > "$work/meshcast-build.log" 2>&1 ||
  { tail -30 "$work/meshcast-build.log"; exit 1; }

# 3. One process per mesh and ray kind: Embree's counters are the process's.
# (The counts table's rows have 7 columns, the timing table's 11.)
mkdir -p "$out"
table=$out/counts.md
{
  echo "$tag with EMBREE_STAT_COUNTERS beside meshcast's counting build ($layout), $rays rays a set, one ray at a time"
  echo
  echo "Each count a ray: meshcast's walker on its own tree / on Embree's tree (the same layout over the binary tree of"
  echo "Embree's builder) / Embree itself"
  echo
  echo "| mesh | rays | query | nodes | leaves | triangles (meshcast: lanes; Embree: blocks of up to 4) |"
  echo "|---|---|---|---:|---:|---:|"
} > "$table"
for mesh in ${meshes//,/ }; do
  name=$(basename "$mesh"); name=${name%.*}
  for kind in ${kinds//,/ }; do
    log=$out/$name-$kind.txt
    LD_LIBRARY_PATH="$prefix/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$work/meshcast/bin/meshcast" bench peers \
      --meshes "$mesh" --kinds "$kind" --queries "$queries" --layouts "$layout,$layout:embree" --peers default --no-cores \
      --no-packets --no-build-times --rounds 1 --rays "$rays" --out-dir "$out/peers" > "$log" 2> "$out/$name-$kind.err"
    grep -q -- "--------- PER TRAVERSAL ---------" "$log" ||
      { echo "embree_counts: no counters from Embree in $log (was $prefix/lib's library loaded?)"; exit 1; }
    # Embree's: the per-traversal block, normal (closest) then shadow (any).
    embree() {  # embree normal|shadow nodes|leaves|prims
      awk -v trav="#$1_travs" -v what="#$2" '
        /PER TRAVERSAL/ {on = 1; next}
        on && $1 == trav {inside = 1; next}
        on && inside && /^  #/ {inside = 0}
        on && inside && $1 == what {gsub(/,/, "", $3); print $3; exit}' "$log"
    }
    for query in ${queries//,/ }; do
      traversal=$([[ $query == any ]] && echo shadow || echo normal)
      counts() {  # counts LAYOUT: its nodes, leaves and lanes
        awk -F' *[|] *' -v m="$name" -v k="$kind" -v q="$query" -v l="$1" \
            '$2 == m && $3 == k && $4 == q && $5 == l && NF == 9 {print $6, $7, $8; exit}' "$log"
      }
      own=$(counts "$layout") swapped=$(counts "$layout:embree")
      [[ -n $own && -n $swapped ]] || { echo "embree_counts: no meshcast counts for $name $kind $query in $log"; exit 1; }
      read -r nodes leaves lanes <<< "$own"
      read -r swapped_nodes swapped_leaves swapped_lanes <<< "$swapped"
      printf '| %s | %s | %s | %s / %s / %s | %s / %s / %s | %s / %s / %s |\n' "$name" "$kind" "$query" \
        "$nodes" "$swapped_nodes" "$(embree "$traversal" nodes)" "$leaves" "$swapped_leaves" "$(embree "$traversal" leaves)" \
        "$lanes" "$swapped_lanes" "$(embree "$traversal" prims)"
    done >> "$table"
  done
done
cat "$table"
