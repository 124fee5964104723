#!/usr/bin/env bash
# Runs all the tests:
#   build/       Release, -DWC_WERROR=ON
#   build-asan/  Debug, AddressSanitizer + UndefinedBehaviorSanitizer, -DWC_WERROR=ON
# and `ctest --output-on-failure` in each: the C tests, and the Python tests
# (binding, scene runner, command line, `pip install .`) with the
# interpreter of .venv/ (made by scripts/venv.sh), and in build/ the Blender
# add-on's tests inside bpy 4.5 from .venv-blender/ (made by
# scripts/venv-blender.sh). Exits non-zero if either fails.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

scripts/install-deps.sh
scripts/venv.sh
scripts/venv-blender.sh

# The Python and Blender tests must run here: a missing package is an error,
# not a skip.
python_args=(-DWC_PYTHON="$root/.venv/bin/python" -DWC_PYTHON_REQUIRED=ON
             -DWC_BLENDER_PYTHON="$root/.venv-blender/bin/python" -DWC_BLENDER_REQUIRED=ON)

jobs=$(nproc 2>/dev/null || echo 2)

# configure DIR ARGS...: first configure picks Ninja; the given options are
# applied every time.
configure() {
    local dir=$1
    shift
    if [ -f "$dir/CMakeCache.txt" ]; then
        cmake -S . -B "$dir" "$@"
    else
        cmake -S . -B "$dir" -G Ninja "$@"
    fi
}

declare -A result
run_build() {
    local name=$1 dir=$2
    shift 2
    echo
    echo "==== $name ($dir)"
    if configure "$dir" "$@" && cmake --build "$dir" -j "$jobs" &&
        (cd "$dir" && ctest --output-on-failure -j 2); then
        result[$name]=passed
    else
        result[$name]=FAILED
    fi
}

release_type=()
[ -f build/CMakeCache.txt ] || release_type=(-DCMAKE_BUILD_TYPE=Release)
run_build normal build "${release_type[@]}" -DWC_WERROR=ON "${python_args[@]}"
run_build sanitizer build-asan -DWC_SANITIZE=ON -DWC_WERROR=ON -DCMAKE_BUILD_TYPE=Debug "${python_args[@]}"

echo
echo "==== summary"
status=0
for name in normal sanitizer; do
    echo "  $name: ${result[$name]}"
    [ "${result[$name]}" = passed ] || status=1
done
exit $status
