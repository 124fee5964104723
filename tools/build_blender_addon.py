#!/usr/bin/env python3
"""Builds the Blender extension zip of the Wet Cloth add-on.

    python tools/build_blender_addon.py --out DIR [--platform PLATFORM]
        [--library PATH] [--build-dir DIR] [--cffi-wheel PATH] [--python-version 3.11]

PLATFORM is linux-x64 (the default), windows-x64, macos-arm64 or macos-x64,
as Blender names them. The zip (DIR/wetcloth-<version>-<platform>.zip, with
an underscore: linux_x64) holds:

* the add-on (blender_addon/: blender_manifest.toml, with
  `platforms = ["<platform>"]`, and its modules);
* the `wetcloth` package (python/wetcloth) as a subpackage, with the cffi
  module _ffi.py generated from include/wetcloth.h and the compiled library
  (libwetcloth.so, wetcloth.dll or libwetcloth.dylib); for Linux also, in
  wetcloth/libs/, the shared libraries it needs besides the C library
  (libccd, libgomp), for machines without them;
* wheels/: the cffi wheel for Blender's Python (3.11 for Blender 4.2 to 4.5)
  on that platform, which Blender installs with the extension (Blender's
  Python has no cffi).

For linux-x64 the library is built with CMake in --build-dir (default
build-blender/, Release, no tests) unless --library names a built
libwetcloth.so. For the other platforms --library must name the library
scripts/cross-build.sh built (it calls this script), linked so that it needs
nothing beside it: only KERNEL32.dll and msvcrt.dll on Windows, only
libSystem on macOS (checked here). The cffi wheel is downloaded with pip
(same version as the cffi running this script) into <build-dir>/wheels/
once, unless --cffi-wheel names one. This script needs cffi (to generate
_ffi.py); it does not need Blender.

Install the zip in Blender with Edit > Preferences > Get Extensions >
Install from Disk (see docs/blender.md).
"""

import argparse
import fnmatch
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ADDON_SRC = os.path.join(ROOT, "blender_addon")
PACKAGE_SRC = os.path.join(ROOT, "python", "wetcloth")
HEADER = os.path.join(ROOT, "include", "wetcloth.h")
GEN_FFI = os.path.join(ROOT, "python", "gen_ffi.py")
sys.path.insert(0, os.path.join(ROOT, "tools"))
import binary_info  # noqa: E402

# Blender's platform name: the library's name inside the package (what
# python/wetcloth/_lib.py looks for), its format and CPU, pip's platform
# for the cffi wheel and the wheel file's platform tag, and the libraries
# the library may need (None: found with ldd and bundled, Linux).
PLATFORMS = {
    "linux-x64": dict(library="libwetcloth.so", format="ELF", machine="x86_64",
                      pip="manylinux2014_x86_64", tag="manylinux*x86_64", system=None),
    "windows-x64": dict(library="wetcloth.dll", format="PE", machine="x86_64",
                        pip="win_amd64", tag="win_amd64", system=("KERNEL32.dll", "msvcrt.dll")),
    "macos-arm64": dict(library="libwetcloth.dylib", format="Mach-O", machine="arm64",
                        pip="macosx_11_0_arm64", tag="macosx_*_arm64",
                        system=("/usr/lib/libSystem.B.dylib",)),
    "macos-x64": dict(library="libwetcloth.dylib", format="Mach-O", machine="x86_64",
                      pip="macosx_11_0_x86_64", tag="macosx_*_x86_64",
                      system=("/usr/lib/libSystem.B.dylib",)),
}
# Shared libraries that come with every Linux (never bundled).
SYSTEM_LIBS = ("linux-vdso", "libc.so", "libm.so", "libpthread", "libdl.so", "librt.so",
               "ld-linux", "libwetcloth")


def fail(message):
    sys.exit("build_blender_addon: " + message)


