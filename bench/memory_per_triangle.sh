#!/usr/bin/env bash
# Peak resident memory of sdfkit per input triangle (SECURITY.md: sizing workers). Writes closed
# UV spheres of increasing size as binary PLY, runs `sdfkit info` (load + weld + topology) and
# `sdfkit compute` on each backend, reads the peak RSS from /usr/bin/time, and prints the
# marginal bytes per triangle between the two largest sizes (the fixed cost of the process,
# drivers and device contexts cancels out).
# Usage: bench/memory_per_triangle.sh [BUILD_DIR=build] [BACKENDS="opencl vulkan"]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
backends="${2:-opencl vulkan}"
sizes="${SIZES:-125 250 500}"   # rings of the spheres: ~4 x rings^2 triangles
mid=$(echo $sizes | awk "{print \$(NF-1)}")
big=$(echo $sizes | awk "{print \$NF}")
sdfkit="$build/apps/sdfkit"
work="$(mktemp -d /tmp/sdfkit-mem-XXXXXX)"
trap 'rm -rf "$work"' EXIT

# A UV sphere with `rings` x `segs` quads (2 triangles each, poles fanned): binary PLY.
sphere() {
  python3 - "$1" "$2" "$3" <<'PY'
import math, struct, sys
rings, segs, path = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
verts = [(0.0, 0.0, 1.0)]
for r in range(1, rings):
    t = math.pi * r / rings
    for s in range(segs):
        p = 2 * math.pi * s / segs
        verts.append((math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)))
verts.append((0.0, 0.0, -1.0))
tris = []
ring = lambda r, s: 1 + (r - 1) * segs + s % segs
for s in range(segs):
    tris.append((0, ring(1, s), ring(1, s + 1)))
for r in range(1, rings - 1):
    for s in range(segs):
        a, b, c, d = ring(r, s), ring(r, s + 1), ring(r + 1, s + 1), ring(r + 1, s)
        tris += [(a, d, c), (a, c, b)]
last = len(verts) - 1
for s in range(segs):
    tris.append((last, ring(rings - 1, s + 1), ring(rings - 1, s)))
with open(path, "wb") as f:
    f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
             "property float y\nproperty float z\nelement face %d\n"
             "property list uchar int vertex_indices\nend_header\n" % (len(verts), len(tris))).encode())
    f.write(b"".join(struct.pack("<3f", *v) for v in verts))
    f.write(b"".join(struct.pack("<B3i", 3, *t) for t in tris))
print(len(tris))
PY
}

peak_kib() { /usr/bin/time -f '%M' -o "$work/time" "$@" >/dev/null 2>"$work/err" || { cat "$work/err" >&2; return 1; }; cat "$work/time"; }

declare -A tris
for size in $sizes; do tris[$size]=$(sphere "$size" "$((2 * size))" "$work/s$size.ply"); done
printf '%-26s' "triangles:"; for size in $sizes; do printf '%12s' "${tris[$size]}"; done; printf '%14s\n' "bytes/tri"
run_row() {
  local name="$1"; shift
  declare -A kib
  for size in $sizes; do kib[$size]=$(peak_kib "$@" "$work/s$size.ply" $( [ "$name" = info ] || echo "-o $work/out.txt" )); done
  printf '%-26s' "$name peak RSS (MiB):"
  for size in $sizes; do printf '%12.1f' "$(echo "${kib[$size]} / 1024" | bc -l)"; done
  printf '%14.0f\n' "$(echo "(${kib[$big]} - ${kib[$mid]}) * 1024 / (${tris[$big]} - ${tris[$mid]})" | bc -l)"
}
run_row info "$sdfkit" info
for b in $backends; do
  run_row "compute --backend $b" "$sdfkit" compute --backend "$b" --rays 30 -q
done
