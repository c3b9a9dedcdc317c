#!/usr/bin/env bash
# test-local.sh: a real end-to-end test of the Slurm path on this one machine.
#
#   sudo bash tools/slurm/test-local.sh
#
# What it does (as root, on Debian/Ubuntu):
#   1. installs Debian's slurm-wlm, munge and python3 if missing (apt-get, non-interactive);
#   2. sets up a private single-node cluster under $WORK (default /tmp/blutrace-slurm-test):
#      its own munge key and munged socket, a minimal slurm.conf (loopback only, ports
#      16817/16818, no cgroups, no accounting) and starts munged, slurmctld and slurmd in
#      the foreground (-F/-D) as background jobs of this script. Nothing in /etc is touched
#      and a system munge/Slurm, if any, is left alone;
#   3. builds blutrace in release (cargo build --release; skipped if BLUTRACE is set);
#   4. submits scenes/notebook14, PHOTONS photons over SHARDS shards with submit.sh,
#      waits for the merge job, traces the same run in one process as the reference and
#      compares: flux.png byte for byte; summary.json ledger, uniformity,
#      uniformity_stderr and extraction_efficiency exactly; flux.exr and angular.exr
#      byte for byte;
#   5. prints PASS or FAIL, exits 0 or 1, and stops the daemons it started (trap on exit).
# Running it again first stops daemons a previous run left behind (recorded pids) and
# starts from an empty $WORK. The work folder is kept for inspection.
#
# Environment (optional): WORK, PHOTONS (400000), SHARDS (4), SEED (7), SCENE,
# CPUS_PER_TASK (threads per shard, 1), BLUTRACE (use this binary, no build), TIMEOUT
# (seconds to wait for the jobs, 1800), CTLD_PORT (16817), SLURMD_PORT (16818).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
WORK=${WORK:-/tmp/blutrace-slurm-test}
PHOTONS=${PHOTONS:-400000}
SHARDS=${SHARDS:-4}
SEED=${SEED:-7}
SCENE=${SCENE:-$repo/scenes/notebook14}
TIMEOUT=${TIMEOUT:-1800}
CTLD_PORT=${CTLD_PORT:-16817}
SLURMD_PORT=${SLURMD_PORT:-16818}
NODE=localhost # the node's Slurm name; slurmd is started with -N $NODE

log() { printf '[%4ds] %s\n' "$SECONDS" "$*"; }
die() {
    log "FAIL: $*"
    exit 1
}

[ "$(id -u)" = 0 ] || die "run as root (installs packages and starts Slurm daemons)"

# ---------------------------------------------------------------- stop what we started
# Daemon pids are recorded in $WORK/pids/NAME; stop_daemons only signals those pids and
# only while they still are the program we started (checked via /proc/PID/comm).
alive() { # alive NAME: the recorded pid of NAME still runs NAME
    [ -f "$WORK/pids/$1" ] && [ "$(cat "/proc/$(cat "$WORK/pids/$1")/comm" 2>/dev/null)" = "$1" ]
}
job_processes() { # pids running $WORK/bin/blutrace, i.e. shards or merges of our jobs
    local p
    for p in /proc/[0-9]*; do
        [ "$(readlink "$p/exe" 2>/dev/null)" = "$WORK/bin/blutrace" ] && echo "${p#/proc/}"
    done
    return 0
}
stop_daemons() {
    local name pid jobs
    [ -d "$WORK/pids" ] || return 0
    # First cancel whatever runs on this private cluster (a timeout, Ctrl-C, or a previous
    # run killed hard), so that no job keeps running or writing into $WORK afterwards.
    if alive slurmctld && alive slurmd; then
        jobs=$(SLURM_CONF="$WORK/etc/slurm.conf" squeue -h -o %A 2>/dev/null | sort -u | tr '\n' ' ')
        if [ -n "${jobs// /}" ]; then
            log "cancelling jobs $jobs"
            # shellcheck disable=SC2086 # a list of job ids
            SLURM_CONF="$WORK/etc/slurm.conf" scancel $jobs 2>/dev/null || true
            # Wait until they are gone from squeue and their blutrace processes (our copy of
            # the binary) have exited.
            for _ in $(seq 60); do
                [ -z "$(SLURM_CONF="$WORK/etc/slurm.conf" squeue -h -o %A 2>/dev/null)" ] &&
                    [ -z "$(job_processes)" ] && break
                sleep 0.5
            done
        fi
    fi
    for name in slurmd slurmctld munged; do
        if alive "$name"; then
            pid=$(cat "$WORK/pids/$name")
            kill -TERM "$pid" 2>/dev/null || true
            for _ in $(seq 50); do # up to 10 s, then SIGKILL
                alive "$name" || break
                sleep 0.2
            done
            if alive "$name"; then kill -KILL "$pid" 2>/dev/null || true; fi
            log "stopped $name (pid $pid)"
        fi
        rm -f "$WORK/pids/$name"
    done
}

