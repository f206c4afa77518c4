"""Speed of ``fado.estimate`` on the recording of ``dev/src/bin/replay-speed.rs`` (the Rust reference).

Run both on the same machine, one after the other::

    cargo run --release -p fado-dev --bin replay-speed
    python scripts/replay-speed.py

Prints the best of several runs in ns per sample for ``estimate`` in float64 and float32,
and for stepping ``Estimator.step`` from a Python loop (the per-call overhead).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

import numpy as np

import fado

TS = 100e-6
RS = 0.327
LQ = 2.63e-3
FLUX = 0.088
REPEATS = 5


def recording(n: int) -> list[np.ndarray]:
    """The same spin-up as replay-speed.rs: 0 → 20 Hz electrical in 0.3 s, i_q = 10 A."""
    k = np.arange(n)
    omega = 2 * np.pi * 20.0 * np.minimum(k * TS / 0.3, 1.0)
    theta = 0.3 + TS * np.concatenate(([0.0], np.cumsum(omega)))
    i = 10j * np.exp(1j * theta)
    flux = FLUX * np.exp(1j * theta) + LQ * i
    v = np.diff(flux) / TS + RS * 0.5 * (i[1:] + i[:-1])
    return [np.ascontiguousarray(x) for x in (v.real, v.imag, i[1:].real, i[1:].imag)]


def best_of(f: Callable[[], object]) -> float:
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    signals = recording(n)
    print(f"{n} samples, best of {REPEATS}")
    for dtype in ("float64", "float32"):
        t = best_of(lambda: fado.estimate(*signals, machine="paper", dtype=dtype))
        print(f"{dtype}: estimate() {t / n * 1e9:.1f} ns/sample")
    m = min(n, 100_000)
    rows = list(zip(*(s[:m].tolist() for s in signals)))

    def python_loop() -> None:
        est = fado.Estimator("paper")
        step = est.step
        for row in rows:
            step(*row)

    t = best_of(python_loop)
    print(f"float64: Estimator.step from a Python loop {t / m * 1e9:.1f} ns/sample")


if __name__ == "__main__":
    main()
