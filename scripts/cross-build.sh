#!/usr/bin/env bash
# Cross-builds libwetcloth from this Debian/Ubuntu machine for another
# platform, and the platform's Blender extension zip:
#
#   scripts/cross-build.sh PLATFORM [--no-zip] [--no-tests] [-- CMAKE_ARGS...]
#
#   PLATFORM     windows-x64   MinGW-w64 (Debian's gcc-mingw-w64-x86-64), OpenMP
#                macos-arm64   zig cc (ziglang from PyPI), macOS 11+, no OpenMP
#                macos-x64     zig cc, macOS 11+, no OpenMP
#   --no-zip     skip the Blender extension zip
#   --no-tests   build the library, examples and tests/consumer only, not tests/
#   CMAKE_ARGS   more options for the library's configure (test-windows.sh
#                passes WC_TARGET_PYTHON)
#
# It installs what it needs, only what is missing (like install-deps.sh):
# the MinGW compilers with apt-get, or ziglang into .venv-cross/
# (python/requirements-cross.txt). libccd comes from Debian's source package
# (the one Debian's libccd-dev is built from, fetched once with apt into
# .cache/debian-src/), built for the target as a static library in double
# precision with its symbols hidden. Then, in build-PLATFORM/:
#
#   build-PLATFORM/             the CMake build (Release, -Werror; tests built)
#   build-PLATFORM/prefix/      installed: include/wetcloth.h, the shared
#                               library (bin/wetcloth.dll or lib/libwetcloth.dylib),
#                               the static one, lib/cmake/wetcloth/ (with
#                               libccd's package beside it), lib/pkgconfig/
#   dist/wetcloth-<version>-<platform>.zip   the Blender extension
#
# The shared library is checked (tools/binary_info.py): it exports exactly
# the header's WC_API functions and needs only the system's libraries
# (KERNEL32.dll and msvcrt.dll; /usr/lib/libSystem.B.dylib, minimum macOS 11).
# Nothing macOS runs on this machine: the macOS builds are built, not run.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

usage() {
    sed -n '5,13p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
}
[ $# -ge 1 ] || usage
platform=$1
shift
make_zip=1
tests=ON
cmake_extra=()
while [ $# -gt 0 ]; do
    case $1 in
        --no-zip) make_zip=0 ;;
        --no-tests) tests=OFF ;;
        --) shift; cmake_extra=("$@"); break ;;
        *) usage ;;
    esac
    shift
done

case $platform in
    windows-x64) ;;
    macos-arm64) zig_target=aarch64-macos.11.0 cpu=arm64 ;;
    macos-x64) zig_target=x86_64-macos.11.0 cpu=x86_64 ;;
    *) echo "cross-build: unknown platform '$platform' (windows-x64, macos-arm64, macos-x64)" >&2; exit 2 ;;
esac

say() { printf '\n== cross-build %s: %s\n' "$platform" "$*"; }

build=$root/build-$platform
prefix=$build/prefix
jobs=$(nproc 2>/dev/null || echo 2)

# ---------------------------------------------------------------------------
# What the host needs: the native build's packages (cmake, ninja, Python with
# cffi in .venv/ for the binding's generated module and the zip), and the
# platform's compilers.
scripts/install-deps.sh
scripts/venv.sh
host_python=$root/.venv/bin/python

if [ "$platform" = windows-x64 ]; then
    # The posix thread model's g++ too: libccd's project() enables C++.
    scripts/apt-install.sh --why "the Windows cross build" \
        gcc-mingw-w64-x86-64 g++-mingw-w64-x86-64-posix
    toolchain=$root/cmake/toolchains/windows-x64-mingw.cmake
    openmp=ON
else
    venv=.venv-cross
    stamp=$venv/.wetcloth-requirements
    if ! "$venv/bin/python" -c 'import sys; sys.exit(sys.prefix == sys.base_prefix)' 2>/dev/null; then
        echo "cross-build: creating $root/$venv"
        rm -rf "$venv"
        python3 -m venv "$venv"
    fi
    if ! { [ -f "$stamp" ] && cmp -s "$stamp" python/requirements-cross.txt; }; then
        echo "cross-build: installing python/requirements-cross.txt into $venv (ziglang)"
        "$venv/bin/python" -m pip install -q --disable-pip-version-check -r python/requirements-cross.txt
        cp python/requirements-cross.txt "$stamp"
    fi
    zig=$("$venv/bin/python" -c 'import os, ziglang; print(os.path.join(os.path.dirname(ziglang.__file__), "zig"))')
    [ -x "$zig" ] || { echo "cross-build: no zig executable at $zig" >&2; exit 1; }
    # CMake takes one program per tool: wrappers around `zig cc -target ...`.
    wrappers=$build/zig
    mkdir -p "$wrappers"
    for tool in cc c++ ar ranlib; do
        case $tool in
            cc|c++) args="$tool -target $zig_target" ;;
            *) args=$tool ;;
        esac
        printf '#!/bin/sh\nexec "%s" %s "$@"\n' "$zig" "$args" > "$wrappers/$tool.new"
        chmod +x "$wrappers/$tool.new"
        if cmp -s "$wrappers/$tool.new" "$wrappers/$tool"; then rm "$wrappers/$tool.new"; else mv "$wrappers/$tool.new" "$wrappers/$tool"; fi
    done
    toolchain=$build/toolchain.cmake
    cat > "$toolchain.new" <<EOF
