#!/usr/bin/env bash
# Installs every Debian 12 package sdfkit needs to build, test and benchmark.
# Usage: scripts/install-deps.sh [--bench]   (--bench adds CGAL and MeshLab for comparisons)
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git python3
  # the fuzz harnesses (CMake preset `fuzz`, scripts/fuzz.sh): clang with libFuzzer
  clang-14 libfuzzer-14-dev
  # Vulkan: loader, headers, lavapipe (CPU driver), validation layers, shader compiler
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers glslang-tools spirv-tools vulkan-tools
  # OpenCL: ICD loader, headers, PoCL (CPU platform)
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd clinfo
  # geometry and I/O
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev libeigen3-dev libnanoflann-dev
  # reference ray caster (tests and benchmarks only)
  libembree-dev libtbb-dev
  # CLI, logging, tests, benchmarks
  libcli11-dev libfmt-dev libgtest-dev libgmock-dev libbenchmark-dev
  # the Python module and its tests
  pybind11-dev python3-numpy python3-dev
  # test data: CGAL's mesh data set (data.tar.gz)
  libcgal-demo
  # the Slurm test (scripts/slurm-local.sh): a single-node cluster on localhost
  slurm-wlm munge
)
# Node.js runs the Khronos glTF validator in the tests; keep a newer one if the machine has it.
if ! command -v npm >/dev/null 2>&1; then packages+=(nodejs npm); fi

if [ "${1:-}" = "--bench" ]; then
  packages+=(libcgal-dev meshlab xvfb xauth)
fi

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${packages[@]}"

# The Khronos glTF validator (npm package gltf-validator, pinned in its package.json).
here="$(cd "$(dirname "$0")/.." && pwd)"
if [ ! -d "$here/tools/gltf-validator/node_modules/gltf-validator" ]; then
  npm install --prefix "$here/tools/gltf-validator" --no-package-lock --no-audit --no-fund --loglevel=error
fi
