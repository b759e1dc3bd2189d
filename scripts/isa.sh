# widest_isa: the widest walker instruction set (cpu/isa.h) this processor
# runs: avx512, avx2 or scalar. Sourced by test.sh and fuzz.sh, whose
# sanitizer and fuzz builds compile this set alone (MESHCAST_ISAS); the
# Release build has every set and test.sh runs each there.
widest_isa() {
  local flags
  flags=$(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null || true)
  has() { [[ " $flags " == *" $1 "* ]]; }
  if has avx2 && has fma && has f16c; then
    if has avx512f && has avx512vl && has avx512bw && has avx512dq; then echo avx512; else echo avx2; fi
  else
    echo scalar
  fi
}
