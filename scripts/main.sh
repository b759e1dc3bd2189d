#!/usr/bin/env bash
# The main job: a real mesh, real rays, every foundation layout, a table and
# a picture (out/bunny00.png).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out
build/bin/meshcast info data/bunny00.off --layout OctTreeCompressed/ClusterBitPackSOA8
build/bin/meshcast demo data/bunny00.off --count 10000 --repeat 5 --png out/bunny00.png
