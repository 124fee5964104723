#!/usr/bin/env bash
# Creates the Python virtual environment .venv/ (if missing or broken) and
# installs python/requirements.txt into it (only when that file changed since
# the last successful install). Called by setup.sh and test.sh; needs
# python3 with its venv module (Debian: python3-venv, which install-deps.sh
# installs). PYTHON=/path/to/python3 picks another interpreter.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

python=${PYTHON:-python3}
venv=.venv
stamp=$venv/.wetcloth-requirements

if ! "$venv/bin/python" -c 'import sys; sys.exit(sys.prefix == sys.base_prefix)' 2>/dev/null; then
    echo "venv: creating $root/$venv with $("$python" --version 2>&1)"
    rm -rf "$venv"
    "$python" -m venv "$venv"
fi

if [ -f "$stamp" ] && cmp -s "$stamp" python/requirements.txt; then
    echo "venv: $venv is up to date with python/requirements.txt"
    exit 0
fi

echo "venv: installing python/requirements.txt into $venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r python/requirements.txt
cp python/requirements.txt "$stamp"
