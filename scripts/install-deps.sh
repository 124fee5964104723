#!/usr/bin/env bash
# Installs the Debian/Ubuntu packages libwetcloth needs to build and test
# (the Python packages come from PyPI into .venv/: scripts/venv.sh),
# only those that are missing. Runs apt-get only when something is missing;
# uses sudo when not root (and sudo exists). Called by setup.sh and test.sh.
set -euo pipefail

packages=(cmake ninja-build gcc libc6-dev libccd-dev pkg-config python3-venv)
# The X11/GL client libraries bpy (Blender as a Python module, for the Blender
# add-on's tests) links against, even headless.
packages+=(libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libsm6 libgl1 libxext6 libxt6)

missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        missing+=("$p")
    fi
done

# Optional, for the robustness tests (docs/robustness.md): clang with its
# libFuzzer/sanitizer runtimes (the fuzz_api test; the build itself stays
# gcc) and valgrind (the memcheck_scene test). Installed when the
# distribution has them (Debian bookworm does); without them those two tests
# are not registered, and nothing else changes.
optional=(clang libclang-rt-14-dev valgrind)
optional_missing=()
for p in "${optional[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        optional_missing+=("$p")
    fi
done

install_optional() {
    [ ${#optional_missing[@]} -eq 0 ] && return 0
    echo "install-deps: installing the optional ${optional_missing[*]}"
    "${sudo[@]}" apt-get install -y -q --no-install-recommends "${optional_missing[@]}" ||
        echo "install-deps: could not install ${optional_missing[*]}; the fuzz and memcheck tests will not run" >&2
}

if [ ${#missing[@]} -eq 0 ] && [ ${#optional_missing[@]} -eq 0 ]; then
    echo "install-deps: all packages present (${packages[*]})"
    exit 0
fi

if [ ${#missing[@]} -eq 0 ] && ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: all required packages present; optional ${optional_missing[*]} missing (no apt-get)"
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: missing ${missing[*]}, and there is no apt-get here." >&2
    echo "Install the equivalents of: ${missing[*]} (CMake >= 3.20, a C99 compiler with" >&2
    echo "OpenMP, libccd 2 with its CMake config, pkg-config), then run this again." >&2
    exit 1
fi

sudo=()
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
        sudo=(sudo)
    else
        if [ ${#missing[@]} -eq 0 ]; then
            echo "install-deps: all required packages present; optional ${optional_missing[*]} missing (not root, no sudo)"
            exit 0
        fi
        echo "install-deps: missing ${missing[*]}; not root and no sudo." >&2
        echo "As root run: apt-get update && apt-get install -y ${missing[*]}" >&2
        exit 1
    fi
fi

export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -q
if [ ${#missing[@]} -gt 0 ]; then
    echo "install-deps: installing ${missing[*]}"
    "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
install_optional