cleanup() {
    local rc=$?
    trap - EXIT INT TERM
    stop_daemons
    log "work folder kept: $WORK"
    exit "$rc"
}

# ---------------------------------------------------------------- 0. fresh work folder
# A previous run killed hard (no trap) may have left daemons: stop them first.
stop_daemons
if [ -e "$WORK" ]; then
    [ -f "$WORK/.blutrace-slurm-test" ] ||
        die "$WORK exists and is not a work folder of this script; set WORK elsewhere"
    rm -rf -- "$WORK"
fi
trap cleanup EXIT
trap 'exit 130' INT TERM

# ---------------------------------------------------------------- 1. packages
missing=()
for p in slurm-wlm munge python3; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' ||
        missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    log "installing ${missing[*]} (apt-get)"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq "${missing[@]}" >/dev/null
fi
log "slurm-wlm $(dpkg-query -W -f='${Version}' slurm-wlm), munge $(dpkg-query -W -f='${Version}' munge)"

# ---------------------------------------------------------------- 2. private cluster
# munged insists on: socket folder (and its parents) executable by all, key folder private.
umask 022
mkdir -p "$WORK"
touch "$WORK/.blutrace-slurm-test"
mkdir "$WORK/munge" "$WORK/etc" "$WORK/state" "$WORK/spool" "$WORK/log" \
    "$WORK/pids" "$WORK/bin"
mkdir -m 700 "$WORK/munge/key" "$WORK/munge/lib"
sock="$WORK/munge/munge.socket"

# Munge key: 1024 random bits, private to root (munged runs as root here).
mungekey --create --keyfile="$WORK/munge/key/munge.key" 2>/dev/null ||
    { dd if=/dev/urandom of="$WORK/munge/key/munge.key" bs=128 count=1 status=none &&
        chmod 600 "$WORK/munge/key/munge.key"; }

munged -F --socket="$sock" --key-file="$WORK/munge/key/munge.key" \
    --pid-file="$WORK/munge/lib/munged.pid" --seed-file="$WORK/munge/lib/munged.seed" \
    --log-file="$WORK/log/munged.log" >"$WORK/log/munged.out" 2>&1 &
echo $! >"$WORK/pids/munged"
for i in $(seq 100); do
    munge -n -S "$sock" 2>/dev/null | unmunge -S "$sock" >/dev/null 2>&1 && break
    [ "$i" = 100 ] && { cat "$WORK/log/munged.out"; die "munged does not answer on $sock"; }
    sleep 0.2
done
log "munged up (pid $(cat "$WORK/pids/munged")), socket $sock"

