#!/usr/bin/env bash
# The meshcast program end to end: every subcommand, its JSON, and its errors
# (clear message naming the input, non-zero exit, no crash).
# Usage: cli_test.sh MESHCAST DATA [all|benches|rest]: the benchmarks'
# smoke runs (most of the time) apart from the rest, so CTest runs the two
# halves side by side.
set -uo pipefail
meshcast=$1
data=$2
part=${3:-all}
[[ $part == all || $part == benches || $part == rest ]] || { echo "cli_test.sh: part '$part' is not all, benches or rest"; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
passes=0
check() {  # check NAME EXPECTED_EXIT PATTERN -- command...
  local name=$1 want=$2 pattern=$3
  shift 4
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [[ $rc -ne $want ]] || ! grep -qE -- "$pattern" <<<"$out"; then
    echo "FAIL $name: exit $rc (want $want), output:"
    echo "$out" | head -20
    failures=$((failures + 1))
  else
    echo "ok   $name"
    passes=$((passes + 1))
  fi
}

mesh=$data/bunny00.off
[[ -f $mesh ]] || mesh=$work/tiny.off
if [[ ! -f $data/bunny00.off ]]; then
  printf 'OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n3 0 1 2\n3 1 3 2\n' >"$mesh"
fi

printf 'OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n' >"$work/tiny_square.off"
# The checks that build every layout (the automatic choice, bench error and
# bench auto) on a mesh of a quarter of bunny00's triangles: on bunny00 they
# took two thirds of this half's time.
small_mesh=$data/ChineseDragon-10kv.off
[[ -f $small_mesh ]] || small_mesh=$mesh
# A binary STL of 2 facets (84 + 100 bytes), for the truncated-STL check.
{ head -c 80 /dev/zero; printf '\x02\x00\x00\x00'; head -c 100 /dev/zero; } >"$work/tiny_bin.stl"
# Most of the benchmarks, each on the fewest rays and the smaller mesh (they
# need only a mesh; their builds of every layout on bunny00 were most of
# this half's time).
benches() {
  check bench-encodings 0 "csv: .*encodings.csv" -- "$meshcast" bench encodings "$small_mesh" --rays 8 --repeat 1 --out-dir "$work"
  check bench-trees 0 "AABBTreePNS/Float3" -- "$meshcast" bench trees "$small_mesh" --rays 8 --repeat 1 --out-dir "$work"
  check bench-splitters 0 "FixedLeafSize" -- "$meshcast" bench splitters "$small_mesh" --rays 8 --repeat 1 --out-dir "$work"
  check bench-trees-all 0 "StacklessLBVH left first" -- "$meshcast" bench trees "$small_mesh" --rays 8 --repeat 1 --out-dir "$work"
  check bench-order 0 "BreadthFirstTrianglesLast" -- "$meshcast" bench order "$small_mesh" --rays 8 --repeat 1 --out-dir "$work"
  check bench-combos 0 "SKDTree/CompressedStrip" -- "$meshcast" bench combos "$small_mesh" --rays 8 --repeat 1 --only SKDTree,OctTree --out-dir "$work"
  # bunny00's cases alone (the 2M terrain's build took 35 s of this part), or the terrain without the data.
  local pairing_case=bunny00
  [[ -f $data/bunny00.off ]] || pairing_case=terrain_2M
  check bench-pairing 0 "bunny00 rotated 45, pairs baked|terrain_2M" -- "$meshcast" bench pairing --data "$data" --rays 8 --repeat 1 --only "$pairing_case" --out-dir "$work"
  check bench-pairing-none 2 "no case is named by --only" -- "$meshcast" bench pairing --data "$data" --only nothing --out-dir "$work"
  check bench-latency 0 "crossover \\(automatic backend" -- "$meshcast" bench latency "$small_mesh" --frame-ms 1 --out-dir "$work"
  check bench-robustness 0 "leaks plain" -- "$meshcast" bench robustness "$small_mesh" --rays 8 --repeat 1
  check bench-offset 0 "150 units at 30000" -- "$meshcast" bench offset "$small_mesh" --rays 8 --repeat 1
  # Embree default alone, and the layout over the tree Embree's builder makes (Debian's Embree: setup.sh installs it).
  check bench-peers-embree-tree 0 "long \\| closest \\| OctTreeCompressed/ClusterBitPackSOA8:embree \\| " -- "$meshcast" bench peers \
    --meshes "$small_mesh" --layouts OctTreeCompressed/ClusterBitPackSOA8,OctTreeCompressed/ClusterBitPackSOA8:embree \
    --peers default --kinds long --rays 100 --rounds 1 --no-cores --no-packets --out-dir "$work"
  check bench-peers-unknown-peer 2 '"fast" is not an Embree build: default, high, robust or compact' -- "$meshcast" bench peers \
    --meshes "$small_mesh" --peers default,fast --out-dir "$work"
  check bench-peers-unknown-source 2 "after ':' is embree or nothing" -- "$meshcast" bench peers --meshes "$small_mesh" \
    --layouts OctTreeCompressed/ClusterBitPackSOA8:kd --kinds long --rays 100 --rounds 1 --no-cores --out-dir "$work"
}
if [[ $part == benches ]]; then
  benches
  echo "$passes passed, $failures failed"
  exit $((failures > 0))
fi
[[ $part == all ]] && benches
# Two more, in this half: the halves take about as long.
check bench-error 0 "plots: " -- "$meshcast" bench error "$small_mesh" --rays 8 --repeat 1 --out-dir "$work"
check bench-auto 0 "choices more than 10% from the best" -- "$meshcast" bench auto "$small_mesh" --rays 8 --repeat 1 --out-dir "$work"
check rays 0 "rays ->" -- "$meshcast" rays "$mesh" --kind long --count 500 --seed 3 --out "$work/r.rays"
check rays-kind 2 "kind" -- "$meshcast" rays "$mesh" --kind sideways --count 5 --out "$work/x.rays"
check build 0 "bytes/triangle" -- "$meshcast" build "$mesh" --layout quadtree/float3soa4 --leaf 4 --out "$work/m.blob"
check info-blob 0 "QuadTree/Float3SOA4, leaf size 4" -- "$meshcast" info "$work/m.blob"
check info-json 0 '"bytes_per_triangle":\{"header"' -- "$meshcast" info "$mesh" --json
check trace 0 "ns/ray" -- "$meshcast" trace "$work/m.blob" --rays "$work/r.rays" --out "$work/h.hits" --repeat 2
check trace-json 0 '"ns_per_ray":' -- "$meshcast" trace "$mesh" --layout AABBTree/Float3 --rays "$work/r.rays" --out "$work/h2.hits" --json
check trace-any 0 '"query":"any"' -- "$meshcast" trace "$mesh" --layout OctTreeCompressed/ClusterBitPackSOA8 --query any --rays "$work/r.rays" --out "$work/ha.hits" --json
# --threads: the batch split over a pool gives the single thread's hits, byte for byte.
check trace-threads 0 '"device":"CPU, 2 threads"' -- "$meshcast" trace "$work/m.blob" --rays "$work/r.rays" --out "$work/h-t2.hits" --repeat 1 --threads 2 --json
cmp "$work/h.hits" "$work/h-t2.hits" || { echo "FAIL: trace --threads 2 answered other hits than one thread"; exit 1; }
check trace-threads-all 0 '"query":"all"' -- "$meshcast" trace "$work/m.blob" --query all --max-hits 4 --rays "$work/r.rays" --out "$work/h-t0.hitc" --repeat 1 --threads 0 --json
"$meshcast" trace "$work/m.blob" --query all --max-hits 4 --rays "$work/r.rays" --out "$work/h-t1.hitc" --repeat 1 >/dev/null
cmp "$work/h-t1.hitc" "$work/h-t0.hitc" || { echo "FAIL: trace --query all --threads 0 answered other rows than one thread"; exit 1; }
check trace-threads-vulkan 2 "threads is for --backend cpu" -- "$meshcast" trace "$work/m.blob" --rays "$work/r.rays" --out "$work/hx.hits" --threads 2 --backend vulkan
# generate: the benchmarks' generated meshes as OFF, read back as the same mesh (the same rays).
check generate 0 "131072 triangles" -- "$meshcast" generate terrain_66k --out "$work/terrain.off"
"$meshcast" rays "$work/terrain.off" --kind probe --count 300 --out "$work/tf.rays" >/dev/null
"$meshcast" rays terrain_66k --kind probe --count 300 --out "$work/tg.rays" >/dev/null
cmp "$work/tf.rays" "$work/tg.rays" || { echo "FAIL: the generated OFF did not read back as the generated mesh"; exit 1; }
check generate-unknown 2 "terrain_2M" -- "$meshcast" generate mountain --out "$work/x.off"
# A generated mesh's name mistyped is answered with the names, nearest
# first, by every command that takes a mesh (as a mistyped layout is); a
# path that is no file is not (it is no name).
for command in "rays:--out $work/x.rays" "info:" "build:--out $work/x.blob" "trace:--rays $work/r.rays --out $work/x.hits" \
               "render:--png $work/x.png" "demo:" "bench encodings:--out-dir $work" "bench latency:--out-dir $work"; do
  IFS=: read -r name options <<<"$command"
  # shellcheck disable=SC2086 # the command's words and options split
  check "mistyped-generated-${name// /-}" 2 "terrain_66K: cannot open the file .*; nor is it a generated mesh: did you mean terrain_66k, terrain_2M or terrain_20M\?" -- "$meshcast" $name terrain_66K $options
done
check mistyped-generated-generate 2 '"terrain_66K" is not a generated mesh; did you mean terrain_66k, terrain_2M or terrain_20M\?' -- "$meshcast" generate terrain_66K --out "$work/x.off"
check missing-path-no-names 2 "nope.off: cannot open the file \([^)]*\)$" -- "$meshcast" info "$work/nope.off"
# ... and the names offered are taken by each of them.
check generated-info 0 '"triangles":131072' -- "$meshcast" info terrain_66k --json
check generated-trace 0 "^terrain_66k: OctTreeCompressed/ClusterBitPackSOA8" -- "$meshcast" trace terrain_66k --rays "$work/tg.rays" --out "$work/tg.hits" --repeat 1
printf '{"meshes": {"t": "terrain_66k"}, "instances": [{"mesh": "t"}]}' >"$work/generated.json"
check generated-scene 0 "1 instances" -- "$meshcast" render "$work/generated.json" --png "$work/g.png" --width 16 --height 16
check trace-query-unknown 2 "query" -- "$meshcast" trace "$mesh" --query nearest --rays "$work/r.rays" --out "$work/hx.hits"
check trace-all 0 '"query":"all","cull":"back"' -- "$meshcast" trace "$mesh" --layout AABBTree/Float3 --query all --max-hits 4 --cull back --rays "$work/r.rays" --out "$work/hn.hitc" --json
# HITC: magic, 500 rays, N, 500 counts, then the kept records alone: 12 + 500
# * 4 + 8 * sum(min(count, N)) bytes.
hitc_size() {  # hitc_size FILE RAYS N: the size the counts call for
  od -An -tu4 -v -j12 -N$((4 * $2)) "$1" | tr -s ' ' '\n' | awk -v rays="$2" -v n="$3" \
    'NF { kept += ($1 < n ? $1 : n) } END { print 12 + 4 * rays + 8 * kept }'
}
if [[ $(head -c 4 "$work/hn.hitc") != HITC || $(stat -c %s "$work/hn.hitc") -ne $(hitc_size "$work/hn.hitc" 500 4) ]]; then
  echo "FAIL trace-all: the HITC file's magic or size"; failures=$((failures + 1))
fi
# At the most hits a ray keeps, the file follows the hits found: the same
# counts as rows of 4, every hit kept, far below the 16 MB that 500 rows of
# 4096 records would take.
out=$("$meshcast" trace "$mesh" --layout AABBTree/Float3 --query all --max-hits 4096 --cull back --rays "$work/r.rays" --out "$work/hl.hitc" --json --repeat 1 2>&1)
rc=$?
every_hit=$(grep -oE '"every_hit":[0-9]+' <<<"$out" | cut -d: -f2)
if [[ $rc -ne 0 || -z $every_hit || $(stat -c %s "$work/hl.hitc") -ne $((12 + 500 * 4 + 8 * every_hit)) ]] ||
   ! cmp -s <(head -c 2012 "$work/hn.hitc" | tail -c 2000) <(head -c 2012 "$work/hl.hitc" | tail -c 2000); then
  echo "FAIL trace-all-limit: exit $rc; the file's size does not follow the ${every_hit:-?} hits found, or its counts differ from rows of 4"
  echo "$out" | head -20
  failures=$((failures + 1))
else
  echo "ok   trace-all-limit"
  passes=$((passes + 1))
fi
# Scenes: a scene file of the mesh and the blob, one instance mirrored and
# far away, another hidden; RAYS rays in, a HITI file out (12 + 500 * 12 bytes).
cat >"$work/level.json" <<JSON
{"meshes": {"mesh": "$mesh", "blob": "m.blob"},
 "instances": [{"mesh": "mesh"},
               {"mesh": "blob", "rotation_scale": [-1, 0, 0, 0, 2, 0, 0, 0, 1], "translation": [1e7, 0, 0], "mask": 2},
               {"mesh": "blob", "translation": [0.5, 0, 0], "enabled": false}]}
JSON
check trace-scene 0 '"instances":3.*"rays":500' -- "$meshcast" trace "$work/level.json" --rays "$work/r.rays" --out "$work/h.hiti" --query any --cull back --json
if [[ $(head -c 4 "$work/h.hiti") != HITI || $(stat -c %s "$work/h.hiti") -ne 6008 ]]; then
  echo "FAIL trace-scene: the HITI file's magic or size"; failures=$((failures + 1))
fi
# One instance where the mesh stands: the scene's closest hits are the
# mesh's own (the ray reaches the instance's frame unrounded): the same t
# bits and triangles as `trace` on the mesh, instance 0 wherever it hits.
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh"}]}' "$mesh" >"$work/one.json"
check trace-scene-one 0 "500 rays" -- "$meshcast" trace "$work/one.json" --layout AABBTree/Float3 --rays "$work/r.rays" --out "$work/one.hiti"
check trace-mesh-one 0 "500 rays" -- "$meshcast" trace "$mesh" --layout AABBTree/Float3 --rays "$work/r.rays" --out "$work/one.hits"
if ! diff <(od -An -tu4 -v -w8 -j8 "$work/one.hits" | awk '{print $1, ($2 == 4294967295 ? "miss" : 0), $2}') \
          <(od -An -tu4 -v -w12 -j8 "$work/one.hiti" | awk '{print $1, ($2 == 4294967295 ? "miss" : $2), $3}') >/dev/null; then
  echo "FAIL trace-scene-one: the scene's hits differ from the mesh's"; failures=$((failures + 1))
fi
# --t-min T on every ray read, T the median first-hit t: a ray whose first
# hit lies past T keeps it (t and triangle bit for bit), one whose first
# hit lies before T finds a later one or misses, and no hit lies before T
# (within od's printed digits: 1e-4 of T either way); the scene of that
# one instance answers as the mesh. A negative or NaN T is refused.
tmin=$(od -An -tf4 -v -w8 -j8 "$work/one.hits" | awk '$1 != "inf" {print $1}' | sort -g | awk '{t[NR] = $1} END {print t[int((NR + 1) / 2)]}')
check trace-t-min 0 "\"t_min\":[0-9]" -- "$meshcast" trace "$mesh" --layout AABBTree/Float3 --t-min "$tmin" --rays "$work/r.rays" --out "$work/tmin.hits" --json
if ! paste <(od -An -tf4 -tu4 -v -w8 -j8 "$work/one.hits" | paste - - ) <(od -An -tf4 -tu4 -v -w8 -j8 "$work/tmin.hits" | paste - - ) |
     awk -v T="$tmin" '
       # Per ray: t, triangle (as floats), t bits, triangle; before, then with --t-min.
       { t0 = $1; b0 = $3; tri0 = $4; t1 = $5; b1 = $7; tri1 = $8
         if (tri1 != 4294967295 && t1 < T * 0.9999) bad++
         if (tri0 == 4294967295) next
         if (t0 > T * 1.0001 && (b1 != b0 || tri1 != tri0)) bad++
         if (t0 < T * 0.9999) { moved++; if (tri1 != 4294967295 && t1 <= t0) bad++ } }
       END { exit !(bad == 0 && moved > 0) }'; then
  echo "FAIL trace-t-min: hits before --t-min, or first hits past it changed, or no ray skipped its first hit"; failures=$((failures + 1))
fi
check trace-scene-t-min 0 "500 rays" -- "$meshcast" trace "$work/one.json" --layout AABBTree/Float3 --t-min "$tmin" --rays "$work/r.rays" --out "$work/tmin.hiti"
if ! diff <(od -An -tu4 -v -w8 -j8 "$work/tmin.hits" | awk '{print $1, ($2 == 4294967295 ? "miss" : 0), $2}') \
          <(od -An -tu4 -v -w12 -j8 "$work/tmin.hiti" | awk '{print $1, ($2 == 4294967295 ? "miss" : $2), $3}') >/dev/null; then
  echo "FAIL trace-scene-t-min: the scene's hits with --t-min differ from the mesh's"; failures=$((failures + 1))
fi
check trace-t-min-negative 2 "--t-min: -0.5 is not in 0\.\.3\.40282347e\+38" -- "$meshcast" trace "$mesh" --t-min -0.5 --rays "$work/r.rays" --out "$work/hx.hits"
check trace-t-min-nan 2 '--t-min: "nan" is not a number' -- "$meshcast" trace "$mesh" --t-min nan --rays "$work/r.rays" --out "$work/hx.hits"
# Every refusal names the value as it was written, not as it was read: a
# --t-min past a float's range is not "inf", one nearer 0 than a float
# holds is not taken as 0.
check trace-t-min-huge 2 "--t-min: 1e39 is not in 0\.\.3\.40282347e\+38" -- "$meshcast" trace "$mesh" --t-min 1e39 --rays "$work/r.rays" --out "$work/hx.hits"
check trace-t-min-huge-negative 2 "--t-min: -1e39 is not in" -- "$meshcast" trace "$mesh" --t-min -1e39 --rays "$work/r.rays" --out "$work/hx.hits"
check trace-t-min-tiny 2 "--t-min: 1e-50 is nearer 0 than the least float above 0 \(1\.40129846e-45\)" -- "$meshcast" trace "$mesh" --t-min 1e-50 --rays "$work/r.rays" --out "$work/hx.hits"
check trace-t-min-scene-huge 2 "--t-min: 1e39 is not in" -- "$meshcast" trace "$work/one.json" --t-min 1e39 --rays "$work/r.rays" --out "$work/hx.hiti"
# The Vulkan scene method (lavapipe in CI) on the same scene, culled: the
# CPU's t bits and instances (the triangle may be the other one of an edge
# both meet at the same t, as gpu_test allows).
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh"}, {"mesh": "mesh", "rotation_scale": [-1, 0, 0, 0, 2, 0, 0, 0, 1], "translation": [0.05, 0, 0]}]}' "$mesh" >"$work/two.json"
check trace-scene-cpu 0 "500 rays" -- "$meshcast" trace "$work/two.json" --layout OctTreeCompressed/ClusterBitPackSOA8 --cull back --rays "$work/r.rays" --out "$work/two-cpu.hiti"
check trace-scene-vulkan 0 '"device":"[^C]' -- "$meshcast" trace "$work/two.json" --backend vulkan --cull back --rays "$work/r.rays" --out "$work/two-gpu.hiti" --json
if ! diff <(od -An -tu4 -v -w12 -j8 "$work/two-cpu.hiti" | awk '{print $1, $2}') \
          <(od -An -tu4 -v -w12 -j8 "$work/two-gpu.hiti" | awk '{print $1, $2}') >/dev/null; then
  echo "FAIL trace-scene-vulkan: the Vulkan scene method's hits differ from the CPU's"; failures=$((failures + 1))
fi
# flip_facing: false is the default, true turns the instance's faces, so
# culling the back faces of a flipped instance answers as culling the front
# faces of a plain one (bit for bit), and not as culling its back faces.
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh", "flip_facing": false}]}' "$mesh" >"$work/facing.json"
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh", "flip_facing": true}]}' "$mesh" >"$work/flipped.json"
for f in one:back:one-back facing:back:facing-back one:front:one-front flipped:back:flipped-back; do
  IFS=: read -r scene cull out <<<"$f"
  check "trace-scene-$out" 0 "500 rays" -- "$meshcast" trace "$work/$scene.json" --layout AABBTree/Float3 --cull "$cull" --rays "$work/r.rays" --out "$work/$out.hiti"
done
if ! cmp -s "$work/one-back.hiti" "$work/facing-back.hiti"; then
  echo "FAIL scene-flip-facing-default: \"flip_facing\": false answers otherwise than no key"; failures=$((failures + 1))
elif ! cmp -s "$work/flipped-back.hiti" "$work/one-front.hiti" || cmp -s "$work/flipped-back.hiti" "$work/one-back.hiti"; then
  echo "FAIL scene-flip-facing: a flipped instance's back faces are not a plain one's front faces"; failures=$((failures + 1))
else
  echo "ok   scene-flip-facing"; passes=$((passes + 1))
fi
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh", "flip_facing": 1}]}' "$mesh" >"$work/flip_number.json"
check scene-flip-facing-not-boolean 2 'flip_number.json: instances\[0\].flip_facing is the number 1, not true or false' -- "$meshcast" trace "$work/flip_number.json" --rays "$work/r.rays" --out "$work/x.hiti"
check render-scene 0 "3 instances of 2 meshes.*scene.png" -- "$meshcast" render "$work/level.json" --png "$work/scene.png" --width 64 --height 48
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh", "translation": [1, 2]}]}' "$mesh" >"$work/short.json"
check scene-short-translation 2 "short.json: instances\[0\].translation is an array of 2, not an array of 3 numbers" -- "$meshcast" trace "$work/short.json" --rays "$work/r.rays" --out "$work/x.hiti"
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh", "rotation_scale": [1,0,0, 0,0,0, 0,0,1]}]}' "$mesh" >"$work/flat.json"
check scene-flat 2 "flat.json: instances\[0\]: .*not invertible" -- "$meshcast" trace "$work/flat.json" --rays "$work/r.rays" --out "$work/x.hiti"
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "rock"}]}' "$mesh" >"$work/rock.json"
check scene-unknown-mesh 2 'rock.json: instances\[0\].mesh: "rock" is not in "meshes"' -- "$meshcast" trace "$work/rock.json" --rays "$work/r.rays" --out "$work/x.hiti"
printf '{"meshes": {"mesh": "%s"}, "instances": [{"mesh": "mesh", "translaton": [1, 2, 3]}]}' "$mesh" >"$work/typo.json"
check scene-unknown-key 2 'typo.json: instances.0.: "translaton" is not an instance.s key' -- "$meshcast" trace "$work/typo.json" --rays "$work/r.rays" --out "$work/x.hiti"
printf '{"meshes": {"mesh": "%s/none.off"}, "instances": []}' "$work" >"$work/gone.json"
check scene-missing-mesh 2 'gone.json: meshes.mesh: .*none.off' -- "$meshcast" trace "$work/gone.json" --rays "$work/r.rays" --out "$work/x.hiti"
printf '{"meshes": {' >"$work/cut.json"
check scene-not-json 2 "cut.json: not JSON" -- "$meshcast" trace "$work/cut.json" --rays "$work/r.rays" --out "$work/x.hiti"
# Hostile scene files: a value nested 100,000 deep (a message that dumped it
# overran the stack), a 5 MB name (the message shows 64 bytes of it), a key
# twice, a NUL in a path, numbers beyond %f's reach.
python3 - "$mesh" "$work" <<'PY'
import json, sys
mesh, work = sys.argv[1], sys.argv[2]
def scene(name, instance, meshes=None):
    text = json.dumps({"meshes": meshes or {"mesh": mesh}, "instances": [instance]})
    open(f"{work}/{name}.json", "w").write(text)
