#!/usr/bin/env python3
"""Loss-of-lock detector evaluation (issue 14): reads `fado-sim sweep` CSVs of the fig11
envelope and prints the detection/false-alarm table of docs/lock.md; with --figure PNG draws
the detection-delay distribution.

Labels (per run, from the true angle error over the whole run with the gates on):
  lost  = max |θ − θ̂| > 1 rad; detected = LOCK_LOST raised no later than 20 ms after
          |θ − θ̂| first exceeded 0.5 rad (raised earlier counts as detected);
  detected in the window = raised no earlier than 0.5 s before and no later than 20 ms after
          (the verdict latches: a flag raised at start-up, seconds before a loss, says nothing
          about that loss);
  clean = max |θ − θ̂| < 0.25 rad; false alarm = LOCK_LOST raised at all in a clean run.
Also: runs passing the paper's criteria (sweep `passed`) that raised the flag.

usage: scripts/lock-eval.py LABEL=DIR/sweep.csv ... [--figure docs/lock-detection.png]
"""

import csv
import math
import sys


def load(path):
    rows = [r for r in csv.DictReader(open(path)) if r["status"] == "ok"]
    f = lambda r, k: float(r[k]) if r[k] != "" else math.nan
    out = []
    for r in rows:
        out.append(
            dict(
                max_run=f(r, "max_angle_error_run"),
                exceeded=f(r, "angle_error_exceeded_time"),
                flagged=f(r, "lock_lost_time"),
                passed=r["passed"] == "true",
            )
        )
    return out


def stats(rows):
    lost = [r for r in rows if r["max_run"] > 1.0]
    delays = [r["flagged"] - r["exceeded"] for r in lost if not math.isnan(r["flagged"])]
    detected = sum(1 for d in delays if d <= 0.020)
    in_window = sum(1 for d in delays if -0.5 <= d <= 0.020)
    never = sum(1 for r in lost if math.isnan(r["flagged"]))
    clean = [r for r in rows if r["max_run"] < 0.25]
    fa = sum(1 for r in clean if not math.isnan(r["flagged"]))
    passed = [r for r in rows if r["passed"]]
    fap = sum(1 for r in passed if not math.isnan(r["flagged"]))
    late = sorted(d for d in delays if d > 0.020)
    return dict(
        runs=len(rows), lost=len(lost), detected=detected, in_window=in_window, never=never, clean=len(clean),
        fa=fa, passed=len(passed), fap=fap, delays=delays,
        late_median=late[len(late) // 2] if late else math.nan,
    )


def pct(a, b):
    return f"{100 * a / b:.1f} %" if b else "—"


def main(argv):
    fig = None
    if "--figure" in argv:
        k = argv.index("--figure")
        fig = argv[k + 1]
        argv = argv[:k] + argv[k + 2 :]
    results = []
    print("| configuration | runs | lost (> 1 rad) | flagged ≤ 20 ms after 0.5 rad | never flagged "
          "| raised in the window −0.5 s … +20 ms | median delay of the late ones | clean (< 0.25 rad) | false alarms | pass paper criteria | flagged |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for arg in argv:
        label, path = arg.split("=", 1)
        s = stats(load(path))
        results.append((label, s))
        late = f"{1000 * s['late_median']:.0f} ms" if not math.isnan(s["late_median"]) else "—"
        print(f"| {label} | {s['runs']} | {s['lost']} | {s['detected']} ({pct(s['detected'], s['lost'])}) "
              f"| {s['never']} | {s['in_window']} ({pct(s['in_window'], s['lost'])}) | {late} | {s['clean']} | {s['fa']} ({pct(s['fa'], s['clean'])}) "
              f"| {s['passed']} | {s['fap']} ({pct(s['fap'], s['passed'])}) |")
    if fig:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig_, ax = plt.subplots(figsize=(8, 4.5))
        for label, s in results:
            d = sorted(max(-1.0, min(1.0, x)) for x in s["delays"])
            n = s["lost"]
            ys = [(k + 1) / n for k in range(len(d))]
            ax.step(d, ys, where="post", label=f"{label} ({n} lost)")
        ax.axvline(0.020, color="k", ls="--", lw=0.8)
        ax.text(0.025, 0.03, "20 ms", fontsize=8)
        ax.set_xlim(-1.0, 1.0)
        ax.set_ylim(0, 1)
        ax.set_xlabel("flag time − first |θ − θ̂| > 0.5 rad (s, clipped to ±1 s)")
        ax.set_ylabel("fraction of runs that lose the rotor (> 1 rad)")
        ax.set_title("fig11 envelope, switching-resolved: loss-of-lock detection delay (CDF)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
        fig_.tight_layout()
        fig_.savefig(fig, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1:])