def run(cmd, **kw):
    print("+ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, **kw)
    if r.returncode != 0:
        fail("command failed (exit %d): %s" % (r.returncode, " ".join(cmd)))
    return r


def library_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(wetcloth VERSION ([0-9.]+)", f.read())
    if not m:
        fail("no project version in CMakeLists.txt")
    return m.group(1)


def build_library(build_dir):
    args = ["cmake", "-S", ROOT, "-B", build_dir]
    if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
        if shutil.which("ninja"):
            args += ["-G", "Ninja"]
        args += ["-DCMAKE_BUILD_TYPE=Release"]
    args += ["-DWC_BUILD_TESTS=OFF", "-DWC_BUILD_BENCHMARKS=OFF", "-DWC_BUILD_EXAMPLES=OFF"]
    run(args)
    run(["cmake", "--build", build_dir, "--target", "wetcloth", "-j", str(os.cpu_count() or 2)])
    lib = os.path.join(build_dir, "libwetcloth.so")
    if not os.path.isfile(lib):
        fail("the build made no %s" % lib)
    return lib


def needed_libs(library):
    """Paths of the shared libraries `library` loads, besides the system's."""
    r = subprocess.run(["ldd", library], capture_output=True, text=True)
    if r.returncode != 0:
        fail("ldd %s failed: %s" % (library, r.stderr.strip()))
    out = []
    for line in r.stdout.splitlines():
        m = re.match(r"\s*(\S+)\s+=>\s+(\S+)", line)
        if not m:
            continue
        name, path = m.groups()
        if path == "not":
            fail("%s needs %s, which is not installed" % (library, name))
        if not name.startswith(SYSTEM_LIBS):
            out.append((name, path))
    return out


def cffi_wheel(cache, python_version, platform):
    try:
        import cffi
    except ImportError:
        fail("cffi is not installed in %s (it generates the binding; pip install cffi)"
             % sys.executable)
    tag = "cp" + python_version.replace(".", "")
    pattern = "cffi-%s-%s-%s-%s.whl" % (cffi.__version__, tag, tag, PLATFORMS[platform]["tag"])

    def found():
        names = os.listdir(cache) if os.path.isdir(cache) else []
        return sorted(os.path.join(cache, n) for n in names if fnmatch.fnmatch(n, pattern))

    if not found():
        os.makedirs(cache, exist_ok=True)
        run([sys.executable, "-m", "pip", "download", "--disable-pip-version-check", "-q",
             "--no-deps", "--only-binary=:all:", "--platform", PLATFORMS[platform]["pip"],
             "--python-version", python_version, "--implementation", "cp", "--abi", tag,
             "-d", cache, "cffi==%s" % cffi.__version__])
        if not found():
            fail("pip downloaded no wheel matching %s into %s" % (pattern, cache))
    return found()[-1]


def check_library(library, platform):
    """Fails unless `library` is the platform's kind of file and, outside
    Linux, needs nothing but the system's libraries."""
    want = PLATFORMS[platform]
    try:
        info = binary_info.read(library)
    except (OSError, binary_info.FormatError, ValueError) as e:
        fail("cannot read %s: %s" % (library, e))
    if (info["format"], info["machine"]) != (want["format"], want["machine"]):
        fail("%s is a %s library for %s; %s needs %s for %s" % (
            library, info["format"], info["machine"], platform, want["format"], want["machine"]))
    if want["system"] is not None:
        allowed = {d.lower() for d in want["system"]}
        other = [d for d in info["dependencies"] if d.lower() not in allowed]
        if other:
            fail("%s needs %s: the extension ships only the library, so it must be linked "
                 "statically (scripts/cross-build.sh %s does that)" % (
                     library, ", ".join(other), platform))


def manifest_text(version, wheels, platform):
    with open(os.path.join(ADDON_SRC, "blender_manifest.toml"), encoding="utf-8") as f:
        text = f.read()
    text, n1 = re.subn(r'(?m)^version = ".*"$', 'version = "%s"' % version, text)
    text, n2 = re.subn(r"(?m)^wheels = \[.*\]$", "wheels = [%s]" % ", ".join(
        '"./wheels/%s"' % os.path.basename(w) for w in wheels), text)
    text, n3 = re.subn(r"(?m)^platforms = \[.*\]$", 'platforms = ["%s"]' % platform, text)
    if n1 != 1 or n2 != 1 or n3 != 1:
        fail("blender_addon/blender_manifest.toml needs one 'version = ', one 'platforms = ' "
             "and one 'wheels = ' line")
    return text


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="folder for the zip")
    ap.add_argument("--platform", default="linux-x64", choices=sorted(PLATFORMS),
                    help="Blender's name of the platform the zip is for (default: linux-x64)")
    ap.add_argument("--library", help="the built library: libwetcloth.so (default for linux-x64: "
                    "build one), wetcloth.dll or libwetcloth.dylib (from scripts/cross-build.sh)")
    ap.add_argument("--build-dir", default=os.path.join(ROOT, "build-blender"),
                    help="CMake build folder and wheel cache (default: build-blender/)")
    ap.add_argument("--cffi-wheel", action="append", default=[],
                    help="a cffi wheel to bundle (default: download one per --python-version)")
    ap.add_argument("--python-version", action="append", default=[],
                    help="Blender's Python, for the cffi wheel (default: 3.11, Blender 4.2-4.5)")
    args = ap.parse_args(argv)

    version = library_version()
    platform = args.platform
    if not args.library and platform != "linux-x64":
        fail("--platform %s needs --library: build it with scripts/cross-build.sh %s "
             "(which makes this zip too)" % (platform, platform))
    library = os.path.abspath(args.library) if args.library else build_library(
        os.path.abspath(args.build_dir))
    if not os.path.isfile(library):
        fail("--library %s is not a file" % library)
    check_library(library, platform)
    wheels = [os.path.abspath(w) for w in args.cffi_wheel]
    for w in wheels:
        if not os.path.isfile(w):
            fail("--cffi-wheel %s is not a file" % w)
    if not wheels:
        wheels = [cffi_wheel(os.path.join(os.path.abspath(args.build_dir), "wheels"), v, platform)
                  for v in (args.python_version or ["3.11"])]

    out_dir = os.path.abspath(args.out)
    os.makedirs(out_dir, exist_ok=True)
    zip_path = os.path.join(out_dir, "wetcloth-%s-%s.zip" % (version, platform.replace("-", "_")))
    with tempfile.TemporaryDirectory(prefix=".wetcloth-addon-", dir=out_dir) as tmp:
        ffi = os.path.join(tmp, "_ffi.py")
        run([sys.executable, GEN_FFI, HEADER, ffi])
        entries = []  # (path in zip, file on disk)
        for name in sorted(os.listdir(ADDON_SRC)):
            if name.endswith(".py"):
                entries.append((name, os.path.join(ADDON_SRC, name)))
        presets = os.path.join(ADDON_SRC, "presets")
        for folder, _dirs, files in sorted(os.walk(presets)):
            for name in sorted(files):
                if name.endswith(".py"):
                    path = os.path.join(folder, name)
                    entries.append((os.path.relpath(path, ADDON_SRC).replace(os.sep, "/"), path))
        for name in sorted(os.listdir(PACKAGE_SRC)):
            if name.endswith((".py", ".json")):
                entries.append(("wetcloth/" + name, os.path.join(PACKAGE_SRC, name)))
        entries.append(("wetcloth/_ffi.py", ffi))
        entries.append(("wetcloth/" + PLATFORMS[platform]["library"], library))
        if PLATFORMS[platform]["system"] is None:
            for soname, path in needed_libs(library):
                entries.append(("wetcloth/libs/" + soname, os.path.realpath(path)))
        for w in wheels:
            entries.append(("wheels/" + os.path.basename(w), w))

        part = os.path.join(tmp, "addon.zip")
        with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("blender_manifest.toml", manifest_text(version, wheels, platform))
            for arc, src in entries:
                z.write(src, arc)
        os.replace(part, zip_path)
    print(zip_path)
    return zip_path


if __name__ == "__main__":
    main()
