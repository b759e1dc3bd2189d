#!/usr/bin/env bash
# The rooms' dependencies run one way (docs/design.md, Rooms): the bytes
# (layout/) include no other room; the CPU walkers (cpu/) nothing of the
# builder; the Vulkan backend (gpu/) nothing of the CPU walkers or the
# builder; the public Caster header none of the threading headers its
# implementation uses. Fails naming every include that breaks a rule.
# Usage: room_includes_test.sh SOURCE_DIR
set -euo pipefail
src=${1:?usage: room_includes_test.sh SOURCE_DIR}
status=0
forbid() {  # forbid ROOM PATTERN WHY
  local hits
  hits=$(grep -rnE "^[[:space:]]*#[[:space:]]*include[[:space:]]*[\"<]($2)" "$src/$1" || true)
  if [[ -n $hits ]]; then
    echo "$1 must not include $2 ($3):"
    echo "$hits"
    status=1
  fi
}
forbid layout 'cpu/|builder/|gpu/|host/|scene/|io/' "the bytes every room reads depend on none of them"
forbid cpu 'builder/|gpu/|host/' "the walkers read blobs, they do not build them"
forbid gpu 'cpu/|builder/|host/' "the Vulkan backend reads the same bytes through layout/, not the CPU's code"
hits=$(grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*<(thread|deque|map|condition_variable|mutex|atomic)>' \
       "$src/include/meshcast/caster.h" || true)
if [[ -n $hits ]]; then
  echo "include/meshcast/caster.h must not include its implementation's threading headers:"
  echo "$hits"
  status=1
fi
[[ $status == 0 ]] && echo "every room includes only what its rules allow"
exit $status