deep = "[" * 100000 + "]" * 100000
open(f"{work}/deep.json", "w").write('{"meshes": {"mesh": %s}, "instances": [{"mesh": "mesh", "translation": [0, 0, %s]}]}'
                                     % (json.dumps(mesh), deep))
scene("long", {"mesh": "x" * 5000000})
scene("long_path", {"mesh": "mesh"}, {"mesh": "y" * 5000000})
open(f"{work}/twice.json", "w").write('{"meshes": {"mesh": %s}, "instances": [{"mesh": "mesh", "mask": 1, "mask": 2}]}'
                                      % json.dumps(mesh))
scene("nul", {"mesh": "mesh"}, {"mesh": "a\u0000b.off"})
scene("tiny_det", {"mesh": "mesh", "rotation_scale": [1e-20, 0, 0, 0, 1e-20, 0, 0, 0, 1e-20]})
scene("huge", {"mesh": "mesh", "translation": [1e300, 0, 0]})
PY
check scene-deep 2 'deep.json: instances\[0\].translation holds an array of 1, not a number' -- "$meshcast" trace "$work/deep.json" --rays "$work/r.rays" --out "$work/x.hiti"
check scene-long-name 2 'long.json: instances\[0\].mesh: "x{64}\.\.\. \(5000000 bytes\)" is not in' -- "$meshcast" trace "$work/long.json" --rays "$work/r.rays" --out "$work/x.hiti"
if (( $("$meshcast" trace "$work/long.json" --rays "$work/r.rays" --out "$work/x.hiti" 2>&1 | wc -c) > 1000 )); then
  echo "FAIL scene-long-name: the message echoes the name whole"; failures=$((failures + 1))
