#!/usr/bin/env bash
# Builds the libFuzzer harnesses (CMake preset `fuzz`: clang-14, ASan + UBSan) and runs each for
# SECONDS on its corpus: fuzz/corpus/<harness>/ (committed seeds, read only) plus a working copy
# in $out/corpus/<harness>/ that keeps what the run adds. One harness at a time, niced
# (SDFKIT_FUZZ_NICE, default 10).
# Usage: scripts/fuzz.sh [SECONDS=30] [HARNESS...]   (harnesses: gltf obj off ply_ascii
#        ply_binary manifest; default all)
# $out is build-fuzz, or SDFKIT_FUZZ_OUT. Logs: $out/logs/<harness>.log; crashes, leaks and
# timeouts: $out/artifacts/<harness>-*. SDFKIT_FUZZ_NO_BUILD=1 runs what build-fuzz has. Prints one summary line per harness (executions, coverage,
# features, corpus size) and exits 1 if any harness found something.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
shift || true
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then harnesses=(gltf obj off ply_ascii ply_binary manifest); fi

launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
if [ "${SDFKIT_FUZZ_NO_BUILD:-0}" != "1" ]; then  # 1: run what build-fuzz already has
  cmake --preset fuzz "${launcher[@]}" >/dev/null
  cmake --build --preset fuzz -j"$(nproc)"
fi

out="${SDFKIT_FUZZ_OUT:-build-fuzz}"   # logs/, artifacts/, corpus/ (the working copies)
mkdir -p "$out/logs" "$out/artifacts"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
status=0
for h in "${harnesses[@]}"; do
  exe="build-fuzz/fuzz/fuzz_$h"
  [ -x "$exe" ] || { echo "fuzz.sh: no harness '$h'" >&2; exit 2; }
  work="$out/corpus/$h"
  mkdir -p "$work"
  log="$out/logs/$h.log"
  rm -f "$out/artifacts/$h"-*
  # -timeout: one input taking longer is a hang; -rss_limit_mb / -malloc_limit_mb: an input
  # making the loader allocate more than this is a finding (the harness sets 1M-triangle limits).
  rc=0
  start=$(date +%s)
  nice -n "${SDFKIT_FUZZ_NICE:-10}" "$exe" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$out/artifacts/$h-" \
    "$work" "fuzz/corpus/$h" >"$log" 2>&1 || rc=$?
  elapsed=$(($(date +%s) - start))
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  cov=$(grep -o 'cov: [0-9]*' <<<"$last" | grep -o '[0-9]*' || true)
  ft=$(grep -o 'ft: [0-9]*' <<<"$last" | grep -o '[0-9]*' || true)
  corp=$(grep -o 'corp: [0-9]*/[0-9a-zA-Z]*' <<<"$last" | sed 's/corp: //' || true)
  found=$(find "$out/artifacts" -name "$h-*" | wc -l)
  echo "fuzz $h: ${elapsed}s, ${execs:-?} executions, cov ${cov:-?}, ft ${ft:-?}, corpus ${corp:-?}, findings $found (rc $rc)"
  if [ "$rc" -ne 0 ] || [ "$found" -ne 0 ]; then
    status=1
    grep -E 'ERROR|SUMMARY|runtime error|==[0-9]+==' "$log" | head -5 >&2 || true
  fi
done
exit $status
