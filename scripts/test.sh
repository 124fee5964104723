#!/usr/bin/env bash
# Runs all the tests:
#   build/       Release, -DWC_WERROR=ON
#   build-asan/  Debug, AddressSanitizer + UndefinedBehaviorSanitizer, -DWC_WERROR=ON
# and `ctest --output-on-failure` in each: the C tests, and the Python tests
# (binding, scene runner, command line, `pip install .`) with the
# interpreter of .venv/ (made by scripts/venv.sh), and in build/ the Blender
# add-on's tests inside bpy 4.5 from .venv-blender/ (made by
# scripts/venv-blender.sh). Then the other platforms:
#   build-windows-x64/  scripts/test-windows.sh: cross-built with MinGW-w64,
#                       every C test, the DLL's exports, the positions against
#                       build/'s, and the binding's tests in Windows' CPython,
#                       all under wine
#   build-macos-*/      scripts/cross-build.sh macos-arm64 and macos-x64:
#                       built with zig cc (tests/ for arm64 only) and checked
#                       (exports, libSystem only, macOS 11), not run:
#                       nothing here runs macOS
# and dist/ gets the three platforms' Blender extension zips.
#
#   scripts/test.sh [--native-only]    (--native-only: build/ and build-asan/ only)
#
# Exits non-zero if any part fails.
set -euo pipefail

native_only=0
case ${1:-} in
    --native-only) native_only=1 ;;
    '') ;;
    *) echo "usage: scripts/test.sh [--native-only]" >&2; exit 2 ;;
esac

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

names=(normal sanitizer)
if [ $native_only = 0 ]; then
    # run_step NAME COMMAND...: one platform's part, timed.
    run_step() {
        local name=$1 t0
        shift
        echo
        echo "==== $name"
        t0=$(date +%s)
        if "$@"; then result[$name]=passed; else result[$name]=FAILED; fi
        result[$name]="${result[$name]} ($(( $(date +%s) - t0 )) s)"
        names+=("$name")
    }
    run_step "windows-x64 (under wine)" scripts/test-windows.sh
    run_step "macos-arm64 (built and checked, not run)" scripts/cross-build.sh macos-arm64
    # The tests of tests/ are compiled for one macOS CPU (they run nowhere
    # here); the other gets the library, the examples and tests/consumer.
    run_step "macos-x64 (built and checked, not run)" scripts/cross-build.sh macos-x64 --no-tests
fi

echo
echo "==== summary"
status=0
for name in "${names[@]}"; do
    echo "  $name: ${result[$name]}"
    case ${result[$name]} in passed*) ;; *) status=1 ;; esac
done
exit $status