fi
check scene-long-path 2 'long_path.json: meshes.mesh: the file name "y{64}\.\.\. \(5000000 bytes\)" is longer than a path may be' -- "$meshcast" trace "$work/long_path.json" --rays "$work/r.rays" --out "$work/x.hiti"
check scene-key-twice 2 'twice.json: the key "mask" appears twice in one object' -- "$meshcast" trace "$work/twice.json" --rays "$work/r.rays" --out "$work/x.hiti"
check scene-nul-path 2 'nul.json: meshes.mesh: the file name "a\\x00b.off" holds a NUL character' -- "$meshcast" trace "$work/nul.json" --rays "$work/r.rays" --out "$work/x.hiti"
check scene-tiny-determinant 2 'tiny_det.json: instances\[0\]: .*determinant 9\.9999[0-9]*e-61\)' -- "$meshcast" trace "$work/tiny_det.json" --rays "$work/r.rays" --out "$work/x.hiti"
check scene-huge-translation 2 'huge.json: instances\[0\]: .*translation\[0\] 1e\+300 is not finite or beyond 2\^100' -- "$meshcast" trace "$work/huge.json" --rays "$work/r.rays" --out "$work/x.hiti"
# Options given where they mean nothing, numbers that are not integers, a
# rays file of the other kind.
check trace-max-hits-closest 2 "max-hits is for --query all" -- "$meshcast" trace "$mesh" --max-hits 8 --rays "$work/r.rays" --out "$work/hx.hits"
check trace-max-hits-scene 2 "max-hits is for --query all" -- "$meshcast" trace "$work/one.json" --query any --max-hits 8 --rays "$work/r.rays" --out "$work/hx.hiti"
check trace-max-hits-float 2 '"1e3" is not an integer \(1\.\.4096\)' -- "$meshcast" trace "$mesh" --query all --max-hits 1e3 --rays "$work/r.rays" --out "$work/hx.hitn"
printf 'RAYD\0\0\0\0' >"$work/none.rayd"
check trace-rayd-on-mesh 2 "none.rayd: not a RAYS file \(rays with float origins\) but a RAYD file \(rays with double origins, read by scenes\)" -- "$meshcast" trace "$mesh" --rays "$work/none.rayd" --out "$work/hx.hits"
: >"$work/empty.rayd"
check trace-empty-rayd 2 "empty.rayd: 0 bytes, shorter than a RAYD file's 8-byte header" -- "$meshcast" trace "$work/one.json" --rays "$work/empty.rayd" --out "$work/hx.hiti"
check trace-max-hits-range 2 "max-hits" -- "$meshcast" trace "$mesh" --query all --max-hits 0 --rays "$work/r.rays" --out "$work/hx.hitn"
# The two hits files agree (same triangle per ray): compare the triangle columns.
if ! cmp -s <(od -An -tu4 -w8 -j8 "$work/h.hits" | awk '{print $2}') \
            <(od -An -tu4 -w8 -j8 "$work/h2.hits" | awk '{print $2}'); then
  echo "FAIL hits of two layouts differ"; failures=$((failures + 1))
