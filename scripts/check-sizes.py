#!/usr/bin/env python3
"""Small pieces: no file in crates/*/src over 800 lines, no function there over 80.

Reads every `.rs` file below `crates/*/src` (rustfmt-formatted: a function's body closes
with a `}` at the indentation of its `fn`) and prints each file over FILE_LIMIT lines and
each function over FN_LIMIT lines (from its `fn` line to its closing brace, attributes and
doc comments excluded), named by path, line and name. Exits 1 when any is found that is not
in KNOWN, or when a known one has grown past the size listed there (a known exception may
shrink, not grow); prints the known ones that are back within the limits, to be removed.

Usage: python3 scripts/check-sizes.py [ROOT]   (ROOT: the repository, default: this script's)
"""

import pathlib
import re
import sys

FILE_LIMIT = 800
FN_LIMIT = 80

# Known exceptions, each with the size it may not exceed: code not yet cut into pieces.
# A file: "path"; a function: "path::name" (the first function of that name in the file
# that is over the limit).
KNOWN = {}

FN = re.compile(
    r'^(\s*)(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?'
    r'(?:extern\s+"[^"]*"\s+)?fn\s+(\w+)'
)


def functions(lines):
    """(line number, name, length) of every function with a body."""
    for i, line in enumerate(lines):
        m = FN.match(line)
        if not m:
            continue
        indent, name = m.group(1), m.group(2)
        j = i
        while j < len(lines) and not lines[j].rstrip().endswith(("{", ";")):
            j += 1
        if j == len(lines) or lines[j].rstrip().endswith(";") or lines[j].rstrip().endswith("}"):
            continue  # a declaration without a body, or a one-line body
        k = j + 1
        while k < len(lines) and lines[k].rstrip() != indent + "}":
            k += 1
        yield i + 1, name, k - i + 1


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)
    found = {}
    for path in sorted(root.glob("crates/*/src/**/*.rs")):
        rel = path.relative_to(root).as_posix()
        lines = path.read_text(encoding="utf-8").split("\n")
        if lines and lines[-1] == "":
            lines.pop()
        if len(lines) > FILE_LIMIT:
            found[rel] = (len(lines), f"{rel}: {len(lines)} lines (limit {FILE_LIMIT})")
        for line, name, length in functions(lines):
            key = f"{rel}::{name}"
            if length > FN_LIMIT and key not in found:
                found[key] = (length, f"{rel}:{line} fn {name}: {length} lines (limit {FN_LIMIT})")
    failed = False
    for key, (size, text) in found.items():
        if key not in KNOWN:
            print(f"TOO LONG: {text}")
            failed = True
        elif size > KNOWN[key]:
            print(f"GREW: {text}, listed in scripts/check-sizes.py at {KNOWN[key]}")
            failed = True
    for key in KNOWN:
        if key not in found:
            print(f"within the limits now, remove from KNOWN in scripts/check-sizes.py: {key}")
    known = sum(1 for key in found if key in KNOWN)
    print(f"{len(found) - known} new over the limits, {known} known exceptions")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
