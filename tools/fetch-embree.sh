#!/usr/bin/env bash
# Fetch Intel Embree 4.4.0 (and the oneTBB it links against) into third_party/embree/lib/.
#
# Debian bookworm ships only Embree 3, so the library comes from the PyPI wheel
# embreex==4.4.0.post1 (manylinux_2_28, x86_64), which bundles a working Embree 4.4.0
# build and its TBB under embreex.libs/. Only those two shared objects are kept:
#
#   third_party/embree/lib/libembree4.so.4          (embreex.libs/libembree4-4aef3270.so.4)
#   third_party/embree/lib/libtbb-dcf63f8c.so.12    (name kept: Embree's DT_NEEDED entry,
#                                                    found next to it through RPATH $ORIGIN)
#
# blutrace looks there by default (the folder is baked in by build.rs); BLUTRACE_EMBREE
# (a .so or a folder) overrides it. The wheel's sha256 and both libraries' sha256 are
# pinned below, so a present and intact install is left alone (idempotent) and a corrupt
# one is replaced.
#
# Usage: bash tools/fetch-embree.sh [--force]
# Needs: python3 with pip (installed with apt-get when run as root on Debian), and access
# to PyPI. Exits non-zero on any failure.
set -euo pipefail

WHEEL_VERSION="4.4.0.post1"
WHEEL_SHA256="2cd0f7d5c6342e6247e31f700761689cae7829454d8c6de0c41e62124a023e1f"
EMBREE_SRC="embreex.libs/libembree4-4aef3270.so.4"
EMBREE_DST="libembree4.so.4"
EMBREE_SHA256="aa4eb9d81e30237d032418832efd9caee19bead50f49939fb08347a053898c7a"
TBB_SRC="embreex.libs/libtbb-dcf63f8c.so.12"
TBB_DST="libtbb-dcf63f8c.so.12"
TBB_SHA256="08d7ce01dcce5c49f874ee91ba8dad75ee3aa1838d5ce8a92f5b2ec98b9df2ed"

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DEST="$ROOT/third_party/embree/lib"

die() {
    echo "fetch-embree: error: $*" >&2
    exit 1
}

force=0
for arg in "$@"; do
    case "$arg" in
        --force) force=1 ;;
        -h | --help)
            sed -n '2,18p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
            exit 0
            ;;
        *) die "unknown argument '$arg' (usage: bash tools/fetch-embree.sh [--force])" ;;
    esac
done

[[ "$(uname -s)" == Linux && "$(uname -m)" == x86_64 ]] ||
    die "the bundled Embree build is for Linux x86_64 only (this is $(uname -s) $(uname -m))"
command -v sha256sum >/dev/null || die "sha256sum (coreutils) is missing"

sha_of() { sha256sum "$1" | cut -d' ' -f1; }

installed_ok() {
    [[ -f "$DEST/$EMBREE_DST" && -f "$DEST/$TBB_DST" ]] &&
        [[ "$(sha_of "$DEST/$EMBREE_DST")" == "$EMBREE_SHA256" ]] &&
        [[ "$(sha_of "$DEST/$TBB_DST")" == "$TBB_SHA256" ]]
}

if [[ $force -eq 0 ]] && installed_ok; then
    echo "fetch-embree: Embree 4.4.0 already installed and verified in $DEST"
    exit 0
fi

PYTHON="${PYTHON:-python3}"
# A fresh Debian machine may have neither Python nor pip: as root, install them.
if ! { command -v "$PYTHON" >/dev/null && "$PYTHON" -m pip --version >/dev/null 2>&1; } &&
    [[ "$(id -u)" == 0 ]] && command -v apt-get >/dev/null; then
    echo "fetch-embree: installing python3-pip with apt-get (needed to fetch the Embree wheel)..."
    DEBIAN_FRONTEND=noninteractive apt-get update -qq &&
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-pip >/dev/null ||
        die "apt-get could not install python3-pip"
fi
command -v "$PYTHON" >/dev/null ||
    die "$PYTHON not found: install Python 3 with pip (e.g. apt-get install python3-pip), or put libembree4.so.4 (4.4.x) somewhere and set BLUTRACE_EMBREE to it"
"$PYTHON" -m pip --version >/dev/null 2>&1 ||
    die "pip is not available for $PYTHON: install it (e.g. apt-get install python3-pip), or set BLUTRACE_EMBREE to an existing libembree4.so.4 (4.4.x)"

TMP="$(mktemp -d "${TMPDIR:-/tmp}/fetch-embree.XXXXXX")"
trap 'rm -rf "$TMP"' EXIT

echo "fetch-embree: downloading embreex==$WHEEL_VERSION (manylinux_2_28_x86_64) from PyPI..."
if ! "$PYTHON" -m pip download \
    --disable-pip-version-check --no-input --quiet \
    --timeout 30 --retries 2 \
    --no-deps --only-binary=:all: \
    --platform manylinux_2_28_x86_64 --python-version 3.11 \
    --implementation cp --abi cp311 \
    --dest "$TMP" "embreex==$WHEEL_VERSION"; then
    die "pip could not download embreex==$WHEEL_VERSION: no network, or PyPI unreachable? (see pip's message above). Without network, set BLUTRACE_EMBREE to an existing Embree 4.4 library, or BLUTRACE_SKIP_EMBREE=1 to skip the Embree tests"
fi

shopt -s nullglob
wheels=("$TMP"/embreex-"$WHEEL_VERSION"-*.whl)
shopt -u nullglob
[[ ${#wheels[@]} -eq 1 ]] || die "expected one embreex-$WHEEL_VERSION wheel from pip, got ${#wheels[@]}"
wheel="${wheels[0]}"
got="$(sha_of "$wheel")"
[[ "$got" == "$WHEEL_SHA256" ]] ||
    die "sha256 mismatch for $(basename "$wheel"): expected $WHEEL_SHA256, got $got (refusing to install)"
echo "fetch-embree: wheel verified (sha256 $WHEEL_SHA256)"

# Extract just the two libraries (python's zipfile: no dependency on unzip).
"$PYTHON" - "$wheel" "$TMP/x" "$EMBREE_SRC" "$TBB_SRC" <<'EOF' || die "could not extract the libraries from the wheel"
import sys, zipfile
wheel, out, *members = sys.argv[1:]
with zipfile.ZipFile(wheel) as z:
    for m in members:
        z.extract(m, out)
EOF

[[ "$(sha_of "$TMP/x/$EMBREE_SRC")" == "$EMBREE_SHA256" ]] || die "unexpected content: $EMBREE_SRC"
[[ "$(sha_of "$TMP/x/$TBB_SRC")" == "$TBB_SHA256" ]] || die "unexpected content: $TBB_SRC"

mkdir -p "$DEST"
# Copy under temporary names, then rename: a half-written library is never left in place.
install -m 0755 "$TMP/x/$TBB_SRC" "$DEST/.$TBB_DST.tmp"
install -m 0755 "$TMP/x/$EMBREE_SRC" "$DEST/.$EMBREE_DST.tmp"
mv -f "$DEST/.$TBB_DST.tmp" "$DEST/$TBB_DST"
mv -f "$DEST/.$EMBREE_DST.tmp" "$DEST/$EMBREE_DST"

installed_ok || die "installation in $DEST failed verification"
echo "fetch-embree: installed Embree 4.4.0 and its TBB in $DEST"