fi
check splitter 0 "ns/ray" -- "$meshcast" trace "$mesh" --layout aabbtreepns/float3soa8 --splitter morton --rays "$work/r.rays" --out "$work/h3.hits"
check unknown-splitter 2 "valid splitters" -- "$meshcast" info "$mesh" --splitter octree
check layouts 0 "OctTreeCompressed/ClusterBitPackSOA8" -- "$meshcast" layouts
check unknown-layout 2 "did you mean OctTreeCompressed/Float3.*meshcast layouts. lists all" -- "$meshcast" info "$mesh" --layout OctTree/Float3
check grouping 0 "ns/ray" -- "$meshcast" trace "$mesh" --layout AABBList/Indexed16SOA4 --grouping morton --rays "$work/r.rays" --out "$work/h5.hits"
check trace-aabblist-vulkan 0 "device: " -- "$meshcast" trace "$mesh" --layout AABBList/BitPackSOA128 --backend vulkan --method aabblist --rays "$work/r.rays" --out "$work/h6.hits" --repeat 1
check auto-speed 0 "chose OctTreeCompressed" -- "$meshcast" build "$mesh" --layout auto --out "$work/auto.blob"
check auto-blob 0 "remap: " -- "$meshcast" info "$work/auto.blob"
check auto-memory 0 "the fewest bytes that meet the limits" -- "$meshcast" info "$mesh" --layout auto --goal memory --max-error 2e-6
check auto-trial 0 "fastest in the trial" -- "$meshcast" build "$mesh" --layout auto --trial 64 --out "$work/auto2.blob"
check auto-gpu 0 "CPU and GPU" -- "$meshcast" info "$mesh" --layout auto --gpu --goal memory
check auto-json 0 '^\{"input"' -- "$meshcast" info "$mesh" --layout auto --json
check auto-impossible 2 "no layout meets the limits \(at most 1 byte a triangle\); the smallest built takes [0-9.]+ bytes a triangle and the most exact is exact \(an error of 0\)$" -- "$meshcast" info "$small_mesh" --layout auto --max-bytes 1
check auto-impossible-small 2 "no layout meets the limits \(at most 0\.001 bytes a triangle\)" -- "$meshcast" info "$small_mesh" --layout auto --max-bytes 0.001
check auto-error-given 0 "error at most 1\.25e-07 of the diagonal" -- "$meshcast" info "$mesh" --layout auto --max-error 1.25e-7
check auto-goal 2 "valid goals: speed memory" -- "$meshcast" info "$mesh" --layout auto --goal fast
check no-triangle-ids 0 "remap: none" -- "$meshcast" info "$mesh" --layout QuadTree/Float3SOA4 --no-triangle-ids
check pairing 0 "of triangles paired" -- "$meshcast" info "$mesh" --layout AABBTree/Float3SOA4 --pairing
check zerobyte 0 "nodes +0 +0\.00" -- "$meshcast" info "$mesh" --layout ZeroByteTree/Indexed24
check zerobyte-stats 0 "shuffled; box cache off" -- "$meshcast" info "$mesh" --layout ZeroByteHybrid/Indexed24 --hybrid-leaf 64 --no-box-cache
check zerobyte-float3 2 "ZeroByteTree/Indexed24" -- "$meshcast" info "$mesh" --layout ZeroByteTree/Float3
check zerobyte-trace 0 "ns/ray" -- "$meshcast" trace "$mesh" --layout ZeroByteTree/Indexed24 --rays "$work/r.rays" --out "$work/hz.hits"
check bench-combos-zerobyte 0 "ZeroByteHybrid/Indexed24 \(leaf 64\)" -- "$meshcast" bench combos "$mesh" --rays 8 --repeat 1 --only ZeroByte,QuadTreeHalfFloat/Indexed8 --out-dir "$work"
check pairing-bruteforce 2 "keeps its own triangle order" -- "$meshcast" info "$mesh" --layout BruteForce/Float3 --pairing
check order 0 "ns/ray" -- "$meshcast" trace "$mesh" --layout quadtreehalffloat/float3 --order breadthfirst --rays "$work/r.rays" --out "$work/h4.hits"
check order-refused 2 "AABBTree is always DepthFirst" -- "$meshcast" info "$mesh" --layout AABBTree/Float3 --order BreadthFirst
check unknown-order 2 "valid node orders" -- "$meshcast" info "$mesh" --layout QuadTree/Float3 --order Random
check lbvh 0 "StacklessLBVH/Float3" -- "$meshcast" info "$mesh" --layout StacklessLBVH/Float3 --lbvh-depth 20 --lbvh-left-first
check trace-vulkan 0 "device: " -- "$meshcast" trace "$mesh" --layout BruteForce/Float3SOA128 --backend vulkan --method bruteforce --rays "$work/r.rays" --out "$work/hv.hits" --repeat 1
# The GPU's hits name the same triangles as the CPU's (AABBTree/Float3 above).
if ! cmp -s <(od -An -tu4 -w8 -j8 "$work/hv.hits" | awk '{print $2}') \
            <(od -An -tu4 -w8 -j8 "$work/h2.hits" | awk '{print $2}'); then
  echo "FAIL vulkan hits differ from the CPU's"; failures=$((failures + 1))
