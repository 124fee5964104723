"""Every row of docs/robustness.md's bad-input tables names a test, and every
test it names exists (ctest test `docs_robustness_table`).

A row's last cell names tests as the table's key says: `test_x: f` is the
function f in tests/test_x.c, `python_y: f` the function f in the pytest file
that ctest test python_y runs, `f[id]` one case of a parametrised test (the id
must appear in the file), a following bare `[id]` another case of the same
test, and a bare `name` a ctest test. ctest names are read from the
CMakeLists.txt files, so the check needs no build.

Usage: python tests/check_robustness_table.py [REPO_ROOT]
"""

import glob
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(__file__), ".."))
DOC = os.path.join(ROOT, "docs", "robustness.md")


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def ctest_tests():
    """ctest name -> the source files it runs (C file or pytest files)."""
    tests = {}
    for cm in glob.glob(os.path.join(ROOT, "**", "CMakeLists.txt"), recursive=True):
        top = os.path.relpath(cm, ROOT).split(os.sep)[0]
        if top.startswith(("build", ".")):  # build trees, virtual environments
            continue
        text = read(cm)
        for name in re.findall(r"^\s*wc_test\((\w+)\)", text, re.M):
            tests[name] = [os.path.join(ROOT, "tests", name + ".c")]
        for name, args in re.findall(r"^\s*wc_python_test\((\w+)\s+([^)]*)\)", text, re.M):
            files = [a.replace("${_wc_py_src}", os.path.join(ROOT, "python")) for a in args.split()]
            tests[name] = files
        for name, args in re.findall(r"add_test\(NAME (\w+)\s+([^)]*)\)", text):
            if "$" in name:
                continue
            files = []
            m = re.search(r"\$\{_wc_py_src\}/([\w/]+)", args)
            if m:
                path = os.path.join(ROOT, "python", m.group(1))
                files = sorted(glob.glob(os.path.join(path, "*.py"))) if os.path.isdir(path) \
                    else [path]
            if files or name not in tests:  # (a skipped variant registers no files)
                tests[name] = files
    return tests


def table_rows(doc):
    """(line number, last cell) of every data row of the tables under
    '## Every input surface'."""
    rows, inside = [], False
    for i, line in enumerate(doc.splitlines(), 1):
        if line.startswith("## "):
            inside = line.startswith("## Every input surface")
        if not inside or not line.startswith("|") or set(line) <= set("|- "):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[0] == "input":  # a header
            continue
        rows.append((i, cells[-1]))
    return rows


def defines(files, func):
    pattern = re.compile(r"^(def %s\(|(static )?\w[\w\s\*]*\b%s\(void\))" % (func, func), re.M)
    return any(pattern.search(read(f)) for f in files if f.endswith((".py", ".c")))


def check_reference(ref, files, tests):
    """Checks one `...` reference. files: those of the test named last in the
    cell (a bare `f` or `[id]` refers to it). Returns (error or None, the
    files of the test this reference names, None if it names none)."""
    m = re.fullmatch(r"(\w+): ([\w.]+)(\[(.+)\])?", ref)
    if m:
        name, func, case = m.group(1), m.group(2), m.group(4)
        if name not in tests:
            return "no ctest test %r" % name, None
        files = tests[name]
        if func.endswith(".py"):
            ok = any(os.path.basename(f) == func for f in files)
            return (None if ok else "%s does not run %s" % (name, func)), files
        return check_function(name, files, func, case), files
    m = re.fullmatch(r"(\w*)(\[(.+)\])?", ref)
    if not m:
        return None, None  # prose in backticks
    func, case = m.group(1), m.group(3)
    if func and not case and func in tests:
        return None, tests[func]  # a ctest test as a whole
    if files is None:
        if case or func.startswith("test_"):
            return "%r names no ctest test and follows none" % ref, None
        return None, None  # a field name
    if not func:  # [id]: another case of the previous parametrised test
        ok = any(('"%s"' % case) in read(f) for f in files)
        return (None if ok else "case %r not found in %s" % (case, files)), files
    return check_function("the previous test", files, func, case), files


def check_function(name, files, func, case):
    if not defines(files, func):
        return "%s: no function %s in %s" % (name, func, files)
    if case and not any(('"%s"' % case) in read(f) for f in files):
        return "%s: case %r of %s not found" % (name, case, func)
    return None


def main():
    tests = ctest_tests()
    errors, checked = [], 0
    for line, cell in table_rows(read(DOC)):
        refs = re.findall(r"`([^`]+)`", cell)
        named = 0
        files = None
        for ref in refs:
            err, named_files = check_reference(ref, files, tests)
            if err:
                errors.append("docs/robustness.md:%d: %s" % (line, err))
            if named_files is not None:
                named += 1
                files = named_files
        if named == 0:
            errors.append("docs/robustness.md:%d: the row names no test (%r)" % (line, cell))
        checked += 1
    for e in errors:
        print(e)
    print("%d rows checked, %d problems" % (checked, len(errors)))
    return 1 if errors or checked < 30 else 0


if __name__ == "__main__":
    sys.exit(main())
