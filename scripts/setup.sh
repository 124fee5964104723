#!/usr/bin/env bash
# Sets everything up and runs the Python demo:
#   1. installs missing system packages (scripts/install-deps.sh),
#   2. makes the Python environment .venv/ (scripts/venv.sh),
#   3. configures and builds libwetcloth in build/ (Release; the C demo
#      build/examples/drape is built there too),
#   4. installs the Python package into .venv/ with `pip install .` (which
#      builds the library again with scikit-build-core, in build-pip/),
#   5. runs the demo, `python -m wetcloth demo --out out/demo`: the thesis
#      scene wet against dry, written as PC2 caches, OBJs, stats.json and
#      out/demo/preview.png.
# Safe to run again: it only does what is not done yet.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

scripts/install-deps.sh
scripts/venv.sh

# First configure picks Ninja and Release; later runs keep what build/ has.
if [ -f build/CMakeCache.txt ]; then
    cmake -S . -B build -DWC_PYTHON="$root/.venv/bin/python"
else
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DWC_PYTHON="$root/.venv/bin/python"
fi
cmake --build build -j "$(nproc 2>/dev/null || echo 2)"

echo "setup: pip install . into .venv"
.venv/bin/python -m pip install -q --disable-pip-version-check --no-build-isolation --no-deps .

mkdir -p out
.venv/bin/python -m wetcloth demo --out out/demo
echo
echo "setup: done. Demo output in $root/out/demo (preview.png, stats.json, dry/wet .pc2 and .obj)"
echo "setup: the package is installed in .venv: .venv/bin/python -c 'import wetcloth'"
echo "setup: run all the tests with scripts/test.sh"