fi
check trace-all-vulkan 0 '"query":"all","cull":"back"' -- "$meshcast" trace "$mesh" --layout AABBTree/Float3 --backend vulkan --method aabbtree --query all --max-hits 4 --cull back --rays "$work/r.rays" --out "$work/hnv.hitc" --repeat 1 --json
# Every hit, culled, on the GPU: the CPU's HITC file byte for byte.
if ! cmp -s "$work/hn.hitc" "$work/hnv.hitc"; then
  echo "FAIL trace-all-vulkan: the HITC file differs from the CPU's"; failures=$((failures + 1))
fi
# A batch whose device rows exceed the device's host-visible memory is
# refused before any pass, naming the bytes (140,000 rows of 4096: 4.6 GB)
# and the limit (lavapipe's heap: 2 GiB).
check rays-many 0 "rays ->" -- "$meshcast" rays "$mesh" --kind long --count 140000 --seed 4 --out "$work/many.rays"
check trace-all-vulkan-refused 2 "140000 rays \(rows of 4096 hits a ray\) needs [0-9]+ bytes of host-visible memory, more than .*host-visible heap" -- "$meshcast" trace "$mesh" --layout AABBTree/Float3 --backend vulkan --method aabbtree --query all --max-hits 4096 --rays "$work/many.rays" --out "$work/hx.hitc"
check bench-gpu 0 "\\| lbvh \\| StacklessLBVH/Float3" -- "$meshcast" bench gpu "$mesh" --rays 8 --repeat 1 --sizes 1k,4k --out-dir "$work"
# The batch-size sweep's rows, each size's rays answered as on the CPU.
grep -qE '^4096,[0-9.e+-]+,[0-9.e+-]+,.*,0$' "$work/gpu_scale.csv" ||
  { echo "FAIL bench-gpu-sizes: no 4096-ray row agreeing with the CPU in gpu_scale.csv"; failures=$((failures + 1)); }
check bench-gpu-bad-size 2 "'3G' is not a batch size" -- "$meshcast" bench gpu "$mesh" --sizes 3G
check render-cpu 0 "device: CPU" -- "$meshcast" render "$mesh" --png "$work/rc.png" --width 160 --height 120
check render-vulkan 0 "device: " -- "$meshcast" render "$mesh" --backend vulkan --png "$work/rv.png" --width 160 --height 120
# The same bytes walked on the GPU give the same picture.
cmp -s "$work/rc.png" "$work/rv.png" || { echo "FAIL the Vulkan picture differs from the CPU's"; failures=$((failures + 1)); }
check vulkan-wrong-layout 2 "reads BruteForce/BitPackSOA128 or BruteForce/Float3SOA128 blobs, not AABBTree/Float3" -- "$meshcast" trace "$mesh" --layout AABBTree/Float3 --backend vulkan --method bruteforce --rays "$work/r.rays" --out "$work/hx.hits"
# --method defaults to the method that reads the blob's layout (trace --help
# says so, as render does): a mesh in the default layout, and a saved blob
# of every layout a GPU method reads (the list trace --help gives, from the
# one table), each cast on the GPU without --method answers as the CPU
# does on the same blob, byte for byte.
check trace-vulkan-default 0 "device: " -- "$meshcast" trace "$mesh" --backend vulkan --rays "$work/r.rays" --out "$work/hvd.hits" --repeat 1
"$meshcast" trace "$mesh" --rays "$work/r.rays" --out "$work/hcd.hits" --repeat 1 >/dev/null
cmp -s "$work/hvd.hits" "$work/hcd.hits" || { echo "FAIL trace-vulkan-default: the GPU's hits differ from the CPU's"; failures=$((failures + 1)); }
gpu_layouts=$("$meshcast" trace --help | grep -- '--method' | grep -oE '[A-Za-z0-9]+/[A-Za-z0-9]+' | sort -u)
if (( $(wc -w <<<"$gpu_layouts") < 10 )); then
  echo "FAIL trace-vulkan-layouts: trace --help names only these layouts a GPU method reads: $gpu_layouts"; failures=$((failures + 1))
