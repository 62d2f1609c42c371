#!/bin/bash
# Runs on a GPU machine, from the root of a copy of the working tree that holds .dev/ and .gl/
# from bench/device/pack.sh: unpacks the Debian-built programs and libraries, points the Vulkan
# loader and ocl-icd at the NVIDIA driver, then runs the shipped benchmarks and the GPU backends'
# tests. Everything goes to $OUT (log.txt, results.tgz). Needs root (it unpacks into /).
# Usage: OUT=DIR [LIMIT=seconds] [STEPS="..."] bench/device/run.sh
# Steps (default all): table1 tests skeleton_eval table2 large huge huge_vulkan batch. A step
# whose estimate no longer fits in LIMIT is skipped, so the run ends inside its lease.
set -u
LIMIT=${LIMIT:-470}
STEPS=${STEPS:-table1 tests skeleton_eval table2 large huge huge_vulkan batch}
T0=$(date +%s)
exec > >(tee -a "$OUT/log.txt") 2>&1
el() { echo $(( $(date +%s) - T0 )); }
stamp() { echo "=== [$(el)s] $*"; }
R=$PWD
RES=/tmp/res; mkdir -p $RES
pack() { tar -C /tmp -czf "$OUT/results.tgz" res 2>/dev/null; }
# step NAME EST TIMEOUT CMD...: runs when STEPS names it and its estimate fits (TIMEOUT 0: none)
step() {
  local name=$1 est=$2 to=$3; shift 3
  [[ " $STEPS " == *" $name "* ]] || return 0
  if (( $(el) + est > LIMIT )); then stamp "SKIP $name (budget)"; return; fi
  stamp "BEGIN $name"
  local t=$(date +%s%N)
  if (( to > 0 )); then timeout -k 5 "$to" "$@"; else "$@"; fi; local rc=$?
  stamp "END $name rc=$rc wall=$(( ($(date +%s%N) - t) / 1000000 ))ms"
  pack
}

stamp setup
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
# The tests and benches carry absolute paths of the machine that built them (/work/main here).
[ "$R" != /work/main ] && mkdir -p /work && ln -sfn "$R" /work/main
mkdir -p /usr/share/doc/libcgal-dev && cp .dev/data.tar.gz /usr/share/doc/libcgal-dev/
tar -xJf .dev/payload.tar.xz -C "$R"
mkdir -p build/tests/data && tar -xzf .dev/data.tar.gz -C build/tests/data --strip-components=2 data/meshes/
mkdir -p build/apps/bench/skeleton_eval_data build/apps/bench/skeleton_bench_data
tar -xzf .dev/data.tar.gz -C build/apps/bench/skeleton_eval_data --strip-components=1
cp build/apps/bench/skeleton_eval_data/meshes/{elephant,refined_elephant,camel,hand}.off build/apps/bench/skeleton_bench_data/
NV=""
for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do [ -d $d ] && NV="$NV:$d"; done
export LD_LIBRARY_PATH="$R/devlib$NV"
for j in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json; do
  if [ -f $j ]; then export VK_DRIVER_FILES=$j VK_ICD_FILENAMES=$j; break; fi
done
ocl=$(find /usr/local/nvidia /usr/lib /usr/lib64 /lib -name 'libnvidia-opencl.so*' 2>/dev/null | head -1)
mkdir -p /tmp/ocl-vendors
[ -n "$ocl" ] && echo "$ocl" > /tmp/ocl-vendors/nvidia.icd
cp /etc/OpenCL/vendors/*.icd /tmp/ocl-vendors/ 2>/dev/null
export OCL_ICD_VENDORS=/tmp/ocl-vendors
{
  echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-none}"
  for f in /tmp/ocl-vendors/*.icd; do echo "$f: $(cat $f)"; done
  grep PRETTY /etc/os-release; ldd --version | head -1; nproc; free -g | head -2
  grep -m1 'model name' /proc/cpuinfo
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
} | tee $RES/machine.txt
build/apps/sdfkit devices 2>&1 | tee $RES/devices.txt
pack

S=build/apps/sdfkit
B=build/apps/bench
gpu_tests() {
  local pids=""
  for b in build/tests/vulkan/vulkan_engine_test build/tests/vulkan/vulkan_depth_peel_test \
           build/tests/vulkan/vulkan_depth_peel_reference_test build/tests/vulkan/vulkan_render_graph_test \
           build/tests/vulkan/vulkan_push_constants_test build/tests/opencl/sdfkit_opencl_tests \
           build/tests/pipeline/sdfkit_pipeline_tests build/tests/diffusion/sdfkit_diffuse_tests \
           build/tests/render/sdfkit_render_tests build/tests/pointcloud/sdfkit_pointcloud_device_tests \
           build/tests/cli/sdfkit_cli_tests build/tests/skeleton/sdfkit_skeleton_tests; do
    local n=$(basename $b)
    ( cd $(dirname $b) && timeout -k 5 150 ./$n --gtest_brief=1 > $RES/test_$n.txt 2>&1; echo "rc=$?" >> $RES/test_$n.txt ) &
    pids="$pids $!"
  done
  wait $pids   # not a bare wait: that also waits for the log's tee
  for f in $RES/test_*.txt; do
    echo "-- $f: $(tail -1 $f) $(grep -E '^\[  (PASSED|FAILED|SKIPPED)' $f | tr '\n' ' ')"
  done
}
# Table 1 with the CGAL anchor (sdf_values, one process per mesh, on this machine's CPU)
step table1 120 170 $S bench --repeats 3 --backends vulkan,opencl,opencl-octree,embree --work-dir /tmp/w1 \
  --markdown $RES/table1.md --json $RES/table1.json
step tests 60 0 gpu_tests
# CGAL's MCF on each mesh as it is, live, beside ours: the speed column (SDF terms on only)
step skeleton_eval 60 130 sh -c "$B/sdfkit_skeleton_bench --eval $B/skeleton_eval_data --no-sdf-off > $RES/skeleton_eval.txt 2>&1"
step table2 100 130 $S bench --diffusion --repeats 3 --work-dir /tmp/w2 --markdown $RES/table2.md --json $RES/table2.json
step large 60 100 $S bench --large --no-cgal --repeats 3 --backends vulkan,opencl,embree --work-dir /tmp/w3 \
  --markdown $RES/large.md --json $RES/large.json
step huge 60 120 $S bench --huge --huge-levels 3,4 --huge-formats ply --huge-backend opencl --work-dir /tmp/w4
step huge_vulkan 40 90 $S bench --huge --huge-levels 3,4 --huge-formats ply --huge-backend vulkan --work-dir /tmp/w5
step batch 40 90 $S bench --batch 300 --batch-jobs 4 --work-dir /tmp/w6
stamp done
pack
