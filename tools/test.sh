#!/usr/bin/env bash
# The whole test suite, exactly as CI runs it (.ci/run calls this script).
# Fetches the Embree 4 library first, so every backend is tested; on a machine without
# network, set BLUTRACE_SKIP_EMBREE=1 to test the pure-Rust backends only. After the Rust
# tests, tools/test-python.sh builds the Python package and runs its pytest suite (a venv
# under target/, packages from PyPI); BLUTRACE_SKIP_PYTHON=1 skips it. Before them,
# tools/book.sh builds the book and the library's API docs (mdBook from crates.io into
# target/tools the first time).
#
# The tests run with TMPDIR set to a new empty folder, so nothing an earlier run left in
# the machine's temporary folder can make a test pass; afterwards that folder must be
# empty again and the checkout must hold no file it did not hold before (every test writes
# only into temporary folders it made and removes), or this script fails and names them.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${BLUTRACE_SKIP_EMBREE:-0}" != "1" ]; then
  bash tools/fetch-embree.sh
fi

scratch=$(mktemp -d "${TMPDIR:-/tmp}/blutrace-test-tmp.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
# Files in the checkout beside the build's own folders (and the Python package's copy of
# scenes/, which its build makes: python/build.rs), before and after the tests.
checkout_files() {
  git status --porcelain --ignored --untracked-files=all -- . \
    ':(exclude)target' ':(exclude)third_party' ':(exclude)fuzz/target' \
    ':(exclude)fuzz/corpus' ':(exclude)fuzz/artifacts' ':(exclude)fuzz/coverage' \
    ':(exclude)python/blutrace/_scenes' 2>/dev/null | sort
}
before=$(checkout_files)

bash tools/book.sh

TMPDIR="$scratch" cargo test --workspace --release "$@"
if [ "${BLUTRACE_SKIP_PYTHON:-0}" != "1" ]; then
  TMPDIR="$scratch" bash tools/test-python.sh
fi

status=0
left=$(cd "$scratch" && find . -mindepth 1 -maxdepth 2 | head -20)
if [ -n "$left" ]; then
  echo "tools/test.sh: the tests left files in their temporary folder:" >&2
  echo "$left" >&2
  status=1
fi
new=$(comm -13 <(echo "$before") <(checkout_files))
if [ -n "$new" ]; then
  echo "tools/test.sh: the tests wrote into the checkout:" >&2
  echo "$new" >&2
  status=1
fi
exit $status
