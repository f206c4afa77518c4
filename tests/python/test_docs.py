"""Every Python and shell code block of README.md and the documentation pages (docs/**/*.md)
runs as written.

A block is a fenced ```python, ```py, ```sh, ```bash or ```console block. The line right
before its fence may say

- ``<!-- not run: REASON -->``: the block is not executed (REASON must say why: it is the
  test suite itself, needs a cluster, runs benchmarks for minutes, ...);
- ``<!-- doctest-setup: CODE -->`` (Python only): CODE runs first, in the same namespace,
  for names the prose supplies (a lab recording, a file the reader has).

The Python blocks of one file run in order in one namespace (later blocks use earlier
results, as a reader would), in a scratch directory (the figures they save land there) that
links the repository's `examples/` and `motors/`, the input files a reader in the repository
root has.
Shell blocks run line by line with bash from the repository root, `python` being this
interpreter; each line must exit 0 (or 1 for ``fado-sim run``, whose 1 means criteria
missed, see README "Exit codes").
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# Generated pages (the gallery's, the API reference's) are not hand-written documentation.
GENERATED = {"auto_examples", "api", "_build"}
DOCS = [
    ROOT / "README.md",
    *sorted(
        p for p in (ROOT / "docs").rglob("*.md") if not GENERATED & set(p.relative_to(ROOT).parts)
    ),
]
PYTHON = {"python", "py"}
SHELL = {"sh", "bash", "console", "shell"}
NOT_RUN = re.compile(r"^<!--\s*not run:\s*(\S.*?)\s*-->$")
SETUP = re.compile(r"^<!--\s*doctest-setup:\s*(.*?)\s*-->$")


@dataclass
class Block:
    path: Path
    line: int  # 1-based line of the opening fence
    lang: str
    code: str
    not_run: str | None
    setup: str | None

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def blocks(path: Path) -> list[Block]:
    found: list[Block] = []
    lines = path.read_text(encoding="utf-8").splitlines()
    k = 0
    while k < len(lines):
        # A language (```python) or a MyST directive (```{toctree}, never run).
        fence = re.match(r"^```(\{[\w-]+\}|\w*)(\s.*)?$", lines[k])
        if not fence:
            k += 1
            continue
        start = k
        k += 1
        body = []
        while k < len(lines) and not lines[k].startswith("```"):
            body.append(lines[k])
            k += 1
        k += 1
        before = lines[start - 1].strip() if start > 0 else ""
        not_run = NOT_RUN.match(before)
        setup = SETUP.match(before)
        found.append(
            Block(
                path,
                start + 1,
                fence.group(1).lower(),
                "\n".join(body) + "\n",
                not_run.group(1) if not_run else None,
                setup.group(1) if setup else None,
            )
        )
    return found


ALL = [b for p in DOCS for b in blocks(p)]
RUNNABLE = [b for b in ALL if b.lang in PYTHON | SHELL]


def test_every_python_or_shell_block_is_run_or_says_why_not() -> None:
    assert RUNNABLE, "no code blocks found: the parser or the paths are wrong"
    for b in ALL:
        assert b.lang, f"{b.where}: a code block without a language"
    for b in RUNNABLE:
        if b.not_run is not None:
            assert len(b.not_run.split()) >= 3, f"{b.where}: say why it is not run"


@pytest.mark.parametrize(
    "path", [p for p in DOCS if any(b.lang in PYTHON for b in blocks(p))], ids=lambda p: p.name
)
def test_python_blocks_run(path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("pandas")
    pytest.importorskip("matplotlib")
    monkeypatch.chdir(tmp_path)
    # A reader runs the blocks from the repository root: its input files are there too.
    for shared in ("examples", "motors"):
        (tmp_path / shared).symlink_to(ROOT / shared)
    namespace: dict[str, object] = {"__name__": "__doc__"}
    ran = 0
    for b in blocks(path):
        if b.lang not in PYTHON or b.not_run is not None:
            continue
        if b.setup:
            exec(compile(b.setup, f"{b.where} (setup)", "exec"), namespace)
        # Line numbers in tracebacks point into the document.
        code = "\n" * b.line + b.code
        exec(compile(code, str(b.path), "exec"), namespace)
        ran += 1
    assert ran > 0


SHELL_BLOCKS = [b for b in RUNNABLE if b.lang in SHELL and b.not_run is None]


@pytest.mark.parametrize("block", SHELL_BLOCKS, ids=lambda b: b.where)
def test_shell_blocks_run(block: Block) -> None:
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    for line in block.code.splitlines():
        command = line.strip()
        if not command or command.startswith("#"):
            continue
        done = subprocess.run(
            ["bash", "-c", command],
            cwd=ROOT,
            env=env,
            capture_output=True,
            text=True,
        )
        allowed = {0, 1} if " run " in command and "fado-sim" in command else {0}
        assert done.returncode in allowed, (
            f"{block.where}: `{command}` exited {done.returncode}\n{done.stderr[-2000:]}"
        )
