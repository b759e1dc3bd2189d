#!/usr/bin/env bash
# Prepares a fresh Debian 12 machine (run as root): installs what meshcast
# needs from Debian's packages, fetches the public test meshes into data/
# (git-ignored) and builds Release into build/.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(cmake g++ make pkg-config libassimp-dev libcli11-dev libpng-dev libgtest-dev dpkg-dev nlohmann-json3-dev
          libvulkan-dev glslang-tools  # the Vulkan backend: headers, loader, glslang
          mesa-vulkan-drivers vulkan-validationlayers      # lavapipe (a Vulkan device on the CPU), the layers the tests run
          libembree-dev gnuplot-nox  # Embree: a peer measured beside meshcast; gnuplot: bench plots
          python3)                   # the CLI test parses every --json output with Python's json module
# The Python package (built into build/python, tested with pytest; its
# README install lines make a venv): pybind11, numpy, pytest, venv.
PACKAGES+=(pybind11-dev python3-dev python3-numpy python3-pytest python3-venv python3-wheel)
# ccache: the package test builds the library twice (cmake, then pip) with the same compiles.
PACKAGES+=(ccache)
# GMP: the tests judge each hit's t against exact rational arithmetic (check/exact_t.h).
PACKAGES+=(libgmp-dev)
source scripts/packages.sh
install_missing "${PACKAGES[@]}"

# Public meshes: data/*.off of CGAL's demo data (libcgal-demo).
bash scripts/fetch_meshes.sh

jobs=$(nproc)
# Debian's interpreter, the one its numpy and pytest belong to (python3 on
# PATH may be another). The walkers are built for every instruction set;
# the Möller-Trumbore ones, which `meshcast bench robustness` compares with
# them, for this machine's widest alone (the set its walkers run).
source scripts/isa.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMESHCAST_PYTHON=ON -DPython3_EXECUTABLE=/usr/bin/python3 \
  "-DMESHCAST_TRIANGLE_TEST_ISAS=$(widest_isa)" >/dev/null
cmake --build build -j"$jobs"