# Written by scripts/cross-build.sh $platform: zig cc for macOS 11+ ($cpu).
set(CMAKE_SYSTEM_NAME Darwin)
set(CMAKE_SYSTEM_PROCESSOR $cpu)
set(CMAKE_SYSTEM_VERSION 20)
set(CMAKE_C_COMPILER "$wrappers/cc")
set(CMAKE_CXX_COMPILER "$wrappers/c++")
set(CMAKE_AR "$wrappers/ar" CACHE FILEPATH "" FORCE)
set(CMAKE_RANLIB "$wrappers/ranlib" CACHE FILEPATH "" FORCE)
# zig's target triple already says the CPU and the minimum macOS: no -arch,
# -isysroot or -mmacosx-version-min from CMake.
set(CMAKE_OSX_ARCHITECTURES "" CACHE STRING "" FORCE)
set(CMAKE_OSX_DEPLOYMENT_TARGET "" CACHE STRING "" FORCE)
set(CMAKE_OSX_SYSROOT "" CACHE PATH "" FORCE)
# CMake's Darwin rules give the rpath flag (and so @rpath install names)
# only when sw_vers says macOS 10.5 or newer; there is no sw_vers here.
set(CMAKE_USER_MAKE_RULES_OVERRIDE "$build/darwin-rules.cmake")
set(CMAKE_FIND_ROOT_PATH "$prefix")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
EOF
    if cmp -s "$toolchain.new" "$toolchain"; then rm "$toolchain.new"; else mv "$toolchain.new" "$toolchain"; fi
    printf 'set(CMAKE_SHARED_LIBRARY_RUNTIME_C_FLAG "-Wl,-rpath,")\n' > "$build/darwin-rules.cmake"
    # zig ships no OpenMP runtime (docs/building.md: macOS is single-threaded).
    openmp=OFF
fi

# ---------------------------------------------------------------------------
# libccd from Debian's source package, fetched once: a private apt source
# list with deb-src lines for the system's own Debian release, so nothing in
# /etc/apt changes.
src_cache=$root/.cache/debian-src
if ! ls "$src_cache"/libccd_*.orig.tar.* >/dev/null 2>&1; then
    say "fetching Debian's libccd source package"
    command -v apt-get >/dev/null || { echo "cross-build: needs apt-get for Debian's libccd source" >&2; exit 1; }
    suite=$(. /etc/os-release && echo "${VERSION_CODENAME:?no VERSION_CODENAME in /etc/os-release}")
    mirror=$(grep -hoE '^(URIs:|deb) *https?://[^ ]+/debian/?( |$)' /etc/apt/sources.list.d/*.sources \
             /etc/apt/sources.list 2>/dev/null | head -1 | grep -oE 'https?://[^ ]+' || true)
    mirror=${mirror:-http://deb.debian.org/debian}
    apt_dir=$src_cache/apt
    rm -rf "$apt_dir"
    mkdir -p "$apt_dir/parts" "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial"
    keyring=/usr/share/keyrings/debian-archive-keyring.gpg
    printf 'Types: deb-src\nURIs: %s\nSuites: %s\nComponents: main\nSigned-By: %s\n' \
        "$mirror" "$suite" "$keyring" > "$apt_dir/parts/debian-src.sources"
    apt_opts=(-o Dir::Etc::SourceList=/dev/null -o Dir::Etc::SourceParts="$apt_dir/parts"
              -o Dir::State::Lists="$apt_dir/lists" -o Dir::Cache="$apt_dir/cache"
              -o APT::Sandbox::User=root)
    apt-get "${apt_opts[@]}" -q update
    (cd "$src_cache" && apt-get "${apt_opts[@]}" -q source --download-only libccd)
    rm -rf "$apt_dir"
fi
ccd_tar=$(ls "$src_cache"/libccd_*.orig.tar.* | sort | tail -1)
ccd_version=$(basename "$ccd_tar" | sed -E 's/^libccd_([^.]+\.[^.]+)\.orig.*/\1/')

ccd_src=$build/libccd-src
if [ ! -f "$ccd_src/.from-$(basename "$ccd_tar")" ]; then
    rm -rf "$ccd_src"
    mkdir -p "$ccd_src"
    tar -xf "$ccd_tar" -C "$ccd_src" --strip-components=1
    # Debian's own changes (none for 2.1-2), applied as dpkg-source would.
    debian_tar=$(ls "$src_cache"/libccd_*.debian.tar.* 2>/dev/null | sort | tail -1 || true)
    if [ -n "$debian_tar" ]; then
        tar -xf "$debian_tar" -C "$ccd_src"
        if [ -f "$ccd_src/debian/patches/series" ]; then
            while read -r patch _; do
                case $patch in ''|'#'*) continue ;; esac
                (cd "$ccd_src" && git apply -p1 "debian/patches/$patch")
            done < "$ccd_src/debian/patches/series"
        fi
    fi
    touch "$ccd_src/.from-$(basename "$ccd_tar")"
