#!/usr/bin/env python3
"""Loss-of-lock detector evaluation: reads `fado-sim sweep` CSVs of the fig11
envelope and prints the detection/false-alarm table of docs/method/lock.md; with --figure PNG draws
the detection-delay distribution.

Labels (per run, from the true angle error over the whole run with the gates on; the sweep's
columns are computed by `fado_sim::Metrics`):
  lost     = max |θ − θ̂| > 1 rad. Its onset t0 (`loss_onset_time`) = the first time
             |θ − θ̂| exceeded 0.5 rad in the excursion (from the last time it was below
             0.25 rad, `loss_settled_time`) that first went beyond 1 rad.
  The flag is the drive's loss evidence: LOCK_LOST (the estimator's verdict) or STALLED (the
  drive's stall symptom), either up; the sweep's `lock_detection_delay`/`lock_late_delay` judge
  that, `lock_lost_time` and `stall_time` are each flag's first rise. The false-alarm columns
  and detection are given for either flag and for LOCK_LOST alone (`lock_lost_detection_delay`;
  older sweeps without that column: run one with `[controller.stall] speed_ratio = 0.0`).
  detected = the flag (a live status) is up at t0 + 20 ms and rose no earlier than
             t0 − X (`lock_detection_delay` = its last rise − t0 ≥ −X), X = 1 s: the time
             fig11's reference takes from its steady −90 r/min to the reversal (2.5 → 3.5 s),
             the passage in which the fixed-R̂s integrand error shrinks |λ̂r| (the precursor the
             flux symptom sees, typically 0.5–0.8 s before the angle goes). A status raised
             within it and still up 20 ms after the error passes 0.5 rad warns of this loss;
             one raised earlier sat through steady running and says nothing about it (on
             fig11, that excludes every start-up flag: losses start after 3.3 s).
  X = 0.5 s, and since settled = stricter variants shown alongside: a rise at most 0.5 s
             before t0, or after the error was last below 0.25 rad (which misses warnings
             raised while the error drifts below 0.25 rad).
  late     = not detected, but LOCK_LOST rose after t0 in the excursion (`lock_late_delay`).
  also shown: flagged ≤ 20 ms counting any earlier flag (the first round's metric: the first
             LOCK_LOST of the run no later than 20 ms after the first 0.5 rad crossing).
  clean    = max |θ − θ̂| < 0.25 rad; false alarm = LOCK_LOST raised at all in a clean run.
Also: runs passing the paper's criteria (sweep `passed`) in which LOCK_LOST was raised
("flagged", the stricter figure the earlier sections quote), and the issue's own rate:
passing runs with a false alarm (flagged and clean) over passing runs.

Runs that tripped (sweep status `diverged`) are left out unless --with-tripped (they keep their
angle-error and LOCK_LOST columns up to the trip; on fig11 there is at most one a seed, on other
motors' envelopes many, docs/method/lock.md).

usage: scripts/lock-eval.py LABEL=DIR/sweep.csv ... [--with-tripped] [--figure docs/lock-detection.png]
"""

import csv
import math
import sys

DEADLINE = 0.020
LEAD = 1.0  # X: earliest rise that counts, s before t0


WITH_TRIPPED = False


def load(path):
    keep = ("ok", "diverged") if WITH_TRIPPED else ("ok",)
    rows = [r for r in csv.DictReader(open(path)) if r["status"] in keep]

    def f(r, k):
        return float(r[k]) if r.get(k, "") != "" else math.nan

    return [
        dict(
            max_run=f(r, "max_angle_error_run"),
            exceeded=f(r, "angle_error_exceeded_time"),
            flagged=min(f(r, "lock_lost_time"), f(r, "stall_time"), key=lambda x: (math.isnan(x), x)),
            lock_lost=f(r, "lock_lost_time"),
            onset=f(r, "loss_onset_time"),
            settled=f(r, "loss_settled_time"),
            delay=f(r, "lock_detection_delay"),
            delay_lock=f(r, "lock_lost_detection_delay"),
            late=f(r, "lock_late_delay"),
            passed=r["passed"] == "true",
        )
        for r in rows
    ]


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2] if xs else math.nan


