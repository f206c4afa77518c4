#!/usr/bin/env python3
"""Dependencies point one way: no block module of fado-core names its user's tuning record.

A block (the flux integrator, a tracker, the current loop, the dead-time compensation, ...)
is configured from plain numbers and the machine model; the estimator and the drive build
their blocks' configurations from their own tuning records (`EstimatorTuning`,
`DriveTuning`) in their own folders. This script reads every `.rs` file below
`crates/fado-core/src` outside those folders (`estimator/`, `control/drive/`) and the
re-exports of `lib.rs` and `control/mod.rs`, and prints each line that names one of the
users' types (an import, a path, a doc link), named by path and line. Exits 1 when any is
found.

Usage: python3 scripts/check-deps.py [ROOT]   (ROOT: the repository, default: this script's)
"""

import pathlib
import re
import sys

# The users and the folders (relative to crates/fado-core/src) that own them.
USERS = {
    "EstimatorTuning": "estimator/",
    "DriveTuning": "control/drive/",
}
# Modules that only re-export the users' types.
REEXPORTS = {"lib.rs", "control/mod.rs"}

NAMES = re.compile(r"\b(" + "|".join(USERS) + r")\b")


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)
    src = root / "crates/fado-core/src"
    owners = tuple(USERS.values())
    found = []
    for path in sorted(src.glob("**/*.rs")):
        rel = path.relative_to(src).as_posix()
        if rel.startswith(owners) or rel in REEXPORTS:
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").split("\n"), 1):
            m = NAMES.search(line)
            if m:
                found.append(f"crates/fado-core/src/{rel}:{number}: names {m.group(1)}: {line.strip()}")
    for text in found:
        print(text)
    print(f"{len(found)} lines of block modules name their user's tuning record")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
