#!/usr/bin/env bash
# The Python package's tests (python/): a venv under target/ (target/python-venv) with
# maturin, numpy, pytest, tqdm and the optional pandas, xarray and matplotlib (sweeps,
# to_xarray and the examples' plots; about 10 s of installing on a fresh venv) from PyPI
# (pinned in python/requirements-test.txt), the
# package built by maturin (a wheel in target/python-wheels) and installed into it, then
# pytest on python/tests. tools/test.sh runs this after the Rust tests, unless
# BLUTRACE_SKIP_PYTHON=1. Nothing is written outside target/ and $TMPDIR.
set -euo pipefail
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
if ! command -v "$python" >/dev/null 2>&1; then
  echo "tools/test-python.sh: no $python: install Debian's python3 and python3-venv" \
    "(apt-get install python3 python3-venv), or set BLUTRACE_SKIP_PYTHON=1" >&2
  exit 1
fi
venv=target/python-venv
if [ ! -x "$venv/bin/python" ]; then
  if ! "$python" -m venv "$venv"; then
    rm -rf "$venv"
    echo "tools/test-python.sh: $python cannot make a venv: install Debian's python3-venv" \
      "(apt-get install python3-venv), or set BLUTRACE_SKIP_PYTHON=1" >&2
    exit 1
  fi
fi
export PYTHONDONTWRITEBYTECODE=1 PIP_DISABLE_PIP_VERSION_CHECK=1
"$venv/bin/python" -m pip install --quiet -r python/requirements-test.txt
rm -rf target/python-wheels
(cd python && ../"$venv"/bin/maturin build --release --quiet --out ../target/python-wheels)
"$venv/bin/python" -m pip install --quiet --force-reinstall --no-deps target/python-wheels/blutrace-*.whl
# The command line the tests compare with: the one `cargo build --release` made.
cargo build --release --quiet --bin blutrace
# pytest's temporary folders in one of our own, removed afterwards (pytest keeps its last
# three otherwise).
base=$(mktemp -d "${TMPDIR:-/tmp}/blutrace-pytest.XXXXXX")
trap 'rm -rf "$base"' EXIT
BLUTRACE_BIN="$PWD/target/release/blutrace" "$venv/bin/python" -m pytest -p no:cacheprovider \
  --basetemp "$base/tmp" -q python/tests "$@"
