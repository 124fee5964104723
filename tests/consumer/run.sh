#!/usr/bin/env bash
# ctest driver for the consumer test (registered by tests/consumer/test.cmake).
#
#   run.sh BUILD_DIR WORK_DIR C_COMPILER GENERATOR LIBDIR [EXTRA_C_FLAGS]
#
# 1. installs the just-built library into WORK_DIR/prefix
#    (cmake --install BUILD_DIR --prefix ...),
# 2. configures, builds and runs tests/consumer against it with
#    find_package(wetcloth CONFIG), shared and static,
# 3. compiles tests/consumer/main.c with `pkg-config --cflags --libs wetcloth`
#    (and the static variant with --static) and runs it.
#
# EXTRA_C_FLAGS is used for every consumer compile and link. The sanitizer
# build passes its -fsanitize flags there: a shared libwetcloth built with
# AddressSanitizer needs the ASan runtime to be loaded first, which only
# happens when the program itself is linked with -fsanitize=address.
#
# Exit status: 0 pass, 77 (ctest SKIP) when pkg-config is not installed and
# everything else passed, anything else a failure.
set -euo pipefail

if [ $# -lt 5 ]; then
    echo "usage: $0 BUILD_DIR WORK_DIR C_COMPILER GENERATOR LIBDIR [EXTRA_C_FLAGS]" >&2
    exit 2
fi
build_dir=$1
work_dir=$2
cc=$3
generator=$4
libdir_rel=$5
extra_flags=${6:-}
src_dir=$(cd "$(dirname "$0")" && pwd)

prefix=$work_dir/prefix
# An absolute CMAKE_INSTALL_LIBDIR is used as it is.
case $libdir_rel in
    /*) libdir=$libdir_rel ;;
    *) libdir=$prefix/$libdir_rel ;;
esac

step() { printf '\n== %s\n' "$*"; }

rm -rf "$work_dir"
mkdir -p "$work_dir"

step "install $build_dir into $prefix"
cmake --install "$build_dir" --prefix "$prefix"

for f in include/wetcloth.h; do
    [ -f "$prefix/$f" ] || { echo "missing after install: $prefix/$f" >&2; exit 1; }
done
for f in libwetcloth.a libwetcloth.so pkgconfig/wetcloth.pc cmake/wetcloth/wetclothConfig.cmake \
         cmake/wetcloth/wetclothConfigVersion.cmake cmake/wetcloth/wetclothTargets.cmake; do
    [ -e "$libdir/$f" ] || { echo "missing after install: $libdir/$f" >&2; exit 1; }
done
# Internal targets must not be part of the exported package.
if grep -E 'wc_flags|wc_internal|wc_objects' "$libdir"/cmake/wetcloth/wetclothTargets*.cmake; then
    echo "internal targets leaked into the exported CMake package" >&2
    exit 1
fi

# Does a program's dynamic section list libwetcloth.so?
needs_libwetcloth() { LC_ALL=C readelf -d "$1" | grep -q 'NEEDED.*libwetcloth\.so'; }

step "consumer project with find_package(wetcloth CONFIG)"
cmake -S "$src_dir" -B "$work_dir/cmake-build" -G "$generator" \
    -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_COMPILER="$cc" \
    -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_FIND_PACKAGE_PREFER_CONFIG=ON \
    -DCMAKE_C_FLAGS="$extra_flags" \
    -DCMAKE_EXE_LINKER_FLAGS="$extra_flags"
cmake --build "$work_dir/cmake-build"
grep -q "wetcloth_DIR:PATH=$libdir/cmake/wetcloth" "$work_dir/cmake-build/CMakeCache.txt" || {
    echo "find_package found wetcloth somewhere other than $libdir/cmake/wetcloth:" >&2
    grep wetcloth_DIR "$work_dir/cmake-build/CMakeCache.txt" >&2
    exit 1
}
"$work_dir/cmake-build/consumer_shared"
"$work_dir/cmake-build/consumer_static"
needs_libwetcloth "$work_dir/cmake-build/consumer_shared" || {
    echo "consumer_shared does not link libwetcloth.so" >&2; exit 1; }
if needs_libwetcloth "$work_dir/cmake-build/consumer_static"; then
    echo "consumer_static links libwetcloth.so instead of the static library" >&2; exit 1
fi

step "pkg-config"
if ! command -v pkg-config >/dev/null 2>&1; then
    echo "SKIP: pkg-config is not installed (scripts/setup.sh installs it);" \
         "the find_package part passed"
    exit 77
fi
export PKG_CONFIG_PATH="$libdir/pkgconfig"
pc_cflags=$(pkg-config --cflags wetcloth)
pc_libs=$(pkg-config --libs wetcloth)
pc_static_libs=$(pkg-config --static --libs wetcloth)
pc_libdir=$(pkg-config --variable=libdir wetcloth)
echo "pkg-config --cflags wetcloth:        $pc_cflags"
echo "pkg-config --libs wetcloth:          $pc_libs"
echo "pkg-config --static --libs wetcloth: $pc_static_libs"
[ "$(cd "$pc_libdir" && pwd -P)" = "$(cd "$libdir" && pwd -P)" ] || {
    echo "wetcloth.pc's libdir $pc_libdir is not $libdir (the .pc file does not relocate)" >&2
    exit 1
}
# Word splitting of the flag strings is intended below.
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -pedantic -Werror $extra_flags "$src_dir/main.c" \
    -o "$work_dir/consumer_pc_shared" $pc_cflags $pc_libs -Wl,-rpath,"$pc_libdir"
"$work_dir/consumer_pc_shared"
needs_libwetcloth "$work_dir/consumer_pc_shared"

# Static: the same flags with --static, and -lwetcloth swapped for the archive
# (both libwetcloth.so and libwetcloth.a are in libdir; -l would pick the .so).
pc_static_libs=${pc_static_libs/-lwetcloth/-l:libwetcloth.a}
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -pedantic -Werror $extra_flags "$src_dir/main.c" \
    -o "$work_dir/consumer_pc_static" $pc_cflags $pc_static_libs
"$work_dir/consumer_pc_static"
if needs_libwetcloth "$work_dir/consumer_pc_static"; then
    echo "consumer_pc_static links libwetcloth.so" >&2; exit 1
fi

step "consumer test passed"