fi
for gpu_layout in $gpu_layouts; do
  blob=$work/gpu-${gpu_layout//\//-}.blob
  "$meshcast" build "$mesh" --layout "$gpu_layout" --out "$blob" >/dev/null
  "$meshcast" trace "$blob" --rays "$work/r.rays" --out "$blob.cpu.hits" --repeat 1 >/dev/null
  check "trace-vulkan-default-$gpu_layout" 0 "\"layout\":\"$gpu_layout\",\"device\":\"[^C]" -- "$meshcast" trace "$blob" --backend vulkan --rays "$work/r.rays" --out "$blob.gpu.hits" --repeat 1 --json
  cmp -s "$blob.cpu.hits" "$blob.gpu.hits" || { echo "FAIL trace-vulkan-default-$gpu_layout: the GPU's hits differ from the CPU's"; failures=$((failures + 1)); }
done
# --layout auto with a method named keeps to the layouts that method reads
# (not a layout of another method, the named one dropped).
check trace-vulkan-auto-method 0 '"layout":"StacklessLBVH/Float3"' -- "$meshcast" trace "$mesh" --layout auto --backend vulkan --method lbvh --rays "$work/r.rays" --out "$work/hx.hits" --repeat 1 --json
# A layout no GPU method reads, and a method that does not exist, are
# refused naming them and what the methods read (not "GPU method ''").
check trace-vulkan-no-method 2 "no GPU method reads QuadTree/Float3SOA4 blobs.*octtree \(OctTreeCompressed/ClusterBitPackSOA8 or OctTreeCompressed/ClusterFloat3SOA8\)" -- "$meshcast" trace "$mesh" --layout QuadTree/Float3SOA4 --backend vulkan --rays "$work/r.rays" --out "$work/hx.hits"
check render-vulkan-no-method 2 "no GPU method reads QuadTree/Float3SOA4 blobs" -- "$meshcast" render "$mesh" --layout QuadTree/Float3SOA4 --backend vulkan --png "$work/x.png" --width 16 --height 16
check trace-vulkan-unknown-method 2 "--method octree: no such GPU method; the methods: aabbtree" -- "$meshcast" trace "$mesh" --backend vulkan --method octree --rays "$work/r.rays" --out "$work/hx.hits"
check trace-help-methods 0 "octtree \(OctTreeCompressed/ClusterBitPackSOA8 or OctTreeCompressed/ClusterFloat3SOA8\), aabblist \(AABBList/Float3SOA128 or AABBList/BitPackSOA128\)" -- "$meshcast" trace --help
check vulkan-no-device 3 "no device matches" -- "$meshcast" trace "$mesh" --layout BruteForce/Float3SOA128 --backend vulkan --device nonesuch --rays "$work/r.rays" --out "$work/hx.hits"
check missing-mesh 2 "nope.off" -- "$meshcast" info "$work/nope.off"
printf 'OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n' >"$work/nan.off"
check nan-mesh 2 "nan.off.*(NaN|nan)" -- "$meshcast" info "$work/nan.off"
head -c 1000 "$work/m.blob" >"$work/cut.blob"
check truncated-blob 2 "cut.blob.*(truncated|bytes)" -- "$meshcast" info "$work/cut.blob"
cp "$work/m.blob" "$work/flip.blob"
printf '\x55' | dd of="$work/flip.blob" bs=1 seek=300 conv=notrunc status=none
check flipped-blob 2 "flip.blob.*checksum" -- "$meshcast" info "$work/flip.blob"
head -c 30 "$work/r.rays" >"$work/cut.rays"
check truncated-rays 2 "cut.rays" -- "$meshcast" trace "$work/m.blob" --rays "$work/cut.rays" --out "$work/x.hits"


# Distances: a unit cube's signed distance on a grid (cell centres at
# -0.375 + 0.25 k over the box grown by half its extent: 4 of 8 a side
# fall inside, 64 in all) and at three points read from a .npy file whose
# distances are known: the centre (-0.5 inside), 2 above the top face, 1
# beside a side face.
printf 'OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n' >"$work/cube.off"
check distance-grid 0 '"points":512,"signed":true,"sign":"parity","inside":64' -- "$meshcast" distance "$work/cube.off" --grid 8 --margin 0.5 --signed --json --out "$work/grid.npy" --layout OctTreeCompressed/Float3SOA8
[[ $(stat -c %s "$work/grid.npy") == 2176 ]] || { echo "FAIL distance-grid: grid.npy is not 128 header bytes and 512 float32"; failures=$((failures + 1)); }
python3 -c 'import struct, sys
h = "{\x27descr\x27: \x27<f8\x27, \x27fortran_order\x27: False, \x27shape\x27: (3, 3), }"
h += " " * ((64 - (10 + len(h) + 1) % 64) % 64) + "\n"
pts = [0.5, 0.5, 0.5, 0.5, 0.5, 3.0, 2.0, 0.5, 0.5]
open(sys.argv[1], "wb").write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(h)) + h.encode() + struct.pack("<9d", *pts))' "$work/p.npy"
check distance-points 0 "1 inside \(negative\), 2 outside" -- "$meshcast" distance "$work/cube.off" --points "$work/p.npy" --signed --out "$work/d.npy" --triangles "$work/t.npy"
got=$(python3 -c 'import struct, sys
b = open(sys.argv[1], "rb").read(); n = struct.unpack("<H", b[8:10])[0]
print(*struct.unpack("<3f", b[10 + n:]))' "$work/d.npy")
[[ $got == "-0.5 2.0 1.0" ]] || { echo "FAIL distance-points: distances $got, not -0.5 2.0 1.0"; failures=$((failures + 1)); }
# The cube without its +y face: a ray from inside along the inside test's
# direction (mostly +y) escapes through the hole from most cells, while the
# winding number is above 1/2 in every cell inside (0.61 at the cells
# nearest the hole) and below it outside (0.39 there).
grep -v '^3 2 3 7$\|^3 2 7 6$' "$work/cube.off" | sed 's/^8 12 0$/8 10 0/' >"$work/open_cube.off"
check distance-winding 0 '"points":512,"signed":true,"sign":"winding","inside":64' -- "$meshcast" distance "$work/open_cube.off" --grid 8 --margin 0.5 --signed --sign winding --json --out "$work/grid.npy" --layout OctTreeCompressed/ClusterFloat3SOA8
"$meshcast" distance "$work/open_cube.off" --grid 8 --margin 0.5 --signed --json --out "$work/grid.npy" --layout OctTreeCompressed/Float3SOA8 | grep -q '"inside":64' &&
  { echo "FAIL distance-winding: parity found every cell of the open cube inside (the test's hole does not show)"; failures=$((failures + 1)); }
check distance-sign 2 "--sign: votes not in \{parity,winding\}|votes" -- "$meshcast" distance "$work/cube.off" --grid 4 --signed --sign votes --out "$work/x.npy"
check distance-both 2 "--points FILE.npy or --grid N, one of them" -- "$meshcast" distance "$work/cube.off" --grid 4 --points "$work/p.npy" --out "$work/x.npy"
check distance-not-npy 2 "cube.off: not a .npy file" -- "$meshcast" distance "$work/cube.off" --points "$work/cube.off" --out "$work/x.npy"
check distance-layout 2 "point queries walk OctTreeCompressed layouts.*AABBTree/Float3" -- "$meshcast" distance "$work/cube.off" --grid 4 --layout AABBTree/Float3 --out "$work/x.npy"
# A .npy file numpy would refuse is refused, naming the file and the limit
# or what is wrong, rather than read in part or answered with a file numpy
# cannot open: a header over numpy.load's 10000 bytes (25,001 dimensions,
# beyond format 1.0's 16-bit header length), more than numpy's 32
# dimensions, a shape that is not a tuple of integers, a key missing or one
# too many. npy FILE VERSION DICT: three float64 points under that header.
npy() {
  python3 -c 'import struct, sys
path, version, h = sys.argv[1], int(sys.argv[2]), sys.argv[3]
h += " " * ((64 - (10 + 2 * (version > 1) + len(h) + 1) % 64) % 64) + "\n"
size = struct.pack("<H" if version == 1 else "<I", len(h))
pts = [0.5, 0.5, 0.5, 0.5, 0.5, 3.0, 2.0, 0.5, 0.5]
open(path, "wb").write(b"\x93NUMPY" + bytes([version, 0]) + size + h.encode() + struct.pack("<9d", *pts))' "$@"
}
f8="'descr': '<f8', 'fortran_order': False"
ones() { printf '1, %.0s' $(seq "$1"); }
npy "$work/wide.npy" 2 "{$f8, 'shape': ($(ones 25000)3), }"
check distance-npy-header-size 2 "wide.npy: a .npy header of [0-9]+ bytes; numpy reads at most 10000" -- "$meshcast" distance "$work/cube.off" --points "$work/wide.npy" --out "$work/x.npy"
npy "$work/dims33.npy" 1 "{$f8, 'shape': ($(ones 32)3), }"
check distance-npy-dimensions 2 "dims33.npy: a shape of more than 32 dimensions; numpy reads at most 32" -- "$meshcast" distance "$work/cube.off" --points "$work/dims33.npy" --out "$work/x.npy"
npy "$work/spaced.npy" 1 "{$f8, 'shape': (1 9, 3), }"
check distance-npy-shape 2 "spaced.npy: the .npy header has no ',' or '\)' after a dimension of 'shape'" -- "$meshcast" distance "$work/cube.off" --points "$work/spaced.npy" --out "$work/x.npy"
npy "$work/number.npy" 1 "{$f8, 'shape': (3), }"
check distance-npy-number 2 "number.npy: the .npy header has a number, not a tuple, for 'shape'" -- "$meshcast" distance "$work/cube.off" --points "$work/number.npy" --out "$work/x.npy"
npy "$work/no_order.npy" 1 "{'descr': '<f8', 'shape': (3, 3), }"
check distance-npy-no-order 2 "no_order.npy: the .npy header has no 'fortran_order' key" -- "$meshcast" distance "$work/cube.off" --points "$work/no_order.npy" --out "$work/x.npy"
npy "$work/extra.npy" 1 "{$f8, 'shape': (3, 3), 'unit': 'mm', }"
check distance-npy-extra-key 2 "extra.npy: the .npy header has a key 'unit'" -- "$meshcast" distance "$work/cube.off" --points "$work/extra.npy" --out "$work/x.npy"
# What is read is numpy's whole: format 2.0, double quotes, no trailing
# comma, a shape of 32 dimensions; what is written numpy loads.
npy "$work/v2.npy" 2 "{\"descr\": \"<f8\", \"fortran_order\": False, \"shape\": (3,3)}"
check distance-npy-v2 0 "1 inside \(negative\), 2 outside" -- "$meshcast" distance "$work/cube.off" --points "$work/v2.npy" --signed --out "$work/d2.npy"
npy "$work/dims32.npy" 1 "{$f8, 'shape': ($(ones 31)3), }"
check distance-npy-32 0 "1 inside \(negative\)" -- "$meshcast" distance "$work/cube.off" --points "$work/dims32.npy" --signed --out "$work/d32.npy" --triangles "$work/t32.npy"
if python3 -c 'import numpy' 2>/dev/null; then
  python3 -c 'import sys, numpy as np
d, t, d32, t32 = (np.load(p) for p in sys.argv[1:])
assert d.dtype == np.float32 and d.tolist() == [-0.5, 2.0, 1.0], d
assert t.dtype == np.uint32 and t.shape == (3,) and (t < 12).all(), t
assert d32.shape == (1,) * 31 and d32.ravel().tolist() == [-0.5], d32.shape
assert t32.dtype == np.uint32 and t32.shape == (1,) * 31' "$work/d.npy" "$work/t.npy" "$work/d32.npy" "$work/t32.npy" ||
    { echo "FAIL distance-npy-numpy: numpy.load does not read what distance wrote"; failures=$((failures + 1)); }
fi

# Hostile input through the command line.
# Every --json output parses as JSON, a path with quotes, backslashes and a
# byte that is not UTF-8 included; NaN is null, not a bare nan.
json_ok() {  # json_ok NAME -- command...: exit 0 and stdout one JSON object
  local name=$1
  shift 2
  local out
  if out=$("$@" 2>/dev/null) && python3 -c 'import json, sys; o = json.loads(sys.stdin.read()); assert isinstance(o, dict)' <<<"$out"; then
    echo "ok   $name"; passes=$((passes + 1))
  else
    echo "FAIL $name: not one JSON object:"; echo "$out" | head -5; failures=$((failures + 1))
  fi
}
odd=$work/$'we"ird\\path\xff'.off
cp "$mesh" "$odd"
json_ok json-info -- "$meshcast" info "$mesh" --json
json_ok json-info-odd-path -- "$meshcast" info "$odd" --json
json_ok json-info-blob -- "$meshcast" info "$work/m.blob" --json
json_ok json-info-auto -- "$meshcast" info "$odd" --layout auto --json
json_ok json-trace -- "$meshcast" trace "$odd" --layout AABBTree/Float3 --rays "$work/r.rays" --out "$work/hj.hits" --json
json_ok json-trace-vulkan -- "$meshcast" trace "$odd" --layout BruteForce/Float3SOA128 --backend vulkan --rays "$work/r.rays" --out "$work/hj2.hits" --json --repeat 1
check json-path-kept 0 'we\\"ird\\\\path' -- "$meshcast" info "$odd" --json
# Output lost without an error: every write is checked (exit 4, the path and
# the reason), and a failed write leaves no file under the final name.
check full-hits 4 "/dev/full.*No space left" -- "$meshcast" trace "$work/m.blob" --rays "$work/r.rays" --out /dev/full
head -c $((8 + 28 * 3)) "$work/r.rays" >"$work/three.rays"
printf '\x03\x00\x00\x00' | dd of="$work/three.rays" bs=1 seek=4 conv=notrunc status=none
check full-hits-small 4 "/dev/full.*No space left" -- "$meshcast" trace "$work/m.blob" --rays "$work/three.rays" --out /dev/full
check full-rays 4 "/dev/full.*No space left" -- "$meshcast" rays "$mesh" --count 3 --out /dev/full
check full-blob 4 "/dev/full.*No space left" -- "$meshcast" build "$work/tiny_square.off" --out /dev/full
check full-png 4 "/dev/full.*No space left" -- "$meshcast" render "$mesh" --png /dev/full --width 16 --height 16
check missing-dir-out 4 "nodir/x.hits.*cannot write" -- "$meshcast" trace "$work/m.blob" --rays "$work/r.rays" --out "$work/nodir/x.hits"
# A write cut short (the file-size limit, as a full disk would) leaves the
# old file whole and nothing beside it.
cp "$work/m.blob" "$work/keep.blob"
check size-limit-blob 4 "keep.blob: cannot write the file \(write: File too large" -- \
  bash -c 'trap "" XFSZ; ulimit -f 1; exec "$0" build "$1" --out "$2"' "$meshcast" "$mesh" "$work/keep.blob"
cmp -s "$work/m.blob" "$work/keep.blob" || { echo "FAIL keep.blob changed by a failed write"; failures=$((failures + 1)); }
if ls -A "$work" | grep -q '^\.meshcast-'; then echo "FAIL a partial file was left in $work"; failures=$((failures + 1)); fi
check json-stdout-full 4 "standard output: cannot write" -- bash -c 'exec "$0" info "$1" --json >/dev/full' "$meshcast" "$mesh"
# A symbolic link (as /dev/stdout is) is written through, not replaced.
: >"$work/target.blob"
ln -s "$work/target.blob" "$work/link.blob"
check link-out 0 "bytes/triangle" -- "$meshcast" build "$work/tiny_square.off" --out "$work/link.blob"
[[ -L $work/link.blob ]] || { echo "FAIL link.blob was replaced"; failures=$((failures + 1)); }
check link-target 0 "OctTreeCompressed" -- "$meshcast" info "$work/target.blob"
# Unclear failures: a message naming the input and the limit, exit 2 (input)
# or 3 (device).
mkdir -p "$work/adir.off"
check dir-mesh 2 "adir.off: is a directory" -- "$meshcast" info "$work/adir.off"
check dir-blob 2 "$work: is a directory" -- "$meshcast" info "$work"
check dir-rays 2 "$work: is a directory" -- "$meshcast" trace "$work/m.blob" --rays "$work" --out "$work/x.hits"
check dev-zero-mesh 2 "/dev/zero: not a regular file" -- "$meshcast" info /dev/zero
check device-huge 3 "no device matches '99999999999'.*an index below" -- "$meshcast" trace "$work/m.blob" --backend vulkan --method quadtree --device 99999999999 --rays "$work/r.rays" --out "$work/x.hits"
check device-huge-env 3 "no device matches '99999999999' \(\\\$MESHCAST_VK_DEVICE\)" -- env MESHCAST_VK_DEVICE=99999999999 "$meshcast" trace "$work/m.blob" --backend vulkan --method quadtree --rays "$work/r.rays" --out "$work/x.hits"
check rays-count-huge 2 "count.*134217728" -- "$meshcast" rays "$mesh" --count 4294967295 --out "$work/x.rays"
head -c 150 "$work/tiny_bin.stl" >"$work/cut.stl" 2>/dev/null
check truncated-stl 2 "cut.stl: malformed file: binary STL truncated.*2 facets" -- "$meshcast" info "$work/cut.stl"
{ printf 'solid exported by a binary writer'; head -c 47 /dev/zero; printf '\x02\x00\x00\x00'; head -c 66 /dev/zero; } >"$work/cut_solid.stl"
check truncated-stl-solid 2 "cut_solid.stl: malformed file: binary STL truncated.*2 facets" -- "$meshcast" info "$work/cut_solid.stl"
check max-bytes-nan 2 '--max-bytes: "nan" is not a number \(a finite number at least 0\)' -- "$meshcast" info "$mesh" --layout auto --max-bytes nan
check max-error-nan 2 '--max-error: "nan" is not a number \(a finite number at least 0\)' -- "$meshcast" info "$mesh" --layout auto --max-error nan
check max-bytes-minus-nan 2 '--max-bytes: "-nan" is not a number' -- "$meshcast" info "$mesh" --layout auto --max-bytes -nan
check max-bytes-huge 2 "--max-bytes: 1e400 is not a finite number at least 0$" -- "$meshcast" info "$mesh" --layout auto --max-bytes 1e400
check max-error-negative 2 "--max-error: -inf is not a finite number at least 0$" -- "$meshcast" info "$mesh" --layout auto --max-error -inf
# Integers: a negative or 65-bit seed was taken wrapped; a leading zero made
# CLI11 read octal (010 as eight); an unchecked count took -1 as 2^64 - 1.
check rays-seed-negative 2 '--seed: "-1" is not an integer \(0\.\.18446744073709551615\)' -- "$meshcast" rays "$mesh" --count 5 --seed -1 --out "$work/x.rays"
check rays-seed-huge 2 "--seed: 18446744073709551616 is not in 0\.\.18446744073709551615" -- "$meshcast" rays "$mesh" --count 5 --seed 18446744073709551616 --out "$work/x.rays"
check rays-seed-largest 0 "5 long rays" -- "$meshcast" rays "$mesh" --count 5 --seed 18446744073709551615 --out "$work/x.rays"
check rays-count-zeros 2 "--count: 010 has a leading zero" -- "$meshcast" rays "$mesh" --count 010 --out "$work/x.rays"
check rays-seed-zero 0 "5 long rays" -- "$meshcast" rays "$mesh" --count 5 --seed 0 --out "$work/x.rays"
check demo-gpu-count-negative 2 '--gpu-count: "-1" is not an integer \(0\.\.10000000\)' -- timeout 60 "$meshcast" demo "$mesh" --gpu-count -1 --count 1 --png "$work/x.png"
check bench-frame-ms-nan 2 '--frame-ms: "nan" is not a number \(0\.\.1000\)' -- timeout 60 "$meshcast" bench latency "$mesh" --frame-ms nan --out-dir "$work"
check blob-leaf 2 "m.blob: is a blob.*--leaf applies only to a mesh" -- "$meshcast" info "$work/m.blob" --leaf 4
check blob-layout 2 "m.blob: is a blob.*--layout applies only" -- "$meshcast" trace "$work/m.blob" --layout AABBTree/Float3 --rays "$work/r.rays" --out "$work/x.hits"
check blob-pairing 2 "m.blob: is a blob.*--pairing" -- "$meshcast" info "$work/m.blob" --pairing

# Long work shows a progress line on stderr when it is a terminal (script(1)
# gives the command one), never with --json, never into a pipe or file.
check rays-1m 0 "rays ->" -- "$meshcast" rays "$mesh" --kind long --count 1100000 --seed 3 --out "$work/big.rays"
check progress-tty 0 "tracing 1100000 rays x 1[ :]" -- script -qec "'$meshcast' trace '$mesh' --rays '$work/big.rays' --out '$work/big.hits' --repeat 1" /dev/null
check progress-json 0 '^[^t]*\{"input"' -- script -qec "'$meshcast' trace '$mesh' --rays '$work/big.rays' --out '$work/big.hits' --repeat 1 --json" /dev/null
if "$meshcast" trace "$mesh" --rays "$work/big.rays" --out "$work/big.hits" --repeat 1 2>&1 | grep -q tracing; then
  echo "FAIL progress-pipe: a progress line went into a pipe"; failures=$((failures + 1))
else
  echo "ok   progress-pipe"; passes=$((passes + 1))
fi
rm -f "$work/big.rays" "$work/big.hits"

echo "$passes passed, $failures failed"
exit $((failures > 0))
