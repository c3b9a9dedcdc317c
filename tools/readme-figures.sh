#!/usr/bin/env bash
# Re-measure the README's figures: the gallery images in docs/img/, the optimizer tables
# and the bench table. Results are deterministic (fixed seeds); only the timings depend on
# the machine and its load, so run it on a quiet machine.
#
#   bash tools/readme-figures.sh [gallery|optimize|bench|all]   (default: all)
#
# Logs go to out/figures/*.log; the README tables are filled in from them by hand.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q
bin=target/release/blutrace
out=out/figures
mkdir -p "$out"
what=${1:-all}

# Run a command with its output into a log, and append its wall time.
timed() {
  local log=$1 t0=$EPOCHREALTIME
  shift
  "$@" >"$log" 2>&1
  echo "wall $(python3 -c "print(round($EPOCHREALTIME - $t0, 1))") s" >>"$log"
}

gallery() {
  for s in notebook14 wedge-ccfl phone-led direct-lit cad-reflector bef-stack; do
    "$bin" trace "scenes/$s" --photons 1000000 --estimator weighted --quiet \
      --out "$out/$s" >"$out/$s.log"
    cp "$out/$s/flux.png" "docs/img/$s-flux.png"
  done
  cp "$out/notebook14/convergence.png" docs/img/notebook14-convergence.png
}

optimize() {
  timed "$out/opt-nm.log" "$bin" optimize scenes/notebook14 --method nelder-mead \
    --out "$out/opt-nm"
  timed "$out/opt-fb.log" "$bin" optimize scenes/notebook14 --method feedback \
    --out "$out/opt-fb"
  timed "$out/phone-1d.log" "$bin" optimize scenes/phone-led --method feedback \
    --out "$out/phone-1d"
  timed "$out/phone-2d-28.log" "$bin" optimize scenes/phone-led --method feedback --dims 2 \
    --cells 28,14 --out "$out/phone-2d-28"
  timed "$out/phone-2d.log" "$bin" optimize scenes/phone-led --method feedback --dims 2 \
    --out "$out/phone-2d"
  cp "$out/phone-2d/initial/flux.png" docs/img/phone-led-2d-initial.png
  cp "$out/phone-2d/final/flux.png" docs/img/phone-led-2d-final.png
}

bench() {
  "$bin" bench --photons 200000 >"$out/bench.log" 2>&1
}

case "$what" in
  gallery) gallery ;;
  optimize) optimize ;;
  bench) bench ;;
  all) gallery; optimize; bench ;;
  *) echo "usage: $0 [gallery|optimize|bench|all]" >&2; exit 2 ;;
esac
