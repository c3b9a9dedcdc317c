#!/usr/bin/env bash
# The whole test suite, exactly as CI runs it (.ci/run calls this script).
# Fetches the Embree 4 library first, so every backend is tested; on a machine without
# network, set BLUTRACE_SKIP_EMBREE=1 to test the pure-Rust backends only.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${BLUTRACE_SKIP_EMBREE:-0}" != "1" ]; then
  bash tools/fetch-embree.sh
fi
cargo test --workspace --release "$@"
