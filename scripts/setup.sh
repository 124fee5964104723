#!/usr/bin/env bash
# Sets everything up and runs the demo:
#   1. installs missing system packages (scripts/install-deps.sh),
#   2. configures and builds libwetcloth in build/ (Release),
#   3. runs the drape demo, which writes out/drape.obj.
# Safe to run again: it only does what is not done yet.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

scripts/install-deps.sh

# First configure picks Ninja and Release; later runs keep what build/ has.
if [ -f build/CMakeCache.txt ]; then
    cmake -S . -B build
else
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build build -j "$(nproc 2>/dev/null || echo 2)"

mkdir -p out
build/examples/drape out/drape.obj
echo
echo "setup: done. Demo mesh: $root/out/drape.obj"
echo "setup: run all the tests with scripts/test.sh"
