#!/usr/bin/env python3
"""What a shared library exports and needs: ELF (Linux), PE (Windows DLL)
and Mach-O (macOS dylib), read from the file itself, with no tool of the
target platform (nothing here can run otool or dumpbin).

    python tools/binary_info.py LIBRARY                 # prints it all as JSON
    python tools/binary_info.py LIBRARY --check --header include/wetcloth.h \\
        [--allow-dep NAME ...] [--min-macos 11.0] [--machine arm64]

--check fails (exit 1, saying what is wrong) unless the exported functions
are exactly the header's WC_API functions, every dependency is one of
--allow-dep (compared case-insensitively; default: no check), and, for
Mach-O, the minimum macOS is --min-macos and the CPU --machine.

The test `library_exports` (tests/CMakeLists.txt) runs this on every build's
library; scripts/cross-build.sh on the Windows and macOS ones;
tools/build_blender_addon.py uses `dependencies` for the extension zips.
"""

import argparse
import json
import re
import struct
import sys


class FormatError(Exception):
    pass


# ---------------------------------------------------------------------------
# ELF (64-bit little-endian only: Linux x64 and arm64)

def _elf(data):
    if data[4] != 2 or data[5] != 1:
        raise FormatError("only 64-bit little-endian ELF is read")
    machine = struct.unpack_from("<H", data, 18)[0]
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    sections = []
    for i in range(shnum):
        (name, typ, _flags, _addr, offset, size, link, _info, _align,
         entsize) = struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize)
        sections.append((typ, offset, size, link, entsize))

    def string(table, at):
        _t, off, _s, _l, _e = sections[table]
        end = data.index(b"\0", off + at)
        return data[off + at:end].decode()

    exports, needed = [], []
    for typ, offset, size, link, entsize in sections:
        if typ == 11:  # SHT_DYNSYM
            for k in range(1, size // entsize):
                name, info, _other, shndx, _value, _size = struct.unpack_from(
                    "<IBBHQQ", data, offset + k * entsize)
                bind, kind = info >> 4, info & 15
                if shndx != 0 and bind in (1, 2) and kind in (1, 2):  # GLOBAL/WEAK FUNC/OBJECT
                    exports.append(string(link, name))
        elif typ == 6:  # SHT_DYNAMIC
            for k in range(size // 16):
                tag, value = struct.unpack_from("<qQ", data, offset + 16 * k)
                if tag == 1:  # DT_NEEDED
                    needed.append(string(link, value))
    return {"format": "ELF", "machine": {62: "x86_64", 183: "arm64"}.get(machine, str(machine)),
            "exports": sorted(set(exports)), "dependencies": needed}


# ---------------------------------------------------------------------------
# PE (Windows, PE32+)

def _pe(data):
    pe, = struct.unpack_from("<I", data, 0x3C)
    if data[pe:pe + 4] != b"PE\0\0":
        raise FormatError("no PE signature")
    machine, nsections = struct.unpack_from("<HH", data, pe + 4)
    opt_size, = struct.unpack_from("<H", data, pe + 20)
    opt = pe + 24
    if struct.unpack_from("<H", data, opt)[0] != 0x20B:
        raise FormatError("only PE32+ (64-bit) is read")
    ndirs, = struct.unpack_from("<I", data, opt + 108)
    dirs = [struct.unpack_from("<II", data, opt + 112 + 8 * i) for i in range(ndirs)]
    sections = []
    for i in range(nsections):
        s = opt + opt_size + 40 * i
        vsize, vaddr, rawsize, rawptr = struct.unpack_from("<IIII", data, s + 8)
        sections.append((vaddr, max(vsize, rawsize), rawptr))

    def at(rva):
        for vaddr, size, rawptr in sections:
            if vaddr <= rva < vaddr + size:
                return rawptr + rva - vaddr
        raise FormatError("address 0x%x is in no section" % rva)

    def cstring(rva):
        o = at(rva)
        return data[o:data.index(b"\0", o)].decode()

    exports, needed = [], []
    erva, _esize = dirs[0]
    if erva:
        e = at(erva)
        # the export directory: NumberOfNames at 24, AddressOfNames at 32
        nnames, = struct.unpack_from("<I", data, e + 24)
        names, = struct.unpack_from("<I", data, e + 32)
        for k in range(nnames):
            exports.append(cstring(struct.unpack_from("<I", data, at(names) + 4 * k)[0]))
    irva, _isize = dirs[1]
    if irva:
        d = at(irva)
        while True:
            lookup, _stamp, _chain, name, thunk = struct.unpack_from("<IIIII", data, d)
            if not (lookup or name or thunk):
                break
            needed.append(cstring(name))
            d += 20
    return {"format": "PE", "machine": {0x8664: "x86_64", 0xAA64: "arm64"}.get(machine, hex(machine)),
            "exports": sorted(exports), "dependencies": needed}


# ---------------------------------------------------------------------------
# Mach-O (64-bit, thin)

def _uleb(data, o):
    value = shift = 0
    while True:
        b = data[o]
        o += 1
        value |= (b & 0x7F) << shift
        shift += 7
        if b < 0x80:
            return value, o


def _export_trie(data, start, size):
    """Names in a Mach-O export trie: what dyld lets other images bind to
    (the symbol table's external entries also list symbols the linker
    makes for itself, such as __mh_dylib_header)."""
    names, todo = [], [(0, "")]
    while todo:
        node, prefix = todo.pop()
        o = start + node
        terminal, o = _uleb(data, o)
        if terminal:
            names.append(prefix)
        o += terminal
        children = data[o]
        o += 1
        for _ in range(children):
            end = data.index(b"\0", o)
            label = data[o:end].decode()
            child, o = _uleb(data, end + 1)
            if child >= size:
                raise FormatError("export trie node out of range")
            todo.append((child, prefix + label))
    return names


def _macho(data):
    magic, cputype, _sub, _filetype, ncmds, _sizeofcmds, _flags = struct.unpack_from("<IiiIIII", data, 0)
    if magic != 0xFEEDFACF:
        raise FormatError("only thin 64-bit little-endian Mach-O is read")
    o = 32
    needed, exports, minos, install_name, trie = [], [], None, None, None
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", data, o)
        cmd &= 0x7FFFFFFF  # LC_REQ_DYLD
        if cmd in (0xC, 0x18, 0x1F, 0x23):  # LC_LOAD_DYLIB, _WEAK_, _REEXPORT_, _UPWARD_
            off, = struct.unpack_from("<I", data, o + 8)
            needed.append(data[o + off:data.index(b"\0", o + off)].decode())
        elif cmd == 0xD:  # LC_ID_DYLIB
            off, = struct.unpack_from("<I", data, o + 8)
            install_name = data[o + off:data.index(b"\0", o + off)].decode()
        elif cmd == 0x32:  # LC_BUILD_VERSION
            _platform, v = struct.unpack_from("<II", data, o + 8)
            minos = "%d.%d.%d" % (v >> 16, (v >> 8) & 255, v & 255)
        elif cmd == 0x24 and minos is None:  # LC_VERSION_MIN_MACOSX
            v, = struct.unpack_from("<I", data, o + 8)
            minos = "%d.%d.%d" % (v >> 16, (v >> 8) & 255, v & 255)
        elif cmd == 0x22:  # LC_DYLD_INFO(_ONLY): the export trie's place is its last pair
            export_off, export_size = struct.unpack_from("<II", data, o + 40)
            if export_size:
                trie = (export_off, export_size)
        elif cmd == 0x33:  # LC_DYLD_EXPORTS_TRIE
            export_off, export_size = struct.unpack_from("<II", data, o + 8)
            trie = (export_off, export_size)
        elif cmd == 0x2:  # LC_SYMTAB
            symoff, nsyms, stroff, _strsize = struct.unpack_from("<IIII", data, o + 8)
            for k in range(nsyms):
                strx, ntype, sect, _desc, _value = struct.unpack_from("<IBBHQ", data, symoff + 16 * k)
                # external, defined in a section, not a debugging entry,
                # not private external (hidden)
                if ntype & 0xE0 == 0 and ntype & 0x01 and ntype & 0x0E == 0x0E and not ntype & 0x10:
                    name = data[stroff + strx:data.index(b"\0", stroff + strx)].decode()
                    exports.append(name[1:] if name.startswith("_") else name)
        o += size
    cpu = {0x01000007: "x86_64", 0x0100000C: "arm64"}.get(cputype & 0xFFFFFFFF, hex(cputype))
    symtab = sorted(set(exports))
    if trie is not None:
        exports = [n[1:] if n.startswith("_") else n for n in _export_trie(data, trie[0], trie[1])]
    return {"format": "Mach-O", "machine": cpu, "exports": sorted(set(exports)),
            "symtab_externals": symtab, "dependencies": needed, "install_name": install_name,
            "min_macos": minos}


def read(path):
    """A dict: format, machine, exports (function and data symbols the
    library defines for others: ELF's dynamic symbols, PE's export table,
    Mach-O's export trie), dependencies (the libraries it loads, as written
    in the file), and for Mach-O install_name, min_macos and
    symtab_externals (the symbol table's external definitions)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"\x7fELF":
        return _elf(data)
    if data[:2] == b"MZ":
        return _pe(data)
    if data[:4] == b"\xcf\xfa\xed\xfe":
        return _macho(data)
    raise FormatError("%s is not an ELF, PE or Mach-O file" % path)


def dependencies(path):
    return read(path)["dependencies"]


def header_api(header):
    """The functions a header declares with WC_API."""
    with open(header, encoding="utf-8") as f:
        text = f.read()
    return sorted(set(re.findall(r"^WC_API\b[^;(]*?\b(\w+)\s*\(", text, re.M)))


# Symbols zig's Mach-O linker exports from every dylib it links: the
# addresses of the Mach header (___dso_handle, __mh_dylib_header as Mach-O
# spells them; Apple's ld keeps them local). Not code, and not the
# library's: tolerated, and named in the report.
MACHO_LINKER_SYMBOLS = {"__dso_handle", "_mh_dylib_header"}


def check(info, api, allow_deps, min_macos, machine):
    problems = []
    exports = set(info["exports"])
    if info["format"] == "Mach-O":
        exports -= MACHO_LINKER_SYMBOLS
    extra, missing = sorted(exports - set(api)), sorted(set(api) - exports)
    if extra:
        problems.append("exports %d symbols that are not the header's WC_API functions: %s"
                        % (len(extra), ", ".join(extra[:20]) + (" ..." if len(extra) > 20 else "")))
    if missing:
        problems.append("does not export %d of the header's functions: %s"
                        % (len(missing), ", ".join(missing)))
    if allow_deps is not None:
        allowed = {d.lower() for d in allow_deps}
        other = [d for d in info["dependencies"] if d.lower() not in allowed]
        if other:
            problems.append("needs %s besides %s" % (", ".join(other), ", ".join(allow_deps) or "nothing"))
    if min_macos is not None and info["format"] == "Mach-O":
        want = tuple(int(x) for x in min_macos.split("."))
        have = tuple(int(x) for x in (info["min_macos"] or "0").split("."))
        while len(want) < len(have):
            want += (0,)
        if have != want:
            problems.append("minimum macOS is %s, not %s" % (info["min_macos"], min_macos))
    if machine is not None and info["machine"] != machine:
        problems.append("is for %s, not %s" % (info["machine"], machine))
    return problems


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("library")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--header", help="the header whose WC_API functions must be the exports")
    ap.add_argument("--allow-dep", action="append", help="a library it may need (repeat)")
    ap.add_argument("--min-macos")
    ap.add_argument("--machine")
    args = ap.parse_args(argv)
    try:
        info = read(args.library)
    except (OSError, FormatError, struct.error, ValueError) as e:
        sys.exit("binary_info: %s: %s" % (args.library, e))
    if not args.check:
        print(json.dumps(info, indent=1))
        return 0
    if not args.header:
        ap.error("--check needs --header")
    api = header_api(args.header)
    problems = check(info, api, args.allow_dep, args.min_macos, args.machine)
    if problems:
        for p in problems:
            print("binary_info: %s %s" % (args.library, p), file=sys.stderr)
        return 1
    linker = sorted(MACHO_LINKER_SYMBOLS & set(info["exports"])) if info["format"] == "Mach-O" else []
    print("binary_info: %s (%s, %s) exports exactly the %d WC_API functions of %s%s; needs %s%s"
          % (args.library, info["format"], info["machine"], len(api), args.header,
             " (and the linker's %s)" % ", ".join("_" + n for n in linker) if linker else "",
             ", ".join(info["dependencies"]) or "nothing",
             "; minimum macOS %s" % info["min_macos"] if info.get("min_macos") else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
