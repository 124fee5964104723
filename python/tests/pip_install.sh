#!/usr/bin/env bash
# ctest python_pip_install: `pip install .` works.
#
#   pip_install.sh PYTHON SOURCE_DIR WORK_DIR
#
# Builds a wheel of the repository with PYTHON's pip through
# scikit-build-core (no build isolation: PYTHON already has the build
# requirements, and no network is needed), checks what it holds, installs it
# into WORK_DIR/site (pip --target) and runs the package from another folder:
# it must load the library inside the installed package, and its command
# line must run the demo for a few frames.
set -euo pipefail

python=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") src=$2 work=$3
rm -rf "$work"
mkdir -p "$work"

"$python" -m pip wheel --no-build-isolation --no-deps --disable-pip-version-check -q \
    -w "$work/wheel" -C build-dir="$work/build" "$src"

wheels=("$work"/wheel/*.whl)
[ ${#wheels[@]} -eq 1 ] || { echo "expected one wheel, found: ${wheels[*]}"; exit 1; }
wheel=${wheels[0]}
echo "built $(basename "$wheel")"
case $(basename "$wheel") in
    wetcloth-*-py3-none-*.whl) ;;
    *) echo "FAIL: the wheel is not py3-none-<platform> (cffi ABI mode needs no Python ABI)"; exit 1 ;;
esac

# The wheel holds the package, the generated cffi module and the library,
# and nothing of the C development files.
"$python" - "$wheel" <<'PY'
import sys, zipfile
names = set(zipfile.ZipFile(sys.argv[1]).namelist())
need = {"wetcloth/__init__.py", "wetcloth/_ffi.py", "wetcloth/libwetcloth.so",
        "wetcloth/cli.py", "wetcloth/__main__.py", "wetcloth/scene.py"}
missing = need - names
stray = [n for n in names if not (n.startswith("wetcloth/") or n.startswith("wetcloth-"))]
if missing or stray:
    sys.exit("FAIL: wheel lacks %s; holds files outside the package: %s" % (sorted(missing), stray))
print("wheel holds %d files, all inside wetcloth/" % len(names))
PY

"$python" -m pip install --no-deps --disable-pip-version-check -q --target "$work/site" "$wheel"

cd "$work"   # not the source tree
export PYTHONPATH="$work/site"
unset WETCLOTH_LIBRARY
"$python" - "$work/site" <<'PY'
import os, sys
import wetcloth
site = os.path.realpath(sys.argv[1])
assert os.path.realpath(wetcloth.__file__).startswith(site), wetcloth.__file__
assert os.path.realpath(wetcloth.library_path) == os.path.join(site, "wetcloth", "libwetcloth.so"), \
    wetcloth.library_path
with wetcloth.World() as w:
    c = w.add_grid_cloth(4, 4)
    w.advance(1 / 24)
    assert (c.positions[:, 2] < 0).all()
print("installed wetcloth %s loads %s" % (wetcloth.__version__, wetcloth.library_path))
PY
"$python" -m wetcloth demo --out "$work/demo" --frames 2 --no-progress
for f in dry.obj dry.pc2 wet.obj wet.pc2 stats.json preview.png; do
    [ -s "$work/demo/$f" ] || { echo "FAIL: the installed demo wrote no $f"; exit 1; }
done
echo "pip install: ok"
