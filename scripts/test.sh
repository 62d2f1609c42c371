#!/usr/bin/env bash
# Installs dependencies, builds with warnings as errors, and runs the whole test suite with
# CTest: Vulkan on Mesa lavapipe, OpenCL on PoCL (CPU devices: no GPU needed). A missing
# device fails the device tests. Then a sanitizer build (ASan + UBSan) runs the CPU tests, and
# each fuzz harness runs ~30 s on its committed corpus.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh

# Pin the CPU drivers so results do not depend on whatever GPU the machine has.
export VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
export VK_ICD_FILENAMES="$VK_DRIVER_FILES"
export SDFKIT_VK_VALIDATION=1
export OCL_ICD_VENDORS=/etc/OpenCL/vendors
export POCL_CACHE_DIR="${TMPDIR:-/tmp}/sdfkit-pocl-cache"
unset SDFKIT_ALLOW_NO_DEVICE

scripts/build.sh
ctest --test-dir build --output-on-failure -j2 --timeout 600

# Embedding: install the CMake package and build + run examples/custom_pass against it.
scripts/test-example.sh build

if [ "${SDFKIT_SKIP_SANITIZE:-0}" != "1" ]; then
  # The library's tests under ASan + UBSan, the Vulkan (lavapipe) and OpenCL (PoCL) host code
  # included. The drivers are preloaded (right after the ASan runtime) so that they stay
  # resident: a driver unloaded at vkDestroyInstance leaves its allocations in an "<unknown
  # module>" no suppression can name. Leaks the drivers keep are suppressed by library name
  # (tests/sanitize/lsan-drivers.supp), never sdfkit's. The tests that run other programs (the
  # CLI, node's glTF validator, Python, Slurm) are left to the normal build above: this build
  # leaves out the CLI and the tests that run it (SDFKIT_BUILD_CLI=OFF: 30 % of its compile
  # time), and skips the GltfValidator suites of the library's writers (node would run under the
  # preloaded ASan runtime). With SDFKIT_SANITIZE_ALL=1 all of them are built and run here too.
  sanitize_start=$(date +%s)
  cli=OFF
  exclude='^GltfValidator\.'
  if [ "${SDFKIT_SANITIZE_ALL:-0}" = "1" ]; then cli=ON; exclude='^$'; fi
  SDFKIT_BUILD_DIR=build-asan scripts/build.sh -DSDFKIT_SANITIZE=ON -DSDFKIT_BUILD_BENCH=OFF -DSDFKIT_BUILD_PYTHON=OFF \
    -DSDFKIT_BUILD_CLI="$cli"
  libdir=/usr/lib/x86_64-linux-gnu
  LD_PRELOAD="$(c++ -print-file-name=libasan.so):$libdir/libvulkan_lvp.so:$libdir/libVkLayer_khronos_validation.so:$libdir/libpocl.so.2" \
  ASAN_OPTIONS=detect_leaks=1 \
  LSAN_OPTIONS="suppressions=$PWD/tests/sanitize/lsan-drivers.supp:print_suppressions=0" \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j2 --timeout 600 -E "$exclude"
  echo "sanitizer stage: $(( $(date +%s) - sanitize_start )) s (build and tests)"
fi

# Fuzzing: every loader and the manifest parser, SDFKIT_FUZZ_SECONDS (30) each on the committed
# corpus, clang + ASan + UBSan (scripts/fuzz.sh; longer runs: docs/fuzzing.md).
if [ "${SDFKIT_SKIP_FUZZ:-0}" != "1" ]; then
  scripts/fuzz.sh "${SDFKIT_FUZZ_SECONDS:-30}"
fi
