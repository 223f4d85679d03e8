#!/usr/bin/env python3
"""Every project file a comment names exists.

Reads the comments of the sources, tests, scripts and CMake files, picks out the paths they name
(`docs/usage.md`, `vision/flow.hpp`, `src/par/farm.cpp`, ...) and checks that each resolves: from
the repository root, from include/ or include/sg/ (how the headers are included), from src/, or
from the commenting file's own folder. A path is the project's when it starts with one of its
folders (docs/, src/, vision/, sg/, ...); others name a library's header (opencv2/...) or a file of
an input format (cam0/sensor.yaml) and are skipped. Exit 1 with one line per stale path.

Usage: scripts/check_comment_paths.py [REPO]   (default: the repository holding this script)
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)
FOLDERS = ["src", "include", "tests", "scripts", "bench", "examples", "python", "cmake", "fuzz",
           ".ci"]
CPP = {".hpp", ".cpp", ".h", ".cc"}
HASH = {".sh", ".py", ".cmake", ".txt", ".yaml", ".supp", ""}
PATH = re.compile(r"(?<![\w./-])((?:[\w.-]+/)+[\w.-]+"
                  r"\.(?:hpp|cpp|md|sh|py|yaml|txt|supp|json|cmake))\b")
OURS = set(FOLDERS) | {"docs", "sg", "core", "io", "par", "pipeline", "sim", "vision", "eval",
                       "apps"}


def comments(path):
    """The comment text of a file, line by line (number, text)."""
    text = path.read_text(errors="replace")
    if path.suffix in CPP:
        in_block = False
        for number, line in enumerate(text.splitlines(), 1):
            if in_block:
                end = line.find("*/")
                yield number, line if end < 0 else line[:end]
                in_block = end < 0
                continue
            # Text after // outside a string (a quote before it: skip the line's code part).
            slash = line.find("//")
            if slash >= 0 and line[:slash].count('"') % 2 == 0:
                yield number, line[slash + 2:]
            start = line.find("/*")
            if start >= 0 and line[:start].count('"') % 2 == 0:
                end = line.find("*/", start + 2)
                yield number, line[start + 2:] if end < 0 else line[start + 2:end]
                in_block = end < 0
    elif path.suffix in HASH or path.name == "CMakeLists.txt":
        for number, line in enumerate(text.splitlines(), 1):
            hash_at = line.find("#")
            if hash_at >= 0 and line[:hash_at].count('"') % 2 == 0 and \
                    line[:hash_at].count("'") % 2 == 0:
                yield number, line[hash_at + 1:]


def resolves(name, where):
    bases = [ROOT, ROOT / "include", ROOT / "include" / "sg", ROOT / "src", where]
    return any((base / name).exists() for base in bases)


def main():
    stale = []
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).rglob("*")):
            if not path.is_file() or "build" in path.relative_to(ROOT).parts:
                continue
            for number, text in comments(path):
                for name in PATH.findall(text):
                    if name.split("/")[0] not in OURS:
                        continue
                    if not resolves(name, path.parent):
                        stale.append(f"{path.relative_to(ROOT)}:{number}: names {name}, "
                                     "which does not exist")
    for line in stale:
        print(line)
    if stale:
        print(f"{len(stale)} comment(s) name a path that does not exist", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
