"""Wall time of `fado.simulate` against the `fado-sim` CLI for one scenario (a measured
report, not a test). Run after `cargo build --release -p fado-sim` and installing the package:

    python scripts/py_simulate_overhead.py [fig11] [--averaged] [--repeat 5]

For each side it reports the best of N of: the whole call (CLI: process start to exit, incl.
writing metrics.json and traces.csv; Python: the `simulate()` call in a running interpreter,
and a fresh `python -c` process incl. `import fado`) and the simulator's own loop time
(`wall_seconds` of metrics.json). Runs are interleaved so that machine load hits both alike.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fado

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("scenario", nargs="?", default="fig11")
    p.add_argument("--averaged", action="store_true")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--cli", type=Path, default=ROOT / "target" / "release" / "fado-sim")
    a = p.parse_args()
    flag = ["--averaged"] if a.averaged else []
    rows: dict[str, list[float]] = {k: [] for k in ("cli", "cli_loop", "py", "py_loop", "py_proc")}
    snippet = f"import fado; fado.simulate({a.scenario!r}, averaged={a.averaged})"
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(a.repeat):
            t = time.perf_counter()
            subprocess.run(
                [str(a.cli), "run", a.scenario, "--out", tmp, *flag],
                capture_output=True,
                check=False,
            )
            rows["cli"].append(time.perf_counter() - t)
            metrics = json.loads((Path(tmp) / "metrics.json").read_text())
            rows["cli_loop"].append(metrics["wall_seconds"])

            t = time.perf_counter()
            r = fado.simulate(a.scenario, averaged=a.averaged)
            rows["py"].append(time.perf_counter() - t)
            rows["py_loop"].append(r.metrics["wall_seconds"])

            t = time.perf_counter()
            subprocess.run([sys.executable, "-c", snippet], check=True)
            rows["py_proc"].append(time.perf_counter() - t)
    best = {k: min(v) for k, v in rows.items()}
    inverter = "averaged" if a.averaged else "switching-resolved"
    print(f"{a.scenario}, {inverter}, best of {a.repeat} (s):")
    print("| what | whole call | simulator loop | overhead |")
    print("|---|---|---|---|")
    print(
        f"| CLI `fado-sim run` (process, writes CSV) | {best['cli']:.3f} | "
        f"{best['cli_loop']:.3f} | {best['cli'] - best['cli_loop']:.3f} |"
    )
    print(
        f"| `fado.simulate()` in a running interpreter | {best['py']:.3f} | "
        f"{best['py_loop']:.3f} | {best['py'] - best['py_loop']:.3f} |"
    )
    print(f"| `python -c 'import fado; fado.simulate()'` | {best['py_proc']:.3f} | | |")


if __name__ == "__main__":
    main()
