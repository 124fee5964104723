"""Finds and loads the compiled libwetcloth (cffi ABI mode: no compiler).

The library is looked for, in this order:

1. the file named by the environment variable WETCLOTH_LIBRARY, if set
   (it must exist: a wrong path is an error, not a fallback);
2. ``libwetcloth.so`` (Linux), ``libwetcloth.dylib`` (macOS) or
   ``wetcloth.dll`` (Windows; ``libwetcloth.dll`` as MinGW names it by
   default) in each folder of the package's ``__path__``: where
   ``pip install .`` puts it, also for editable installs, whose ``__path__``
   spans the source tree and the installed files.
"""

import os

from ._ffi import ffi

ENV_VAR = "WETCLOTH_LIBRARY"
LIBRARY_NAMES = ("libwetcloth.so", "libwetcloth.dylib", "wetcloth.dll", "libwetcloth.dll")
REINSTALL = ("Install the package and its library together ('pip install .' at the repository "
             "root, or scripts/setup.sh), or point %s at the library built with this "
             "binding" % ENV_VAR)


def find_library(package_path):
    """Path of the shared library to load (see the module docstring)."""
    override = os.environ.get(ENV_VAR)
    if override:
        if not os.path.isfile(override):
            raise ImportError(
                "%s is set to %r, which is not a file; point it at libwetcloth.so "
                "or unset it to use the library inside the package" % (ENV_VAR, override))
        return override
    searched = []
    for folder in package_path:
        for name in LIBRARY_NAMES:
            candidate = os.path.join(folder, name)
            if os.path.isfile(candidate):
                return candidate
        searched.append(folder)
    raise ImportError(
        "libwetcloth's shared library is not in the wetcloth package (looked in %s). "
        "Install the package with 'pip install .' at the repository root, or set %s "
        "to the path of a built libwetcloth.so" % (", ".join(searched) or "nothing", ENV_VAR))


def load(package_path):
    """(lib, path): the loaded library and where it came from."""
    path = find_library(package_path)
    try:
        lib = ffi.dlopen(os.path.abspath(path))
    except OSError as e:
        raise ImportError("cannot load libwetcloth from %s: %s" % (path, e)) from None
    major, minor = lib.WC_VERSION_MAJOR, lib.WC_VERSION_MINOR
    found = lib.wc_version()
    if found // 100 != major * 100 + minor:
        raise ImportError(
            "%s is libwetcloth %s, but this binding was generated from the %d.%d header; "
            "0.x versions must match in major and minor" %
            (path, ffi.string(lib.wc_version_string()).decode(), major, minor))
    check_struct_sizes(lib, ffi, path)
    keep_loaded(path)
    return lib, path


_kept = []


def keep_loaded(path):
    """Keeps the library, and the OpenMP runtime it brings, mapped until the
    process ends. cffi unloads a library when its handle is freed, which
    Python's shutdown does; but a world that ran on several threads leaves
    OpenMP's worker threads behind, waiting (spinning for a while) in code
    that the unloading unmaps, and the process then crashed on its way out
    (a 2-thread world with OMP_WAIT_POLICY=active: every time; with the
    default policy and the machine busy: about one run in two). A second
    reference that is never released (ctypes never closes its handles),
    with RTLD_NODELETE where the system has it, keeps it mapped."""
    import ctypes
    mode = getattr(os, "RTLD_NOW", 0) | getattr(os, "RTLD_NODELETE", 0)
    try:
        _kept.append(ctypes.CDLL(os.path.abspath(path), mode=mode) if mode
                     else ctypes.CDLL(os.path.abspath(path)))
    except OSError as e:
        raise ImportError("cannot load libwetcloth from %s: %s" % (path, e)) from None


def declared_structs(binding):
    """(typedef name, size) of each struct with a body that the cffi FFI
    `binding` declares; opaque handles (wc_world) and function types have
    no layout."""
    # cffi raises ValueError for an incomplete type's size, and ffi.error
    # (a class of a generated module's ffi only) for a function type
    no_layout = (ValueError, TypeError) + ((binding.error,) if hasattr(binding, "error") else ())
    found = []
    for name in sorted(binding.list_types()[0]):
        try:
            if binding.typeof(name).kind == "struct":
                found.append((name, binding.sizeof(name)))
        except no_layout:
            continue
    return found


def check_struct_sizes(lib, binding, path):
    """Raises ImportError unless every struct `binding` declares has
    the size the library was compiled with (wc_struct_size). The version
    check alone misses a header changed within a 0.x version: a binding
    generated from an older wetcloth.h than its library's would pass
    structs too short for the library, which reads and writes past them."""
    try:
        struct_size = lib.wc_struct_size
    except (AttributeError, ffi.error):  # this package's ffi raises its error
        raise ImportError(
            "%s has no wc_struct_size: it was built from an older wetcloth.h than this "
            "binding. %s" % (path, REINSTALL)) from None
    wrong = []
    for name, ours in declared_structs(binding):
        theirs = struct_size(name.encode())
        if theirs != ours:
            wrong.append("%s is %d bytes in the library, %d in the binding" % (
                name, theirs, ours) if theirs else
                "%s is not a struct the library knows" % name)
    if wrong:
        raise ImportError(
            "%s and this binding were built from different versions of wetcloth.h: %s. "
            "%s" % (path, "; ".join(wrong), REINSTALL))