def stats(rows):
    lost = [r for r in rows if r["max_run"] > 1.0]
    detected = [r for r in lost if r["delay"] >= -LEAD]
    detected_lock = sum(1 for r in lost if r["delay_lock"] >= -LEAD)
    half = sum(1 for r in lost if r["delay"] >= -0.5)
    since_settled = sum(
        1 for r in lost if r["delay"] >= -LEAD and (math.isnan(r["settled"]) or r["delay"] >= r["settled"] - r["onset"])
    )
    any_earlier = sum(
        1 for r in lost if not math.isnan(r["flagged"]) and r["flagged"] - r["exceeded"] <= DEADLINE
    )
    late = [r["late"] for r in lost if not r["delay"] >= -LEAD and r["late"] > DEADLINE]
    never = len(lost) - len(detected) - len(late)
    # The figure: the detecting rise, else the late one.
    delays = [r["delay"] if r["delay"] >= -LEAD else r["late"] for r in lost]
    clean = [r for r in rows if r["max_run"] < 0.25]
    fa = sum(1 for r in clean if not math.isnan(r["flagged"]))
    passed = [r for r in rows if r["passed"]]
    fap = sum(1 for r in passed if not math.isnan(r["flagged"]))
    # The issue's false-alarm rate: passing runs with a false alarm (flagged, < 0.25 rad
    # throughout) over passing runs.
    fapc = sum(1 for r in passed if not math.isnan(r["flagged"]) and r["max_run"] < 0.25)
    fa_lock = sum(1 for r in clean if not math.isnan(r["lock_lost"]))
    fap_lock = sum(1 for r in passed if not math.isnan(r["lock_lost"]))
    return dict(
        runs=len(rows), lost=len(lost), detected=len(detected), any_earlier=any_earlier, since_settled=since_settled, half=half,
        median_delay=median([r["delay"] for r in detected]), late=len(late),
        late_median=median(late), never=never, clean=len(clean), fa=fa, passed=len(passed),
        fap=fap, fapc=fapc, detected_lock=detected_lock, fa_lock=fa_lock, fap_lock=fap_lock, delays=delays,
        onset_moved=sum(1 for r in lost if r["onset"] != r["exceeded"]),
    )


def pct(a, b):
    return f"{100 * a / b:.1f} %" if b else "—"


def ms(x):
    return f"{1000 * x:.0f} ms" if not math.isnan(x) else "—"


def main(argv):
    global WITH_TRIPPED
    if "--with-tripped" in argv:
        WITH_TRIPPED = True
        argv = [a for a in argv if a != "--with-tripped"]
    fig = None
    if "--figure" in argv:
        k = argv.index("--figure")
        fig = argv[k + 1]
        argv = argv[:k] + argv[k + 2 :]
    results = []
    print("| configuration | runs | lost (> 1 rad) | **detected** (up at t0 + 20 ms, risen ≥ t0 − 1 s) "
          "| median delay | risen ≥ t0 − 0.5 s | risen since < 0.25 rad | raised late (median) | not raised "
          "| flagged ≤ 20 ms counting earlier flags | clean (< 0.25 rad) | **false alarms** | pass paper criteria | flagged "
          "| **passing with a false alarm** (flagged, < 0.25 rad) | LOCK_LOST alone: detected / clean flagged / passing flagged |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for arg in argv:
        label, path = arg.split("=", 1)
        s = stats(load(path))
        results.append((label, s))
        print(f"| {label} | {s['runs']} | {s['lost']} | {s['detected']} ({pct(s['detected'], s['lost'])}) "
              f"| {ms(s['median_delay'])} | {s['half']} ({pct(s['half'], s['lost'])}) | {s['since_settled']} ({pct(s['since_settled'], s['lost'])}) | {s['late']} ({ms(s['late_median'])}) | {s['never']} "
              f"| {s['any_earlier']} ({pct(s['any_earlier'], s['lost'])}) | {s['clean']} "
              f"| {s['fa']} ({pct(s['fa'], s['clean'])}) | {s['passed']} | {s['fap']} ({pct(s['fap'], s['passed'])}) "
              f"| {s['fapc']} ({pct(s['fapc'], s['passed'])}) "
              f"| {s['detected_lock']} ({pct(s['detected_lock'], s['lost'])}) / {s['fa_lock']} / {s['fap_lock']} |")
    for label, s in results:
        if s["onset_moved"]:
            print(f"({label}: in {s['onset_moved']} lost runs the onset is a later 0.5 rad crossing "
                  "than the first)", file=sys.stderr)
    if fig:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig_, ax = plt.subplots(figsize=(8, 4.5))
        for label, s in results:
            d = sorted(x for x in s["delays"] if not math.isnan(x))
            n = s["lost"]
            ys = [(k + 1) / n for k in range(len(d))]
            style = "--" if label.startswith("before") else "-"
            ax.step(d, ys, where="post", ls=style, label=f"{label} ({n} lost)")
        ax.axvline(DEADLINE, color="k", ls="--", lw=0.8)
        ax.axvline(-LEAD, color="k", ls=":", lw=0.8)
        ax.text(0.025, 0.03, "20 ms", fontsize=8)
        ax.text(-LEAD + 0.01, 0.03, "−X", fontsize=8)
        ax.set_xlim(-1.05, 0.5)
        ax.set_ylim(0, 1)
        ax.set_xlabel("rise of the LOCK_LOST up at t0 + 20 ms (else the first rise after t0) − t0 "
                      "(s)")
        ax.set_ylabel("fraction of runs that lose the rotor (> 1 rad)")
        ax.set_title("fig11 envelope, switching-resolved: loss-of-lock detection delay (CDF)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
        fig_.tight_layout()
        fig_.savefig(fig, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1:])