# The node as this machine really is: CPUs, sockets, cores, threads and memory from
# `slurmd -C` (its first line, without its NodeName).
hw=$(slurmd -C | head -1 | sed 's/^NodeName=[^ ]* //')
cat >"$WORK/etc/slurm.conf" <<EOF
# Single-node test cluster written by tools/slurm/test-local.sh
ClusterName=blutrace-test
SlurmctldHost=localhost
SlurmctldAddr=127.0.0.1
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
# Our own munged socket, for authentication and job credentials.
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/state/slurmctld.pid
SlurmdPidFile=$WORK/spool/slurmd.pid
SlurmctldLogFile=$WORK/log/slurmctld.log
SlurmdLogFile=$WORK/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
MailProg=/bin/true
# No cgroups: track processes by parent pid, no task binding, no accounting.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
# Cores are the consumable resource (memory is not, so jobs need no --mem).
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
# Keep finished jobs visible to scontrol for 10 minutes.
MinJobAge=600
NodeName=$NODE NodeAddr=127.0.0.1 $hw State=UNKNOWN
PartitionName=test Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$WORK/etc/slurm.conf" # read by slurmctld, slurmd, sbatch, squeue, ...
log "slurm.conf: NodeName=$NODE $hw"

# Foreground daemons (-D) in the background of this script: no daemonizing, and $! is
# the daemon's pid. -c: start with empty state; -N: the node name in slurm.conf.
slurmctld -D -c -f "$SLURM_CONF" >"$WORK/log/slurmctld.out" 2>&1 &
echo $! >"$WORK/pids/slurmctld"
for i in $(seq 100); do
    scontrol ping 2>/dev/null | grep -q 'is UP' && break
    [ "$i" = 100 ] && { tail "$WORK/log/slurmctld.log"; die "slurmctld does not answer"; }
    sleep 0.2
done
slurmd -D -N "$NODE" -f "$SLURM_CONF" >"$WORK/log/slurmd.out" 2>&1 &
echo $! >"$WORK/pids/slurmd"
log "slurmctld (pid $(cat "$WORK/pids/slurmctld")) and slurmd (pid $(cat "$WORK/pids/slurmd")) started"

