#!/usr/bin/env bash
# A real Slurm on this machine: configures Debian's slurm-wlm (slurmctld + slurmd) and munge as a
# single-node cluster on localhost, submits `sbatch --array=0-3 scripts/slurm-batch.sbatch` over a
# generated list of assets, waits for the array, and checks that every asset has exactly one
# complete result and that the four shard reports add up to the list.
#
#   scripts/slurm-local.sh [BUILD_DIR]        (as root; slurm-wlm and munge from install-deps.sh)
#
# Everything it starts (munged, slurmctld, slurmd) is stopped at the end; state lives in a
# temporary directory. Exit status 0 only when every check passed.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
build=$(realpath "${1:-build}")
[ -x "$build/apps/sdfkit" ] || { echo "slurm-local: $build/apps/sdfkit not built" >&2; exit 2; }
# Exit 77 (CTest's skip) where this machine cannot run it: the tools are missing or not root.
for tool in slurmctld slurmd sbatch squeue sinfo munged; do
  command -v "$tool" >/dev/null || { echo "slurm-local: $tool missing (scripts/install-deps.sh installs slurm-wlm)" >&2; exit 77; }
done
[ "$(id -u)" = 0 ] || { echo "slurm-local: needs root (it starts slurmctld and slurmd as root)" >&2; exit 77; }

work=$(mktemp -d /tmp/sdfkit-slurm.XXXXXX)
node=$(hostname -s)
cpus=$(nproc)
pids=()
cleanup() {
  local status=$?
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [ "$status" = 0 ]; then rm -rf "$work"; else echo "slurm-local: logs kept in $work/log" >&2; fi
}
trap cleanup EXIT
start=$(date +%s)

# munge: a fresh key and socket in the work directory.
mkdir -p "$work/munge" "$work/spool/ctld" "$work/spool/d" "$work/log"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$work/munge"; chmod 400 "$work/munge/munge.key"
munged --foreground --force --key-file "$work/munge/munge.key" --socket "$work/munge/socket" \
  --pid-file "$work/munge/munged.pid" --log-file "$work/log/munged.log" --seed-file "$work/munge/seed" \
  >"$work/log/munged.out" 2>&1 &
pids+=($!)

cat > "$work/slurm.conf" <<CONF
ClusterName=sdfkit-local
SlurmctldHost=$node(127.0.0.1)
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/spool/ctld
SlurmdSpoolDir=$work/spool/d
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
sleep 1
slurmctld -D -f "$SLURM_CONF" >"$work/log/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/log/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 60); do sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break; sleep 1; done
sinfo

# 12 assets: CGAL meshes and built-in shapes, one path per line.
mkdir -p "$work/assets"
tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$work/assets" --strip-components=2 \
  data/meshes/cow.off data/meshes/elephant.off data/meshes/cube-ouvert.off data/meshes/armadillo.off
for i in $(seq 0 7); do cp "$work/assets/cow.off" "$work/assets/cow-copy$i.off"; done
ls "$work/assets"/*.off > "$work/assets.list"
n_assets=$(wc -l < "$work/assets.list")

# The README's job array, as users run it (cores per task fitted to this node).
export PATH="$build/apps:$PATH"
job=$(sbatch --parsable --array=0-3 --cpus-per-task=1 --output="$work/log/task-%a.out" \
  "$repo/scripts/slurm-batch.sbatch" "$work/assets.list" "$work/out")
echo "slurm-local: submitted array job $job ($n_assets assets, 4 tasks)"
for _ in $(seq 600); do
  [ -z "$(squeue -h -j "$job" 2>/dev/null)" ] && break
  sleep 1
done
[ -z "$(squeue -h -j "$job" 2>/dev/null)" ] || { echo "slurm-local: array job $job did not finish" >&2; exit 1; }
for t in 0 1 2 3; do echo "  task $t: $(tail -n 1 "$work/log/task-$t.out")"; done

# Checks: one complete result per asset; the shard reports cover the list exactly once.
python3 - "$work" "$n_assets" <<'PY'
import json, pathlib, sys
work, n = pathlib.Path(sys.argv[1]), int(sys.argv[2])
assets = [pathlib.Path(l.strip()) for l in open(work / "assets.list") if l.strip()]
out = work / "out"
reports = sorted(out.glob("batch-report-shard*-of-4.json"))
seen = {}
for r in reports:
    for a in json.load(open(r))["assets"]:
        seen.setdefault(a["input"], []).append((r.name, a["status"]))
bad = []
if len(reports) != 4: bad.append(f"{len(reports)} shard reports, expected 4")
for a in assets:
    entries = seen.get(str(a), [])
    if len(entries) != 1: bad.append(f"{a.name}: in {len(entries)} shard reports")
    elif entries[0][1] != "done": bad.append(f"{a.name}: {entries[0][1]}")
    rec = out / (a.stem + ".json")
    results = list(out.glob(a.stem + ".*"))
    outputs = [p for p in results if p.suffix not in (".json",) and ".tmp" not in p.name]
    if not rec.exists() or not json.load(open(rec)).get("ok"): bad.append(f"{a.name}: no ok record")
    if len(outputs) != 1: bad.append(f"{a.name}: {len(outputs)} outputs")
if sum(len(v) for v in seen.values()) != n: bad.append("the shard reports do not add up to the list")
for r in reports: print(f"  {r.name}: {len(json.load(open(r))['assets'])} assets")
if bad:
    print("slurm-local: FAILED\n  " + "\n  ".join(bad)); sys.exit(1)
print(f"slurm-local: OK: {n} assets, each with exactly one complete result; 4 shard reports add up")
PY
echo "slurm-local: $(( $(date +%s) - start )) s in all"
