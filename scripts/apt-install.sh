#!/usr/bin/env bash
# Installs the given Debian packages, only those that are missing: runs
# apt-get (as root, or through sudo) only when one is. Used by the cross
# builds (scripts/cross-build.sh, scripts/test-windows.sh); the native
# build's packages are scripts/install-deps.sh's.
#
#   scripts/apt-install.sh [--why TEXT] PACKAGE...
set -euo pipefail

why=""
if [ "${1:-}" = --why ]; then
    why=" ($2)"
    shift 2
fi

missing=()
for p in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        missing+=("$p")
    fi
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "apt-install: present: $*"
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    echo "apt-install: missing ${missing[*]}$why, and there is no apt-get here;" \
         "install the equivalents by hand (see docs/building.md, Cross builds)" >&2
    exit 1
fi
sudo=()
if [ "$(id -u)" -ne 0 ]; then
    if ! command -v sudo >/dev/null 2>&1; then
        echo "apt-install: missing ${missing[*]}$why; not root and no sudo." >&2
        echo "As root run: apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
        exit 1
    fi
    sudo=(sudo)
fi

export DEBIAN_FRONTEND=noninteractive
echo "apt-install: installing ${missing[*]}$why"
# The package lists may be old or absent on a fresh machine: update first
# when the install cannot find a package.
if ! "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"; then
    "${sudo[@]}" apt-get update -q
    "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" || {
        echo "apt-install: could not install ${missing[*]}$why" >&2
        exit 1
    }
fi
