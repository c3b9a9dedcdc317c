#!/usr/bin/env bash
# submit.sh: submit a sharded blutrace run to Slurm: a job array of SHARDS trace tasks and
# a merge job that starts once all of them succeeded (--dependency=afterok).
#
#   tools/slurm/submit.sh SCENE PHOTONS SHARDS OUT [SEED]
#
# Writes OUT/shards/K/shard.json (one per task), the merged outputs of the run in
# OUT/merged (flux.exr, angular.exr, flux.png, convergence.csv/png, summary.json) and the jobs' logs
# in OUT/logs. Prints the job ids as "array_job=ID" and "merge_job=ID" lines on stdout.
# SEED defaults to 1 (the default [trace] seed of scenes); give it to be explicit.
#
# Environment (optional):
#   BLUTRACE       blutrace binary; default: blutrace on PATH, else this checkout's
#                  target/release/blutrace. Must be at the same path on the compute nodes.
#   CPUS_PER_TASK  cores (= blutrace threads) per shard; default 1
#   MAX_PARALLEL   run at most this many shards at once (array throttle --array=...%N)
#   Anything else through sbatch's own variables, which apply to both jobs, e.g.
#   SBATCH_PARTITION, SBATCH_ACCOUNT, SBATCH_TIMELIMIT, SBATCH_MEM_PER_CPU, SBATCH_QOS.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
die() {
    echo "submit.sh: error: $*" >&2
    exit 2
}
usage() {
    sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "${BASH_SOURCE[0]}" >&2
    exit 2
}
[ $# -ge 4 ] && [ $# -le 5 ] || usage
scene=$1 photons=$2 shards=$3 out=$4 seed=${5:-1}

[[ $photons =~ ^[0-9]+$ ]] && ((photons > 0)) || die "PHOTONS must be a positive whole number, got '$photons'"
[[ $shards =~ ^[0-9]+$ ]] && ((shards > 0)) || die "SHARDS must be a positive whole number, got '$shards'"
[[ $seed =~ ^[0-9]+$ ]] || die "SEED must be a whole number, got '$seed'"
[ -e "$scene" ] || die "scene $scene does not exist"
command -v sbatch >/dev/null || die "sbatch not found: run this on a Slurm login node"

# The binary: $BLUTRACE, else blutrace on PATH, else this checkout's release build.
if [ -z "${BLUTRACE:-}" ]; then
    BLUTRACE=$(command -v blutrace || true)
    [ -n "$BLUTRACE" ] || BLUTRACE="$here/../../target/release/blutrace"
fi
[ -x "$BLUTRACE" ] || die "blutrace binary $BLUTRACE not found or not executable (set BLUTRACE, or cargo build --release)"

# Absolute paths: the jobs run elsewhere, and the scene path is recorded in the shards.
SCENE=$(readlink -f -- "$scene")
BLUTRACE=$(readlink -f -- "$BLUTRACE")
mkdir -p -- "$out/shards" "$out/logs"
OUT=$(readlink -f -- "$out")
PHOTONS=$photons SEED=$seed SHARDS=$shards
export BLUTRACE SCENE PHOTONS SEED OUT SHARDS

array="0-$((shards - 1))"
if [ -n "${MAX_PARALLEL:-}" ]; then
    array+="%$MAX_PARALLEL"
fi

# --parsable prints "jobid" or "jobid;cluster".
array_job=$(sbatch --parsable --export=ALL \
    --array="$array" --cpus-per-task="${CPUS_PER_TASK:-1}" \
    --output="$OUT/logs/trace-%A_%a.out" \
    "$here/trace-array.sbatch")
array_job=${array_job%%;*}
merge_job=$(sbatch --parsable --export=ALL \
    --dependency="afterok:$array_job" --kill-on-invalid-dep=yes \
    --output="$OUT/logs/merge-%j.out" \
    "$here/merge.sbatch")
merge_job=${merge_job%%;*}

echo "# $SCENE: $PHOTONS photons, seed $SEED, $SHARDS shards -> $OUT" >&2
echo "# trace array job $array_job (tasks $array), merge job $merge_job (afterok:$array_job)" >&2
echo "array_job=$array_job"
echo "merge_job=$merge_job"