fi

if [ ! -f "$prefix/lib/ccd/ccd-config.cmake" ] || [ ! -f "$build/libccd-build/.built-$ccd_version" ]; then
    say "libccd $ccd_version (static, double precision, symbols hidden)"
    ccd_args=(-DCMAKE_TOOLCHAIN_FILE="$toolchain" -DCMAKE_BUILD_TYPE=Release
              -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_INSTALL_LIBDIR=lib
              -DCCD_DOUBLE=ON -DBUILD_SHARED_LIBS=OFF -DBUILD_TESTING=OFF
              -DCCD_HIDE_ALL_SYMBOLS=ON -DCMAKE_C_VISIBILITY_PRESET=hidden
              -DCMAKE_POSITION_INDEPENDENT_CODE=ON)
    # libccd looks for a libm outside Windows; zig's is part of libSystem.
    [ "$platform" = windows-x64 ] || ccd_args+=(-DLIBM_LIBRARY:STRING=m)
    cmake -S "$ccd_src" -B "$build/libccd-build" -G Ninja "${ccd_args[@]}" > "$build/libccd-configure.log" ||
        { cat "$build/libccd-configure.log" >&2; exit 1; }
    cmake --build "$build/libccd-build" -j "$jobs"
    cmake --install "$build/libccd-build" > /dev/null
    touch "$build/libccd-build/.built-$ccd_version"
fi

# ---------------------------------------------------------------------------
# The library, its tests and its install tree.
say "libwetcloth (OpenMP $openmp)"
configure_args=(-DCMAKE_TOOLCHAIN_FILE="$toolchain" -DCMAKE_BUILD_TYPE=Release
                -DCMAKE_PREFIX_PATH="$prefix" -Dccd_DIR="$prefix/lib/ccd"
                -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_INSTALL_LIBDIR=lib
                -DWC_OPENMP=$openmp -DWC_WERROR=ON -DWC_BUILD_TESTS=$tests
                -DWC_BUILD_BENCHMARKS=OFF -DWC_BUILD_EXAMPLES=ON
                -DWC_PYTHON="$host_python")
generator=()
[ -f "$build/CMakeCache.txt" ] || generator=(-G Ninja)
cmake -S . -B "$build" "${generator[@]}" "${configure_args[@]}" "${cmake_extra[@]}"
cmake --build "$build" -j "$jobs"
cmake --install "$build" > /dev/null

case $platform in
    windows-x64)
        library=$prefix/bin/wetcloth.dll
        check=(--allow-dep KERNEL32.dll --allow-dep msvcrt.dll --machine x86_64) ;;
    *)
        library=$prefix/lib/libwetcloth.dylib
        check=(--allow-dep /usr/lib/libSystem.B.dylib --min-macos 11.0 --machine "$cpu") ;;
esac
say "checking $library"
"$host_python" tools/binary_info.py "$library" --check --header include/wetcloth.h "${check[@]}"

# The installed CMake package as a user's project takes it: tests/consumer
# with find_package(wetcloth CONFIG), shared and static, for the target
# (scripts/test-windows.sh runs the Windows programs under wine).
say "tests/consumer against $prefix"
consumer=$build/consumer
cmake -S tests/consumer -B "$consumer" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$toolchain" \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_PACKAGE_PREFER_CONFIG=ON \
    > "$build/consumer-configure.log" || { cat "$build/consumer-configure.log" >&2; exit 1; }
grep -q "wetcloth_DIR:PATH=$prefix/lib/cmake/wetcloth" "$consumer/CMakeCache.txt" || {
    echo "cross-build: tests/consumer found wetcloth somewhere other than $prefix:" >&2
    grep wetcloth_DIR "$consumer/CMakeCache.txt" >&2
    exit 1
}
cmake --build "$consumer" -j "$jobs"

if [ $make_zip = 1 ]; then
    say "Blender extension"
    "$host_python" tools/build_blender_addon.py --platform "$platform" --library "$library" \
        --build-dir "$build" --out dist
    # Blender's own check of an extension package (its manifest, the wheels
    # against the platforms), where bpy is installed (scripts/venv-blender.sh).
    version=$(sed -nE 's/^project\(wetcloth VERSION ([0-9.]+).*/\1/p' CMakeLists.txt)
    blender_ext=$(ls .venv-blender/lib/python3*/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py 2>/dev/null | head -1 || true)
    if [ -n "$blender_ext" ]; then
        .venv-blender/bin/python "$blender_ext" validate "dist/wetcloth-$version-${platform/-/_}.zip"
    else
        echo "cross-build: no .venv-blender/ (scripts/venv-blender.sh): the zip is not validated by Blender's extension tool"
    fi
fi
