#!/usr/bin/env bash
# Configures and builds sdfkit in ./build (Release with debug info, warnings as errors).
# Usage: scripts/build.sh [extra cmake -D options...]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${SDFKIT_BUILD_DIR:-build}"
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSDFKIT_WERROR=ON "${launcher[@]}" "$@"
cmake --build "$BUILD_DIR" -j"$(nproc)"
