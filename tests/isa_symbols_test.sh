#!/usr/bin/env bash
# The walkers are compiled once an instruction set (cpu/isa.h); code of one
# set must never stand in for another's. Every weak code symbol an AVX2 or
# AVX-512 walker object defines must lie in that set's own namespace: a weak
# symbol outside it (an inline function of a shared header, a template of
# the standard library) could be the copy the linker keeps for the baseline
# code too, and fault on a processor without that set.
# Usage: isa_symbols_test.sh BUILD_DIR
set -euo pipefail
build=${1:?usage: isa_symbols_test.sh BUILD_DIR}
status=0
checked=0
# The library's walkers (meshcast_walkers_<set>) and the plain
# Möller–Trumbore ones the benchmark links (meshcast_walkers_moller_trumbore_<set>).
for isa in avx2 avx512; do
  for objects in "meshcast_walkers_$isa" "meshcast_walkers_moller_trumbore_$isa"; do
    dir="$build/CMakeFiles/$objects.dir"
    [[ -d $dir ]] || continue
    checked=1
    leaks=$(find "$dir" -name '*.o' -exec nm -C --defined-only {} + | awk '$2 == "W" { $1 = ""; $2 = ""; print }' |
            grep -v "isa_$isa" | sort -u || true)
    if [[ -n $leaks ]]; then
      echo "$objects shares weak code outside meshcast::isa_$isa:"
      echo "$leaks"
      status=1
    else
      echo "$objects: every weak code symbol lies in meshcast::isa_$isa"
    fi
  done
done
[[ $checked == 1 ]] || echo "no wide instruction set built (scalar only): nothing to check"
exit $status
