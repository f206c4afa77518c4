#!/usr/bin/env python3
"""Fails when README.md, the documentation or the crates' sources tell history.

The product states what fado is and why, in the present tense; how it came to be belongs in
CHANGELOG.md and in commit messages. Flagged (case-insensitive):

- "session" (a work session), except pytest's ``scope="session"`` and ``session`` fixtures;
- "pass" as a round of work: "second pass", "fifth pass", "pass 2";
- "issue <N>", "issue #N", "PR #N": references to the tracker;
- "main <hash>", "on main", "commit <hash>": versions of the repository;
- "SPEC §" citations of a working note that is not in the repository;
- "before … now" / "was … until" narration on one line.

Usage: python3 scripts/check_history_words.py [PATH ...]   (default: README.md docs crates)
Exit status 1 with FILE:LINE: WORD for every hit.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT = ["README.md", "docs", "crates"]
SUFFIXES = {".md", ".rs", ".py", ".pyi", ".toml", ".txt", ".rst"}
# Generated or vendored text the project does not write by hand.
SKIP_PARTS = {"auto_examples", "api", "_build", "target"}

ORDINAL = r"(first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|twelfth|last|next|previous|earlier|later)"
PATTERNS = [
    ("session", re.compile(r"\bsessions?\b", re.I)),
    ("pass (a round of work)", re.compile(rf"\b{ORDINAL}\s+pass(es)?\b|\bpass\s+\d+\b(?![.,]\d)", re.I)),
    ("issue number", re.compile(r"\b(issues?|PR|pull request)\s+#?\d+", re.I)),
    ("repository version", re.compile(r"\b(main|commit|branch)\s+[0-9a-f]{7,40}\b|\bon main\b", re.I)),
    ("SPEC citation", re.compile(r"\bSPEC\s*§")),
    ("before … now", re.compile(r"\bbefore\b.{0,80}\bnow\b|\bwas\b.{0,80}\buntil\b", re.I)),
]
# A hit on a line matching one of these is not history.
ALLOW = [
    re.compile(r"scope\s*=\s*[\"']session[\"']"),  # pytest fixture scope
    re.compile(r"\bsession\s*:\s*pytest\b|pytest\.Session|nox\.session"),
    re.compile(r"#\[|#!\[|\"#[0-9a-fA-F]{3,8}\"|'#[0-9a-fA-F]{3,8}'|color=\"#"),  # Rust attributes, colours
    re.compile(r"&#\d+;"),  # HTML character references
]


def rel(f: Path) -> Path:
    return f.relative_to(ROOT) if f.is_relative_to(ROOT) else f


def files(args: list[str]) -> list[Path]:
    out: list[Path] = []
    for a in args or DEFAULT:
        p = (ROOT / a) if not Path(a).is_absolute() else Path(a)
        if p.is_file():
            out.append(p)
        elif p.is_dir():
            out.extend(
                f
                for f in sorted(p.rglob("*"))
                if f.is_file()
                and f.suffix in SUFFIXES
                and not SKIP_PARTS & set(rel(f).parts)
            )
    return out


def main(argv: list[str]) -> int:
    hits = 0
    for f in files(argv):
        for n, line in enumerate(f.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            if any(a.search(line) for a in ALLOW):
                continue
            for name, pattern in PATTERNS:
                m = pattern.search(line)
                if m:
                    hits += 1
                    print(f"{rel(f)}:{n}: {name}: {m.group(0)!r}: {line.strip()[:120]}")
                    break
    if hits:
        print(
            f"{hits} line(s) tell history; state what is (the story goes in CHANGELOG.md and "
            "commit messages)",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
