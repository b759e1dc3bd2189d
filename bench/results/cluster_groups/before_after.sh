#!/usr/bin/env bash
# Runs `meshcast bench peers` with two builds of meshcast in turn (OLD, NEW,
# OLD, NEW, ...), each run timing its layouts beside Embree's builds in
# interleaved rounds, so each binary's ratio to Embree comes from one run.
# Writes OUT/run<k>_<old|new>/peers.csv and the stderr of each run.
#   before_after.sh OLD_MESHCAST NEW_MESHCAST OUT [RUNS] [-- bench peers options]
set -euo pipefail
old=${1:?usage: before_after.sh OLD NEW OUT [RUNS] [-- options]}
new=${2:?usage: before_after.sh OLD NEW OUT [RUNS] [-- options]}
out=${3:?usage: before_after.sh OLD NEW OUT [RUNS] [-- options]}
runs=${4:-2}
shift $(( $# < 4 ? $# : 4 ))
[[ ${1:-} == -- ]] && shift
mkdir -p "$out"
for ((k = 1; k <= runs; ++k)); do
  for side in old new; do
    bin=$old
    [[ $side == new ]] && bin=$new
    dir="$out/run${k}_$side"
    mkdir -p "$dir"
    echo "run $k $side: $bin $*" >&2
    "$bin" bench peers --no-cores --out-dir "$dir" "$@" > "$dir/table.md" 2> "$dir/stderr.txt"
  done
done
