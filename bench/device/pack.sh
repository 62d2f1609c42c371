#!/bin/bash
# Packs what bench/device/run.sh needs on a GPU machine that has none of sdfkit's Debian
# dependencies (how the NVIDIA H200 numbers in bench/RESULTS.md were made): the built programs
# and GPU tests (debug info stripped), the Debian libraries they link (Embree, TBB, ocl-icd,
# tinygltf, stb, GMP/MPFR for the CGAL helpers), CGAL's data set, and the Debian packages of the
# Vulkan loader, glvnd and the validation layers. Writes .dev/ and .gl/ (both git-ignored through
# .git/info/exclude); copy them with the working tree and run bench/device/run.sh there.
# Usage: bench/device/pack.sh [BUILD_DIR=build]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
bins="apps/sdfkit apps/bench/sdfkit-bench apps/bench/sdfkit-cgal-sdf apps/bench/sdfkit_skeleton_bench
  tests/vulkan/vulkan_engine_test tests/vulkan/vulkan_depth_peel_test tests/vulkan/vulkan_depth_peel_reference_test
  tests/vulkan/vulkan_render_graph_test tests/vulkan/vulkan_push_constants_test tests/opencl/sdfkit_opencl_tests
  tests/pipeline/sdfkit_pipeline_tests tests/diffusion/sdfkit_diffuse_tests tests/render/sdfkit_render_tests
  tests/pointcloud/sdfkit_pointcloud_device_tests tests/cli/sdfkit_cli_tests tests/skeleton/sdfkit_skeleton_tests"
for b in $bins; do
  mkdir -p "$stage/build/$(dirname "$b")"
  strip --strip-debug -o "$stage/build/$b" "$build/$b"
done
mkdir -p "$stage/devlib"
for l in libOpenCL.so.1 libembree3.so.3 libgmp.so.10 libmpfr.so.6 libstb.so.0 libtbb.so.12 libtbbmalloc.so.2 libtinygltf.so.2d; do
  cp -L "/lib/x86_64-linux-gnu/$l" "$stage/devlib/"
done
mkdir -p .dev .gl
tar -C "$stage" -cf - . | xz -T0 -6 > .dev/payload.tar.xz
cp /usr/share/doc/libcgal-dev/data.tar.gz .dev/
grep -qx '/.dev/' .git/info/exclude 2>/dev/null || echo '/.dev/' >> .git/info/exclude
grep -qx '/.gl/' .git/info/exclude 2>/dev/null || echo '/.gl/' >> .git/info/exclude
lists=$(mktemp -d)
mkdir -p "$lists/partial"
o="-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=$lists"
apt-get $o update >/dev/null
(cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 vulkan-validationlayers)
rm -rf "$lists"
du -sh .dev .gl
