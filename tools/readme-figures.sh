#!/usr/bin/env bash
# Re-measure the book's figures: the gallery images in docs/book/src/img/, the optimizer tables
# and the bench table. Results are deterministic (fixed seeds); only the timings depend on
# the machine and its load, so run it on a quiet machine.
#
#   bash tools/readme-figures.sh [gallery|optimize|layout|volume|bench|bodies|placement|all]   (default: all)
#
# Logs go to out/figures/*.log; the book's tables are filled in from them by hand.
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
  for s in notebook14 wedge-ccfl phone-led direct-lit cad-reflector bef-stack diffusion-lgp; do
    "$bin" trace "scenes/$s" --photons 1000000 --estimator weighted --quiet \
      --out "$out/$s" >"$out/$s.log"
    cp "$out/$s/flux.png" "docs/book/src/img/$s-flux.png"
  done
  cp "$out/notebook14/convergence.png" docs/book/src/img/notebook14-convergence.png
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
  cp "$out/phone-2d/initial/flux.png" docs/book/src/img/phone-led-2d-initial.png
  cp "$out/phone-2d/final/flux.png" docs/book/src/img/phone-led-2d-final.png
}

# notebook14's efficiency for each lamp body (book, scene/sources.md "Lamp bodies"): the scene copied with
# every source's body replaced.
bodies() {
  local dir=$out/bodies
  echo "body | extraction efficiency | absorbed by the four tubes (W of 4)" >"$out/bodies.log"
  for body in '"transparent"' '"absorber"' '{ model = "lambert", albedo = 0.3 }' \
    '{ model = "lambert", albedo = 0.5 }' '{ model = "lambert", albedo = 0.9 }'; do
    rm -rf "$dir" && mkdir -p "$dir" && cp scenes/notebook14/* "$dir/"
    BODY="$body" python3 - "$dir/scene.toml" <<'PY'
import os, re, sys
p = sys.argv[1]
s = open(p).read()
s = re.sub(r"^body = .*$", "body = " + os.environ["BODY"], s, flags=re.M)
open(p, "w").write(s)
PY
    "$bin" trace "$dir" --photons 1000000 --estimator weighted --quiet --out "$dir/out" >/dev/null
    python3 - "$dir/out/summary.json" "$body" >>"$out/bodies.log" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
l = d["ledger"]
print(f"{sys.argv[2]} | {d['extraction_efficiency']:.4f} +- {d['extraction_efficiency_stderr']:.4f} | {sum(l['absorbed_by_source_w'].values()):.3f}")
PY
  done
}

# "Dot placement and correlated extraction": the slab and guide tables per placement and
# the grooves walk (deterministic; about a minute).
placement() {
  cargo test --release -q --test dot_placement -- --ignored --nocapture --test-threads 1 \
    table table_guide grooves_table >"$out/placement.log" 2>&1
}

volume() {
  # The diffusion-lgp profile table (book, scene/media.md, "Diffusion light guides").
  cargo test --release -q --test variants -- --ignored diffusion_lgp_profile_table \
    --nocapture >"$out/diffusion-lgp-profile.log" 2>&1
}

# The book's "Optimizing the layout and the reflectors": direct-lit-rows (6 lamps) over lamp
# height, pitch and ridge height; then the lamp count 4..8 with the pitch searched for each.
layout() {
  # The bulk-diffuser plate makes direct-lit slow to trace (about 50k photons/s on 2
  # cores): 2e5 photons per design, 2e6 per verification trace.
  timed "$out/layout-dl6.log" "$bin" optimize scenes/direct-lit-rows \
    --vary 'sources.0.center.2=4..20' --vary sources.0.array.pitch_mm=50..75 \
    --vary procedural.0.ridge_height_mm=0..15 --photons 200000 --verify-photons 2000000 \
    --out "$out/layout-dl6"
  timed "$out/layout-count.log" "$bin" optimize scenes/direct-lit-rows \
    --vary sources.0.array.count=4..8 --vary sources.0.array.pitch_mm=40..110 \
    --photons 200000 --verify-photons 2000000 --out "$out/layout-count"
  # The edge-lit holder for coupling efficiency, then the dots for the new holder.
  timed "$out/layout-holder.log" "$bin" optimize scenes/edge-holder \
    --vary procedural.0.section.radius_mm=2.0..2.5 --objective efficiency \
    --photons 200000 --verify-photons 2000000 --out "$out/layout-holder"
  timed "$out/layout-holder-dots.log" "$bin" optimize "$out/layout-holder/optimized.toml" \
    --method feedback --photons 200000 --verify-photons 2000000 --out "$out/layout-holder-dots"
}

# Every table of the book's "Backends" section (performance.md): first blutrace against the reference
# kernel on scenes/bench-box (speed of light), then the backends on notebook14.
bench() {
  # 1e6 photons, 5 rounds: at 2e5 the kernel's rounds last 50 ms and its rate varied 1.4x.
  "$bin" bench --photons 1000000 --repeat 5 >"$out/bench.log" 2>&1
}

case "$what" in
  gallery) gallery ;;
  optimize) optimize ;;
  layout) layout ;;
  volume) volume ;;
  bench) bench ;;
  bodies) bodies ;;
  placement) placement ;;
  all) gallery; bodies; optimize; layout; placement; volume; bench ;;
  *) echo "usage: $0 [gallery|optimize|layout|volume|bench|bodies|placement|all]" >&2; exit 2 ;;
esac
