#!/usr/bin/env bash
# libmeshcast_c.so exports the C API's functions alone, each under the
# version node of capi/meshcast_c.map, and every function the header
# declares. Fails naming any other exported symbol, or a missing one.
# Usage: c_api_symbols_test.sh LIBRARY HEADER
set -euo pipefail
lib=${1:?usage: c_api_symbols_test.sh LIBRARY HEADER} header=${2:?}
status=0
# Defined, exported symbols (nm -D: the dynamic table), with their
# versions; the version nodes' own absolute symbols (type A) aside.
exported=$(nm -D --defined-only --with-symbol-versions "$lib" | awk '$2 != "A" {print $3}')
others=$(grep -v '^meshcast_' <<<"$exported" || true)
if [[ -n $others ]]; then
  echo "$lib exports symbols outside the meshcast_ prefix:"
  echo "$others"
  status=1
fi
unversioned=$(grep -v '@@MESHCAST_C_' <<<"$exported" || true)
if [[ -n $unversioned ]]; then
  echo "$lib exports symbols without a version node:"
  echo "$unversioned"
  status=1
fi
# Every function the header declares is exported.
for f in $(grep -oE 'meshcast_[a-z_0-9]+\(' "$header" | tr -d '(' | sort -u); do
  grep -q "^$f@@" <<<"$exported" || { echo "$lib lacks $f, which the header declares"; status=1; }
done
[[ $status == 0 ]] && echo "$(wc -l <<<"$exported") symbols, every one a versioned meshcast_ function"
exit $status
