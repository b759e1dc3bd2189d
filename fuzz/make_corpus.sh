#!/usr/bin/env bash
# Writes the fuzz seed corpora (kept in the repository; rerun only to add
# formats): fuzz/corpus/mesh/ holds small mesh files of every format the
# reader takes, each behind mesh_fuzz's format byte ('0' OFF, '1' OBJ,
# '2' PLY, '3' STL); fuzz/corpus/blob/ holds a small sphere built into every
# layout (and paired where a tree takes pairs) by the meshcast CLI given as $1.
set -euo pipefail
cd "$(dirname "$0")"
meshcast=${1:?usage: make_corpus.sh path/to/meshcast}
mkdir -p corpus/mesh corpus/blob
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# A UV sphere of 6 rings x 8 segments in OFF, closed, poles shared.
awk 'BEGIN {
  r = 6; s = 8; pi = atan2(0, -1); nv = 2 + (r - 1) * s;
  nf = 2 * s + 2 * s * (r - 2);
  printf "OFF\n%d %d 0\n0 0 1\n", nv, nf;
  for (i = 1; i < r; ++i) for (j = 0; j < s; ++j) {
    th = pi * i / r; ph = 2 * pi * j / s;
    printf "%.6f %.6f %.6f\n", sin(th) * cos(ph), sin(th) * sin(ph), cos(th);
  }
  printf "0 0 -1\n";
  for (j = 0; j < s; ++j) printf "3 0 %d %d\n", 1 + j, 1 + (j + 1) % s;
  for (i = 0; i < r - 2; ++i) for (j = 0; j < s; ++j) {
    a = 1 + i * s + j; b = 1 + i * s + (j + 1) % s; c = a + s; d = b + s;
    printf "3 %d %d %d\n3 %d %d %d\n", a, c, b, b, c, d;
  }
  for (j = 0; j < s; ++j) { a = 1 + (r - 2) * s + j; b = 1 + (r - 2) * s + (j + 1) % s; printf "3 %d %d %d\n", nv - 1, b, a; }
}' > "$tmp/sphere.off"

{ printf '0'; cat "$tmp/sphere.off"; } > corpus/mesh/sphere.off
printf '0OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 2 3\n' > corpus/mesh/quad.off
printf '1# two groups sharing vertices\nvt 0 0\nvt 1 0\nvt 0 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.5\ng a\nf 1 2 3\ng b\nf 2/1 4/2 3/3\nf -3 -1 -2\nl 1 2\n' > corpus/mesh/groups.obj
printf '2ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 1e-3\n3 0 1 2\n3 1 3 2\n' > corpus/mesh/ascii.ply
{ printf '2ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
  printf '\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00'
  printf '\x03\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00'; } > corpus/mesh/binary.ply
printf '3solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n' > corpus/mesh/ascii.stl
{ printf '3'; head -c 80 /dev/zero; printf '\x01\x00\x00\x00'; head -c 12 /dev/zero
  printf '\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00'; } > corpus/mesh/binary.stl

layouts=$("$meshcast" layouts)
[[ -n $layouts ]] || { echo "make_corpus.sh: '$meshcast layouts' listed no layout" >&2; exit 1; }
for layout in $layouts; do
  name=${layout/\//_}
  leaf=4
  [[ $layout == *SOA128 ]] && leaf=31  # 128-lane blocks: few leaves keep the seed small
  "$meshcast" build "$tmp/sphere.off" --layout "$layout" --leaf $leaf --out "corpus/blob/$name.mcb" >/dev/null
  # Paired too where the tree takes pairs and they change the bytes.
  if "$meshcast" build "$tmp/sphere.off" --layout "$layout" --leaf $leaf --pairing --out "$tmp/paired.mcb" >/dev/null 2>&1 &&
     ! cmp -s "$tmp/paired.mcb" "corpus/blob/$name.mcb"; then
    mv "$tmp/paired.mcb" "corpus/blob/${name}_paired.mcb"
  fi
done
ls corpus/blob | wc -l
