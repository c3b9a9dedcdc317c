#!/usr/bin/env bash
# Fuzz blutrace's input loaders with cargo-fuzz (libFuzzer): every target in fuzz/ (scene
# TOML, OBJ, glTF/GLB, STL, PLY, IES, CSV intensity tables, shard JSON, TM-25 and text
# ray files, IS BSDF tables; see fuzz/README.md) runs for SECONDS each, one after the other. Not part of CI (.ci/run and
# tools/test.sh never call it); run it by hand:
#
#   bash tools/fuzz.sh [SECONDS_PER_TARGET] [TARGET ...]   # default 60 s, all targets
#
# Installs cargo-fuzz (crates.io) if missing; needs the nightly toolchain. Limits: one
# fuzzing process per target and no parallel jobs (libFuzzer's default single worker),
# builds with CARGO_BUILD_JOBS=1; an input is a finding if it panics, aborts, overflows
# the stack, runs over 10 s (-timeout=10) or takes over 2 GiB of memory
# (-rss_limit_mb=2048). Errors returned as Err are the intended outcome, not findings. Builds are optimized with debug assertions and overflow checks on, without a
# sanitizer (the loaders are safe Rust; this doubles the executions per second).
#
# New inputs go to fuzz/corpus/TARGET (seeded from fuzz/seeds/TARGET, which is never
# written), reproducers to fuzz/artifacts/TARGET/, logs to fuzz/target/fuzz-logs/. The
# script builds all targets once, goes on to the next target after a finding (a target
# stops at its first; FUZZ_KEEP_GOING=1 makes it go on, one forked worker at a time) and
# exits 1 at the end if any target found one, naming each reproducer (exit 2: no build).
# Replay one with
#   cd fuzz && cargo +nightly fuzz run -s none TARGET artifacts/TARGET/crash-...
# and minimize it with `cargo +nightly fuzz tmin -s none TARGET artifacts/TARGET/crash-...`.
set -uo pipefail
secs=${1:-60}
shift || true
case $secs in
  '' | *[!0-9]*)
    echo "usage: bash tools/fuzz.sh [SECONDS_PER_TARGET] [TARGET ...]" >&2
    exit 2
    ;;
esac
cd "$(dirname "$0")/../fuzz" || exit 2
export CARGO_BUILD_JOBS=1

if ! rustup toolchain list | grep -q '^nightly'; then
  echo "tools/fuzz.sh: cargo-fuzz needs the nightly toolchain: rustup toolchain install nightly" >&2
  exit 2
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
  cargo install cargo-fuzz || exit 2
fi
fuzz=(cargo +nightly fuzz)

if [ $# -gt 0 ]; then
  targets=("$@")
else
  mapfile -t targets < <("${fuzz[@]}" list)
fi
# Build once, then run the binaries: a run fuzzes the library as it was at the start,
# even if crates/blutrace/src/ is edited meanwhile (cargo fuzz run would rebuild before every target).
if ! "${fuzz[@]}" build -s none; then
  echo "tools/fuzz.sh: the build failed (crates/blutrace/src/ being edited? retry in a minute)" >&2
  exit 2
fi
bin=target/$(rustc +nightly -vV | sed -n 's/^host: //p')/release
extra=()
# FUZZ_KEEP_GOING=1: go on after a finding (one forked worker at a time), to find more.
if [ "${FUZZ_KEEP_GOING:-0}" = 1 ]; then
  extra=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
fi

logs=target/fuzz-logs
mkdir -p "$logs"
# The targets' scratch folders (/dev/shm or $TMPDIR /blutrace-fuzz-TARGET-PID): libFuzzer
# exits without cleaning up, so remove those whose process is gone.
sweep() {
  local d
  for d in /dev/shm/blutrace-fuzz-"$1"-* "${TMPDIR:-/tmp}"/blutrace-fuzz-"$1"-*; do
    [ -d "$d" ] || continue
    kill -0 "${d##*-}" 2>/dev/null || rm -rf "$d"
  done
}

found=()
for t in "${targets[@]}"; do
  mkdir -p "corpus/$t" "artifacts/$t"
  seeds=()
  [ -d "seeds/$t" ] && seeds=("seeds/$t")
  before=$(ls "artifacts/$t")
  echo "== $t: ${secs} s"
  "$bin/$t" -artifact_prefix="artifacts/$t/" -max_total_time="$secs" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 "${extra[@]}" "corpus/$t" "${seeds[@]}" \
    >"$logs/$t.log" 2>&1
  status=$?
  sweep "$t"
  grep -E '^#[0-9]+' "$logs/$t.log" | tail -1
  new=$(comm -13 <(echo "$before") <(ls "artifacts/$t") | grep -v '^slow-unit-' || true)
  if [ $status -ne 0 ] || [ -n "$new" ]; then
    grep -E -A1 'panicked at|^==[0-9]+== ERROR|ERROR: libFuzzer' "$logs/$t.log" | head -4
    for f in $new; do found+=("fuzz/artifacts/$t/$f"); done
    [ -z "$new" ] && found+=("$t: exit status $status, see fuzz/$logs/$t.log")
  fi
done

if [ ${#found[@]} -gt 0 ]; then
  echo "tools/fuzz.sh: findings (reproducers):" >&2
  printf '  %s\n' "${found[@]}" >&2
  exit 1
fi
echo "tools/fuzz.sh: no findings in ${#targets[@]} targets x ${secs} s"