# Wait until the node is idle.
for i in $(seq 120); do
    state=$(sinfo -h -n "$NODE" -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    if [ "$i" = 120 ]; then
        sinfo -R || true
        tail "$WORK/log/slurmd.log" "$WORK/log/slurmctld.log" || true
        die "node $NODE is '$state', not idle, after 60 s"
    fi
    sleep 0.5
done
log "node $NODE idle: $(sinfo -h -o '%P %D node(s) %c CPUs %m MB')"

# ---------------------------------------------------------------- 3. blutrace
if [ -z "${BLUTRACE:-}" ]; then
    command -v cargo >/dev/null ||
        die "cargo not found: install Rust (https://rustup.rs) or set BLUTRACE to a binary"
    log "cargo build --release"
    (cd "$repo" && cargo build --release --quiet --bin blutrace) || die "cargo build failed"
    BLUTRACE="$repo/target/release/blutrace"
fi
# A private copy: shards, merge and reference all use the same binary, even if the
# checkout is rebuilt meanwhile.
cp "$BLUTRACE" "$WORK/bin/blutrace"
export BLUTRACE="$WORK/bin/blutrace"
log "blutrace: $("$BLUTRACE" --version)"

# ---------------------------------------------------------------- 4. the Slurm run
run="$WORK/run"
log "submit: $SCENE, $PHOTONS photons, seed $SEED, $SHARDS shards"
ids=$(cd "$WORK" && bash "$here/submit.sh" "$SCENE" "$PHOTONS" "$SHARDS" "$run" "$SEED") ||
    die "submit.sh failed"
array_job=$(sed -n 's/^array_job=//p' <<<"$ids")
merge_job=$(sed -n 's/^merge_job=//p' <<<"$ids")
[ -n "$array_job" ] && [ -n "$merge_job" ] || die "submit.sh printed no job ids: $ids"
log "submitted: array job $array_job, merge job $merge_job"
squeue

# Poll the merge job until it ends (it is cancelled if a shard fails: --kill-on-invalid-dep).
t0=$SECONDS
last=''
while :; do
    info=$(scontrol -o show job "$merge_job" 2>/dev/null || true)
    jstate=$(grep -o 'JobState=[A-Z_]*' <<<"$info" | cut -d= -f2)
    reason=$(grep -o 'Reason=[^ ]*' <<<"$info" | cut -d= -f2)
    running=$(squeue -h -j "$array_job" -t R -o %i 2>/dev/null | tr '\n' ' ')
    now="$jstate/$reason; array tasks running: ${running:-none}"
    [ "$now" != "$last" ] && log "merge job $merge_job $now"
    last=$now
    case $jstate in
    COMPLETED) break ;;
    FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY | PREEMPTED | BOOT_FAIL | DEADLINE)
        for f in "$run"/logs/*; do
            echo "--- $f"
            tail -n 5 "$f"
        done
        die "merge job $merge_job ended $jstate ($reason)"
        ;;
    '') die "merge job $merge_job unknown to slurmctld" ;;
    esac
    [ "$reason" = DependencyNeverSatisfied ] && die "a shard failed: merge job never runs"
    ((SECONDS - t0 < TIMEOUT)) || die "jobs not done after $TIMEOUT s"
    sleep 1
done
slurm_s=$((SECONDS - t0))

# What each job did, from slurmctld and the job logs.
scontrol -o show job "$array_job" | while read -r line; do
    grep -o 'JobId=[0-9]* ArrayJobId=[0-9]* ArrayTaskId=[0-9]*\|JobState=[A-Z]*\|RunTime=[^ ]*\|ExitCode=[^ ]*' <<<"$line" |
        tr '\n' ' '
    echo
done | sed 's/^/    /'
grep -h '^shard\|^done' "$run"/logs/trace-*.out | sed 's/^/    /'
grep -h '^time\|^traced' "$run"/logs/merge-*.out | sed 's/^/    /'
log "Slurm run done in ${slurm_s} s (submit to merged outputs)"

# ---------------------------------------------------------------- 5. reference and compare
ref="$WORK/ref"
t0=$SECONDS
"$BLUTRACE" trace "$SCENE" --photons "$PHOTONS" --seed "$SEED" --quiet --out "$ref" \
    >"$WORK/log/reference.out" || die "reference run failed"
grep '^time' "$WORK/log/reference.out" | sed 's/^/    /'
log "reference (one process) done in $((SECONDS - t0)) s"

if ! python3 - "$run/merged" "$ref" <<'EOF'
import json, sys
from pathlib import Path

run, ref = Path(sys.argv[1]), Path(sys.argv[2])
ok = True

def check(name, same):
    global ok
    ok &= same
    print(f"    {'PASS' if same else 'FAIL'} {name}")

a, b = (run / "flux.png").read_bytes(), (ref / "flux.png").read_bytes()
check(f"flux.png byte for byte ({len(a)} bytes)", a == b)
sa = json.loads((run / "summary.json").read_text())
sb = json.loads((ref / "summary.json").read_text())
for key in ["ledger", "uniformity", "uniformity_stderr", "extraction_efficiency"]:
    same = key in sa and sa.get(key) == sb.get(key)
    check(f"summary.json {key}", same)
    if not same:
        print(f"      merged:    {json.dumps(sa.get(key))}\n      reference: {json.dumps(sb.get(key))}")
print(f"    photons {sa['photons']} / {sb['photons']}, seed {sa['seed']} / {sb['seed']}, "
      f"extraction efficiency {sa['extraction_efficiency']:.6f}, cv {sa['uniformity']['cv']:.6f}")

# Not part of the verdict, for information: the other summary fields.
timing = {"runtime_s", "photons_per_s", "interactions_per_s", "threads", "figure_of_merit", "backend"}
other = [k for k in sorted(set(sa) | set(sb)) if k not in timing and sa.get(k) != sb.get(k)]
print(f"    note: other summary.json fields that differ: {', '.join(other) or 'none'}")

# EXR files, byte for byte (blutrace writes header attributes in name order).
for f in ["flux.exr", "angular.exr"]:
    a, b = (run / f).read_bytes(), (ref / f).read_bytes()
    check(f"{f} ({len(a)} bytes)", a == b)
sys.exit(0 if ok else 1)
EOF
then
    die "merged Slurm run differs from the single-process run"
fi
log "PASS: $SHARDS Slurm shards merged equal one process ($PHOTONS photons, seed $SEED)"
