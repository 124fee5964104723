"""Generates wetcloth/_ffi.py, the cffi ABI-mode ("out-of-line", no
compiler) description of include/wetcloth.h.

    python gen_ffi.py HEADER OUTPUT

The declarations are taken from the public header itself, so the binding
cannot drift from it: preprocessor lines are dropped (except the integer
version macros), as are WC_API and the C++ guards. The output needs only
cffi's _cffi_backend at run time (no pycparser, no compiler).
Run by CMake (python/CMakeLists.txt) at build time.
"""

import re
import sys

import cffi


def cdef_from_header(text):
    lines = []
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("#"):
            m = re.match(r"#define\s+(WC_VERSION_(MAJOR|MINOR|PATCH))\s+(\d+)\s*$", stripped)
            if m:
                lines.append("#define %s %s" % (m.group(1), m.group(3)))
            continue
        if stripped in ('extern "C" {', "}") and not line.startswith(" ") and "typedef" not in line:
            # the C++ guard's braces (struct and enum bodies close with "} name;")
            continue
        lines.append(line.replace("WC_API ", ""))
    return "\n".join(lines)


def main(argv):
    if len(argv) != 3:
        sys.exit("usage: gen_ffi.py HEADER OUTPUT")
    with open(argv[1], encoding="utf-8") as f:
        cdef = cdef_from_header(f.read())
    ffi = cffi.FFI()
    ffi.cdef(cdef)
    ffi.set_source("wetcloth._ffi", None)
    ffi.emit_python_code(argv[2])


if __name__ == "__main__":
    main(sys.argv)
