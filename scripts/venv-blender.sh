#!/usr/bin/env bash
# Creates .venv-blender/ (if missing or broken) with bpy, Blender 4.5 as a
# Python module from PyPI, for the Blender add-on's tests, and installs
# python/requirements-blender.txt into it (only when that file changed since
# the last successful install; bpy is ~370 MB, so this is done once).
# bpy 4.5 needs Python 3.11: PYTHON=/path/to/python3.11 picks the interpreter
# (default python3). Called by scripts/test.sh.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

python=${PYTHON:-python3}
venv=.venv-blender
stamp=$venv/.wetcloth-requirements

if ! "$venv/bin/python" -c 'import sys; sys.exit(sys.prefix == sys.base_prefix)' 2>/dev/null; then
    version=$("$python" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
    if [ "$version" != 3.11 ]; then
        echo "venv-blender: $python is Python $version; bpy 4.5 needs 3.11 (set PYTHON=python3.11)" >&2
        exit 1
    fi
    echo "venv-blender: creating $root/$venv with $("$python" --version 2>&1)"
    rm -rf "$venv"
    "$python" -m venv "$venv"
fi

if [ -f "$stamp" ] && cmp -s "$stamp" python/requirements-blender.txt; then
    echo "venv-blender: $venv is up to date with python/requirements-blender.txt"
    exit 0
fi

echo "venv-blender: installing python/requirements-blender.txt into $venv (bpy, ~370 MB)"
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r python/requirements-blender.txt
cp python/requirements-blender.txt "$stamp"
