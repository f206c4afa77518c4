#!/usr/bin/env python3
"""Re-runs points of a `fado-sim sweep reversal` envelope (scripts/lock-sweeps-preset.sh) with
full-rate traces and prints the state at the loss onset t0, at t0 + 20 ms and at the first
LOCK_LOST: angle error, true/estimated/reference speed as fractions of the rated speed,
|n* − n̂|, i_q* / rated current, mode (limiter or k_df), LOCK_LOST and the estimator's `lock`
status (0 locked, 1 suspect, 2 lost) (docs/method/lock.md). The point's load profile is
the reversal's ramp [1.2 s, 0] → [1.7 s, T_L], as the sweep's `load_torque` axis scales it.

usage: scripts/lock-trace-points.py PRESET OUT/VARIANT.toml OUT/VARIANT/sweep.csv POINT...
"""

import csv
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
LOCK_LOST = 128
LIMITER = 64


def main(preset, variant_toml, sweep, points):
    rows = {r["point"]: r for r in csv.DictReader(open(sweep))}
    with open(os.path.join(ROOT, "motors", preset + ".toml"), "rb") as f:
        motor = tomllib.load(f)["motor"]
    rated_i, rated_n = motor["rated_current"], motor["rated_speed_rpm"]
    for pt in points:
        row = rows[pt]
        tmp = tempfile.mkdtemp()
        try:
            cfg = os.path.join(tmp, "point.toml")
            with open(cfg, "w") as f:
                f.write(open(variant_toml).read())
                f.write(
                    f"\n[mismatch]\nrs_ratio = {1 + float(row['rs_error'])}\n"
                    f"lq_ratio = {1 + float(row['lq_error'])}\n"
                    f"flux_linkage_ratio = {1 + float(row['flux_linkage_error'])}\n"
                    f"\n[load.torque]\npoints = [[1.2, 0.0], [1.7, {row['load_torque']}]]\n"
                    "\n[simulation]\ndecimation = 1\n"
                )
            out = os.path.join(tmp, "out")
            binary = os.path.join(ROOT, "target/release/fado-sim")
            subprocess.run([binary, "run", "reversal", "--config", cfg, "--out", out], capture_output=True)
            trace = list(csv.DictReader(open(os.path.join(out, "traces.csv"))))
        finally:
            shutil.rmtree(tmp)

        def state(t):
            x = min(trace, key=lambda x: abs(float(x["time"]) - t))
            flags = int(float(x["fault_flags"]))
            n, n_hat, n_ref = (float(x[k]) / rated_n for k in ("speed_rpm", "speed_hat_rpm", "speed_ref_rpm"))
            return (
                f"t={t:.3f} err={float(x['angle_error']):+.2f} n={n:+.4f} n̂={n_hat:+.4f} n*={n_ref:+.4f} "
                f"|n*-n̂|={abs(n_ref - n_hat):.4f} iq*={float(x['i_q_ref']) / rated_i:+.2f} "
                f"{'lim' if flags & LIMITER else 'kdf'} {'LOST' if flags & LOCK_LOST else '-'} st={x['lock']}"
            )

        print(
            f"#{pt} rs{float(row['rs_error']):+.3f} lf{float(row['flux_linkage_error']):+.3f} "
            f"lq{float(row['lq_error']):+.3f} TL{float(row['load_torque']):.2f} "
            f"max{float(row['max_angle_error_run']):.2f} pass={row['passed']}"
        )
        times = []
        if row["loss_onset_time"]:
            t0 = float(row["loss_onset_time"])
            times += [t0, t0 + 0.020]
        raised = [float(x["time"]) for x in trace if int(float(x["fault_flags"])) & LOCK_LOST]
        if raised:
            times.append(raised[0])
        for t in times:
            print("   ", state(t))


if __name__ == "__main__":
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:])
