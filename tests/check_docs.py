"""The documentation's links and commands point at things that exist
(ctest test `docs_links`).

* Every relative link in README.md, CHANGELOG.md and docs/*.md resolves: the
  file (or folder) exists, and a `#fragment` names a heading of the target
  page (GitHub's anchor for it: lower case, punctuation dropped, spaces as
  hyphens).
* Every command the pages quote, in code spans and code blocks, names a
  program or script that exists: a source path (`tools/x.py`, `scripts/x.sh`,
  `tests/...`, `python/...`, `examples/...`) must be a file, and a built one
  (`build/tools/bench_collide`, `build-asan/tests/test_wet`, ...) must be a
  target that the CMake files add.

Usage: python tests/check_docs.py [REPO_ROOT]
"""

import glob
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(__file__), ".."))

LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
CODE_BLOCK = re.compile(r"^```.*?$(.*?)^```", re.S | re.M)
CODE_SPAN = re.compile(r"`([^`\n]+)`")
SOURCE_PATH = re.compile(r"(?<![\w./-])((?:tools|scripts|tests|python|examples|blender_addon|"
                         r"libwetcloth|include|cmake|\.ci)/[\w./+-]*[\w+-])")
BUILT_PATH = re.compile(r"(?<![\w./-])build[\w-]*/((?:tools|tests|examples)/[\w-]+)")


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def pages():
    out = [os.path.join(ROOT, n) for n in ("README.md", "CHANGELOG.md")
           if os.path.exists(os.path.join(ROOT, n))]
    return out + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))


def anchor(heading):
    """GitHub's anchor for a heading."""
    text = re.sub(r"`|\*\*|\*|_(?=\w)|(?<=\w)_", "", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text, flags=re.UNICODE)
    return text.replace(" ", "-")


def anchors(path):
    found, seen = set(), {}
    in_code = False
    for line in read(path).splitlines():
        if line.startswith("```"):
            in_code = not in_code
            continue
        m = re.match(r"#{1,6}\s+(.*)", line)
        if m and not in_code:
            a = anchor(m.group(1))
            n = seen.get(a, 0)
            seen[a] = n + 1
            found.add(a if n == 0 else "%s-%d" % (a, n))
    return found


def cmake_targets():
    targets = set()
    for path in glob.glob(os.path.join(ROOT, "**", "CMakeLists.txt"), recursive=True):
        if "/build" in path[len(ROOT):] or "/.venv" in path[len(ROOT):]:
            continue
        for m in re.finditer(r"add_executable\(\s*([\w-]+)", read(path)):
            targets.add(m.group(1))
        for m in re.finditer(r"wc_(?:add_)?(?:bench|test|example)\w*\(\s*([\w-]+)", read(path)):
            targets.add(m.group(1))
    return targets


def check_links(page, problems):
    base = os.path.dirname(page)
    text = CODE_BLOCK.sub("", read(page))
    for target in LINK.findall(text):
        if re.match(r"[a-z][a-z0-9+.-]*:", target) or target.startswith("mailto:"):
            continue
        path, _, fragment = target.partition("#")
        dest = os.path.normpath(os.path.join(base, path)) if path else page
        rel = os.path.relpath(page, ROOT)
        if not os.path.exists(dest):
            problems.append("%s: the link %s goes to %s, which does not exist"
                            % (rel, target, os.path.relpath(dest, ROOT)))
            continue
        if fragment and dest.endswith(".md") and fragment not in anchors(dest):
            problems.append("%s: the link %s names no heading of %s"
                            % (rel, target, os.path.relpath(dest, ROOT)))


def quoted_code(text):
    for m in CODE_BLOCK.finditer(text):
        yield m.group(1)
    for m in CODE_SPAN.finditer(CODE_BLOCK.sub("", text)):
        yield m.group(1)


def check_commands(page, targets, problems):
    rel = os.path.relpath(page, ROOT)
    for code in quoted_code(read(page)):
        for m in SOURCE_PATH.finditer(code):
            path = m.group(1)
            if "*" in path or "<" in path or "…" in path or re.search(r"_[xy]\.", path):
                continue  # a pattern or a placeholder (`tests/test_x.c`)
            full = os.path.join(ROOT, path)
            # a program named by its source (`tools/bench_wet` is tools/bench_wet.c)
            if not (os.path.exists(full) or os.path.exists(full + ".c")):
                problems.append("%s: `%s` names %s, which does not exist" % (rel, code.strip()[:60],
                                                                            path))
        for m in BUILT_PATH.finditer(code):
            name = m.group(1).split("/")[-1]
            # a folder the build makes beside a source folder (build/tests/consumer/)
            if name not in targets and not os.path.isdir(os.path.join(ROOT, m.group(1))):
                problems.append("%s: `%s` names the program %s, which no CMake file builds"
                                % (rel, code.strip()[:60], m.group(1)))


def main():
    problems = []
    targets = cmake_targets()
    checked = pages()
    for page in checked:
        check_links(page, problems)
        check_commands(page, targets, problems)
    for p in problems:
        print(p)
    print("%d pages checked, %d problems" % (len(checked), len(problems)))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
