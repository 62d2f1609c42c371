#!/usr/bin/env bash
# Installs a built sdfkit into <build>/install, then builds the outside project
# examples/custom_pass against that package (find_package(sdfkit)) and runs it on Mesa lavapipe
# with the validation layer on. Exits non-zero on any failure.
#   scripts/test-example.sh [BUILD_DIR]   (default: the repository's build/)
set -euo pipefail
build="$(realpath "${1:-$(dirname "$0")/../build}")"
cd "$(dirname "$0")/.."
prefix="$build/install"
example_build="$build/example-custom_pass"

export VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
export VK_ICD_FILENAMES="$VK_DRIVER_FILES"
export SDFKIT_VK_VALIDATION=1

passed=0
failed=0
run() {  # run NAME COMMAND...: one step; a failure is counted and reported
  local name="$1"
  shift
  echo "== $name: $*"
  if "$@"; then
    return 0
  fi
  echo "example: step '$name' failed"
  return 1
}

if run install cmake --install "$build" --prefix "$prefix" &&
   run configure cmake -S examples/custom_pass -B "$example_build" -G Ninja \
       -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=RelWithDebInfo &&
   run build cmake --build "$example_build" &&
   run custom_pass "$example_build/custom_pass" "$example_build/custom_pass.png"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
fi

echo "example: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
