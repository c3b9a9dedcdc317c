#!/bin/sh
# Export the CAD lamp reflector of scenes/cad-reflector with Blender, headless.
#
#   tools/cad/export-reflector.sh [OUT_DIR]     (default: scenes/cad-reflector)
#
# Installs Debian's blender package (and python3-numpy, which Blender's glTF exporter
# imports but the package does not depend on) if missing (needs root and apt), runs
# tools/cad/make_reflector.py in background mode (no display needed) and writes
# reflector.gltf, reflector.bin, reflector.obj and reflector.mtl. The committed files
# were made with Debian bookworm's Blender 3.4.1.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-"$root/scenes/cad-reflector"}

if ! command -v blender >/dev/null 2>&1 || ! python3 -c 'import numpy' 2>/dev/null; then
    echo "export-reflector: installing Debian's blender and python3-numpy" >&2
    if [ "$(id -u)" -ne 0 ]; then
        echo "export-reflector: run as root, or: apt-get install blender python3-numpy" >&2
        exit 1
    fi
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
        blender python3-numpy
fi

blender --version | head -n 1
# --factory-startup: ignore any user preferences and startup file, so runs are repeatable.
blender -b --factory-startup --python-exit-code 1 \
    --python "$here/make_reflector.py" -- "$out"
ls -l "$out"/reflector.*
