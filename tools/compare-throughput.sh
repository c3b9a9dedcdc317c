#!/usr/bin/env bash
# Compare the photon throughput of two blutrace binaries (say, before and after a change):
# single-threaded `trace` runs, the two binaries interleaved, CPU (user) seconds per run,
# medians and minima of ROUNDS runs each. Single-threaded CPU time is what to compare on
# a shared machine: it moves far less with other load than wall time does. It also says
# whether the two wrote the same flux map (same physics, same random numbers, same bits).
#
#   bash tools/compare-throughput.sh OLD_BINARY NEW_BINARY [SCENE] [PHOTONS] [ROUNDS]
#
# Defaults: scenes/notebook14, 2000000 photons, 5 rounds. To get the previous release's
# binary: git worktree add /tmp/old <commit> && (cd /tmp/old && cargo build --release).
set -euo pipefail
old=$1 new=$2
scene=${3:-scenes/notebook14} photons=${4:-2000000} rounds=${5:-5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
declare -a t_old t_new
for _ in $(seq "$rounds"); do
  for which in old new; do
    bin=${!which}
    /usr/bin/time -f %U -o "$work/t" "$bin" trace "$scene" --photons "$photons" --threads 1 \
      --quiet --out "$work/$which" >/dev/null 2>&1
    if [ "$which" = old ]; then t_old+=("$(cat "$work/t")"); else t_new+=("$(cat "$work/t")"); fi
  done
done
python3 - "${t_old[*]}" "${t_new[*]}" "$photons" <<'PY'
import statistics, sys
old = [float(x) for x in sys.argv[1].split()]
new = [float(x) for x in sys.argv[2].split()]
n = int(sys.argv[3])
for name, t in (("old", old), ("new", new)):
    print(f"{name}: CPU s {sorted(t)}  median {statistics.median(t):.2f}  "
          f"photons/s (median) {n / statistics.median(t):.0f}")
print(f"speed-up new/old: median {statistics.median(old) / statistics.median(new):.3f}, "
      f"minimum {min(old) / min(new):.3f}")
PY
if cmp -s "$work/old/flux.exr" "$work/new/flux.exr"; then
  echo "flux maps: identical"
else
  echo "flux maps: differ (expected when the random numbers or the physics changed)"
fi
