#!/bin/bash
# usage: walk_before_after.sh OLD_MESHCAST NEW_MESHCAST (from the repository root)
# One thread; 5 interleaved rounds of `trace --repeat 3` a binary, the median
# ns a ray of each, and whether their hits files are byte-identical.
OLD=$1; NEW=$2; D=${MESHCAST_DATA:-data}; W=${TMPDIR:-/tmp}/walk_before_after; mkdir -p $W
for mesh in bunny00 armadillo; do
  for kind in long radial; do
    $NEW rays $D/$mesh.off --kind $kind --count 200000 --out $W/${mesh}_$kind.rays >/dev/null 2>&1
  done
  for L in OctTreeCompressed/ClusterBitPackSOA8 AABBTree/Float3SOA8 QuadTree/Float3SOA4; do
    n=${L//\//_}
    $NEW build $D/$mesh.off --layout $L --out $W/${mesh}_$n.blob >/dev/null 2>&1
    for kind in long radial; do
      o=(); nw=()
      for round in 1 2 3 4 5; do
        o+=($($OLD trace $W/${mesh}_$n.blob --rays $W/${mesh}_$kind.rays --out $W/o.hits --repeat 3 --json 2>/dev/null | grep -o '"ns_per_ray":[0-9.]*' | cut -d: -f2))
        nw+=($($NEW trace $W/${mesh}_$n.blob --rays $W/${mesh}_$kind.rays --out $W/n.hits --repeat 3 --json 2>/dev/null | grep -o '"ns_per_ray":[0-9.]*' | cut -d: -f2))
      done
      cmp -s $W/o.hits $W/n.hits && same=same || same=DIFFER
      mo=$(printf '%s\n' "${o[@]}" | sort -g | sed -n 3p); mn=$(printf '%s\n' "${nw[@]}" | sort -g | sed -n 3p)
      echo "$mesh $kind $L old $mo new $mn ratio $(echo "$mn / $mo" | bc -l | cut -c1-5) hits $same"
    done
  done
done
