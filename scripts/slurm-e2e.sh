#!/usr/bin/env bash
# End to end on a real Slurm cluster: starts a one-node cluster on 127.0.0.1 (its own munge key,
# slurmctld and slurmd, no accounting database) from a configuration written in a temporary
# folder, renders a scene through `englobe farm slurm` as 8 tiles, cancels one running array task
# on purpose, shows that `--resume` completes the image, and compares the bytes (PNG and EXR) with
# a single-process render. Every daemon it started is stopped by its pid, whatever happens.
#
# Needs root (for apt-get and slurmd). Installs Debian's slurm-wlm and munge when missing.
# Usage: scripts/slurm-e2e.sh [path/to/englobe]   (default: target/debug/englobe, built if needed)
set -euo pipefail
cd "$(dirname "$0")/.."

[ "$(id -u)" = 0 ] || { echo "slurm-e2e: needs root (apt-get, slurmd)" >&2; exit 1; }
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "slurm-e2e: installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -q slurm-wlm munge >/dev/null 2>&1 || { apt-get update -q >/dev/null && apt-get install -y -q slurm-wlm munge >/dev/null; }
fi

ENGLOBE=${1:-target/debug/englobe}
[ -x "$ENGLOBE" ] || cargo build -q -p englobe-cli
ENGLOBE=$(realpath "$ENGLOBE")
SCENE=$(realpath scenes/cornell-box-path.toml)
# About 1.5 s of rendering per tile on one core of a debug build: long enough to catch a task
# while it runs.
OPTS=(--width 128 --height 96 --spp 512)

START=$(date +%s.%N)
elapsed() { python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$START" "$(date +%s.%N)"; }
D=$(mktemp -d -t englobe-slurm.XXXXXX)
PIDFILES=("$D/slurmd.pid" "$D/slurmctld.pid" "$D/munge/munged.pid")
cleanup() {
    status=$?
    set +e
    scancel --full "--name=englobe-cornell-box-path" >/dev/null 2>&1
    for f in "${PIDFILES[@]}"; do
        [ -s "$f" ] && kill "$(cat "$f")" 2>/dev/null
    done
    for f in "${PIDFILES[@]}"; do
        [ -s "$f" ] || continue
        pid=$(cat "$f")
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null
    done
    if [ "$status" != 0 ]; then
        echo "slurm-e2e: FAILED; daemon logs:" >&2
        tail -n 20 "$D"/log/*.log >&2
    fi
    rm -rf "$D"
    exit "$status"
}
trap cleanup EXIT INT TERM

mkdir -p "$D/munge" "$D/state" "$D/spool" "$D/log" "$D/work"
dd if=/dev/urandom of="$D/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$D/munge"
chmod 400 "$D/munge/munge.key"
munged --force --key-file="$D/munge/munge.key" --socket="$D/munge/munge.socket" \
    --pid-file="$D/munge/munged.pid" --log-file="$D/log/munged.log" --seed-file="$D/munge/seed"

free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
CPUS=$(nproc)
MEM=$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2))
cat >"$D/slurm.conf" <<CONF
ClusterName=englobe-e2e
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
AuthType=auth/munge
AuthInfo=socket=$D/munge/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/log/slurmctld.log
SlurmdLogFile=$D/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
MinJobAge=600
NodeName=node0 NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM State=UNKNOWN
PartitionName=e2e Nodes=node0 Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$D/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF" -N node0
for _ in $(seq 300); do
    [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && break
    sleep 0.2
done
[ "$(sinfo -h -o %T)" = idle ] || { echo "slurm-e2e: the node did not come up" >&2; exit 1; }
echo "slurm-e2e: cluster up ($CPUS cores) after $(elapsed) s, in $D"

cd "$D/work"
"$ENGLOBE" render "$SCENE" "${OPTS[@]}" -o one.png -q
"$ENGLOBE" render "$SCENE" "${OPTS[@]}" -o one.exr -q

# First run: cancel one task as soon as one runs. A task can end between `squeue` seeing it run
# and `scancel` reaching it (a tile takes a second or two); that run then rightly succeeds, and it
# is made again from scratch, three times at most. A farm that ignored cancelled tasks would
# succeed every time and fail the check below.
for ATTEMPT in 1 2 3; do
    rm -rf out.png out.png.tiles first.log
    set +e
    "$ENGLOBE" farm slurm "$SCENE" "${OPTS[@]}" --tiles 8 -o out.png --poll 0.3 >first.log 2>&1 &
    FARM=$!
    set -e
    CANCELLED=
    for _ in $(seq 300); do
        if [ -s out.png.tiles/jobs ]; then
            JOB=$(head -1 out.png.tiles/jobs)
            CANCELLED=$(squeue -h --array -j "$JOB" -t RUNNING -o %i 2>/dev/null | head -1)
            [ -n "$CANCELLED" ] && break
        fi
        sleep 0.1
    done
    [ -n "$CANCELLED" ] || { echo "slurm-e2e: no task seen running" >&2; exit 1; }
    scancel "$CANCELLED"
    echo "slurm-e2e: cancelled task $CANCELLED"
    set +e
    wait "$FARM"
    FIRST=$?
    set -e
    cat first.log
    [ "$FIRST" = 0 ] || break
    echo "slurm-e2e: task $CANCELLED ended before its cancel reached it (attempt $ATTEMPT of 3)" >&2
done
[ "$FIRST" != 0 ] || { echo "slurm-e2e: the run with a cancelled task claimed success" >&2; exit 1; }
INDEX=${CANCELLED#*_}
grep -q "1 of 8 tiles missing" first.log
grep -q "tile $INDEX/8" first.log
[ ! -e out.png ] || { echo "slurm-e2e: an image was written despite a missing tile" >&2; exit 1; }

# The resumed run renders the one missing tile and assembles.
"$ENGLOBE" farm slurm "$SCENE" "${OPTS[@]}" --tiles 8 -o out.png --poll 0.3 --resume | tee second.log
grep -q "submitted job .*: 1 of 8 tiles ($INDEX)" second.log
cmp one.png out.png
"$ENGLOBE" assemble out.png.tiles -o out.exr
cmp one.exr out.exr
echo "slurm-e2e: OK after $(elapsed) s: task $CANCELLED cancelled, resumed, image byte-identical to one render (PNG and EXR)"
