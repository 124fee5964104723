#!/usr/bin/env bash
# Regenerates docs/benchmarks.md (and its parts and charts under docs/bench/)
# with tools/bench/report.py, the one program that writes them; run it on a
# quiet machine: many figures are wall-clock rates.
#
#   tools/run_benchmarks.sh [report.py options, e.g. --only speed]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
py=.venv/bin/python
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DWC_PYTHON="$PWD/$py" >/dev/null
cmake --build build --target wetcloth_python bench_core bench_collide bench_wet test_hard_cases >/dev/null
PYTHONPATH=build/python exec "$py" tools/bench/report.py --out docs/bench --report docs/benchmarks.md "$@"
