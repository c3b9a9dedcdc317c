#!/usr/bin/env bash
# Digest of every output blutrace writes for the bundled scenes, with timings left out:
# run it before and after a change that must not change behaviour, and compare.
#
#   bash tools/output-digest.sh > before.txt   # on the old commit
#   bash tools/output-digest.sh > after.txt    # on the new one
#   diff before.txt after.txt                  # empty: byte-identical outputs
#
# Traces every scene under scenes/ (both estimators, two threads, the BVH backend and the
# auto backend), a 2-shard run merged, and a short feedback and Nelder-Mead optimization.
# Images and CSV/JSON are hashed after dropping the fields that measure time.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q
bin=target/release/blutrace
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
photons=${DIGEST_PHOTONS:-30000}

# Hash a run's outputs; summary/optimize JSON and CSV without their time fields.
digest() {
  local dir=$1 label=$2
  find "$dir" -type f | sort | while read -r f; do
    local rel=${f#"$dir"/}
    case "$rel" in
      *convergence.png) continue ;; # its x axis is wall time
      *.json) python3 - "$f" <<'PY' | sha256sum | sed "s|-|$label/$rel|" ;;
import json, sys
TIME = {"runtime_s", "photons_per_s", "interactions_per_s", "figure_of_merit",
        "search_time_s", "wall_time_s", "seconds", "time_s", "threads"}
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in TIME}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open(sys.argv[1]))), sort_keys=True))
PY
      *.csv) python3 - "$f" <<'PY' | sha256sum | sed "s|-|$label/$rel|" ;;
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
if not rows:
    sys.exit(0)
keep = [i for i, h in enumerate(rows[0]) if h not in ("seconds", "time_s", "wall_s")]
for r in rows:
    print(",".join(r[i] for i in keep if i < len(r)))
PY
      # optimized.toml names its geometry by absolute path: hash it relative to the repo.
      *.toml) grep -v '^#' "$f" | sed "s|$PWD/||g" | sha256sum | sed "s|-|$label/$rel|" ;;
      *) sha256sum "$f" | sed "s|$f|$label/$rel|" ;;
    esac
  done
}

for scene in $(find scenes -name scene.toml | sort); do
  name=$(dirname "$scene")
  for est in analog weighted; do
    for backend in bvh auto; do
      out="$work/$name-$est-$backend"
      "$bin" trace "$scene" --photons "$photons" --seed 7 --threads 2 --estimator "$est" \
        --backend "$backend" --quiet --out "$out" >/dev/null 2>&1 || echo "$name $est $backend: exit $?"
      [ -d "$out" ] && digest "$out" "$name-$est-$backend"
    done
  done
done

for k in 0 1; do
  "$bin" trace scenes/notebook14 --photons 40000 --seed 3 --shard "$k/2" --quiet \
    --out "$work/shard$k" >/dev/null
done
"$bin" merge "$work/shard0" "$work/shard1" --out "$work/merged" >/dev/null
digest "$work/merged" merged

"$bin" optimize scenes/notebook14 --method feedback --photons 100000 --max-iter 3 \
  --verify-photons 100000 --out "$work/opt-fb" >/dev/null 2>&1
digest "$work/opt-fb" opt-fb
"$bin" optimize scenes/notebook14 --method nelder-mead --photons 50000 --max-iter 4 \
  --verify-photons 50000 --out "$work/opt-nm" >/dev/null 2>&1
digest "$work/opt-nm" opt-nm
"$bin" optimize scenes/phone-led --method feedback --dims 2 --cells 14,7 --photons 100000 \
  --max-iter 2 --verify-photons 100000 --out "$work/opt-2d" >/dev/null 2>&1
digest "$work/opt-2d" opt-2d
