#!/usr/bin/env bash
# Speed of the switching-resolved closed loop (plant + drive, one core) on every saturating
# preset against the same machine class with constant inductances: simulated seconds per CPU
# second of the process (user + system time from wait4, microsecond resolution, so that other
# load on the machine does not count), best of N. Writes docs/results/saturated-speed.md whole
# (a temporary file renamed over it) and prints its table.
# The default scenario is `stops`, which every preset passes: a run that trips stops switching
# and simulates its remaining seconds cheaply, so its figure would not be the drive's.
# Usage: bash scripts/saturated-speed.sh [N]      (env SCENARIO=stops, OUT=docs/results/saturated-speed.md)
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-5}
scenario=${SCENARIO:-stops}
out=${OUT:-docs/results/saturated-speed.md}
cargo build --release --quiet -p fado-sim
python3 - "$n" "$scenario" "$out" <<'EOF'
import json, os, subprocess, sys, tempfile

n, scenario, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
binary = "target/release/fado-sim"
presets = [
    ("motors/ipmsm-2k2.toml", "constant inductances"),
    ("motors/saturated/ipmsm-2k2-qsat.toml", "algebraic saturation"),
    ("motors/saturated/pmsyrm-baldor-5k6.toml", "algebraic saturation with rib"),
    ("motors/saturated/pmsyrm-baldor-5k6-measured.toml", "measured 21 × 27 flux map"),
    ("motors/saturated/pmsm-gem-1k1-measured.toml", "measured 12 × 25 flux map"),
]


def cpu_seconds(args):
    """User + system CPU seconds of one run (its own process, from wait4)."""
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_utime + usage.ru_stime, proc.returncode


load_before = os.getloadavg()
rows = []
with tempfile.TemporaryDirectory() as tmp:
    for path, kind in presets:
        runs = [cpu_seconds([binary, "run", scenario, "--config", path, "--out", tmp + "/out"])
                for _ in range(n)]
        best = min(c for c, _ in runs)
        with open(tmp + "/out/metrics.json") as f:
            metrics = json.load(f)
        sim = metrics["simulated_seconds"]
        passed = bool(metrics["passed"])
        name = os.path.basename(path)[: -len(".toml")]
        rows.append((name, kind, sim, best, sim / max(best, 1e-6), passed))
load_after = os.getloadavg()

cpu = "unknown CPU"
with open("/proc/cpuinfo") as f:
    for line in f:
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
table = [
    f"| motor | magnetics | simulated (s) | CPU (s), best of {n} | × real time | `{scenario}` passed |",
    "|---|---|---:|---:|---:|---|",
]
for name, kind, sim, best, speed, passed in rows:
    table.append(f"| {name} | {kind} | {sim:.2f} | {best:.3f} | {speed:.0f} | {'yes' if passed else 'no'} |")
page = f"""# Saturated plant speed

The switching-resolved closed loop — plant (the stator flux linkage integrated as the state of a
saturating machine, i = i(ψ) from its magnetic model), inverter with dead time, sensors, drive
and estimator — on one core, scenario `{scenario}`: simulated seconds per CPU second of the
`fado-sim run` process (user + system time, so that other load on the machine does not count;
the run's own start-up and its trace and metrics files included), the best of {n} runs.
`ipmsm-2k2` is the constant-inductance reference (the plant's exact closed-form path).

Regenerate: `bash scripts/saturated-speed.sh [N]` (writes this page whole).

{chr(10).join(table)}

Measured on {os.cpu_count()} × {cpu} (x86-64 baseline build, release profile), load average
{load_before[0]:.1f} before and {load_after[0]:.1f} after the runs (other processes on the
machine: CPU time is the process's own, but on a loaded machine shared caches and cores still
slow it, so that figures measured under load are lower bounds).

## Where the time goes

Instructions counted by callgrind on `fado-sim run stops` (deterministic, unlike time on a
shared machine; `valgrind --tool=callgrind target/release/fado-sim run stops --config …`).

- **Flux map** (`pmsyrm-baldor-5k6-measured`, `pmsm-gem-1k1-measured`): the plant's inverse
  i(ψ) is solved in closed form per bilinear cell (`fado_core::magnetics`, "Inversion"); the
  sub-step is 0.05 of the shortest incremental time constant over the map's own grid
  (`fado-sim`'s `magnetics` module), so that nearly every interval of one switch state is one
  sub-step. Each Runge–Kutta stage, and the trapezoid rule's Euler end on a short interval
  (a dead time), is Newton's steps from the last solution in its cell (one, or a second where
  the first misses), taken where their error is below 10⁻⁵ of the cell (`STAGE_TOLERANCE`: a
  stage's current enters the flux through R·h/3 or less) and they stay in it; the map is
  inverted where they do not. The end's current, a hair from the last stage's flux, is one
  Newton step to 10⁻⁹ of the cell. `stops` on the GEM map has five intervals per sample,
  three in five short: nine stages and five ends per sample, 1.4 inversions. The plant keeps
  the last four cells' polynomials
  (`fado_core::magnetics::InverseCache`, moved from sample to sample) and solves first in
  the last solution's cell, then in the neighbour its root points into, taking a root that
  lies inside by more than 10⁻⁶ of the cell (the walk's own answer, bit for bit): 87 % of the
  inversions are one or two quadratics, a square root and two divisions each, with no search.
  The inversions are 5.5 % of the GEM map's instructions, the Newton steps 17 % and the
  Runge–Kutta steps around them 10 %. The estimator reads the map through its C¹ interpolant (docs/method/saturation.md
  "A map's interpolation") twice per sample, at the two operating points it forms (the
  observer's and the rotor flux's, at different currents): the flux alone
  (`FluxMap::smooth_flux`), the cells found as the bilinear lookup finds them, the node slopes
  along i_q loaded (found once per map); the Jacobian only in the slow laws' slots; ψq(i_d, 0)
  not at all on a map made odd in i_q (both measured presets). These reads are about 11 % of
  the instructions. The drive's torque solve on the map, Newton's steps from the last
  sample's i_q* ended by a step below 10⁻⁶ of the rated current (one or two flux solves
  instead of three), about 4 %.
- **Algebraic model** (`ipmsm-2k2-qsat`, `pmsyrm-baldor-5k6`): the plant's i(ψ) is the model's
  own closed form; the drive's and the estimator's ψ(i) are Newton solves started from the
  tangent plane of their last solution (`fado_core::magnetics::FluxWarmStart`: one step and the
  one that confirms it, 1.4 evaluations per solve on average), about 19 % of the PM-SyRM's
  instructions, the plant's i(ψ) 11 %.
- **Trace** (every motor): `traces.csv` keeps one sample in ten, 40 columns, each row formatted
  into one line buffer (`fado_sim::sim::CsvTraceWriter`: floats by `zmij` in `ryu`'s form, the
  bytes the `csv` crate writes): 5 % of the GEM map's instructions, 10 % of the
  constant-inductance motor's. A flux map's file is read once (the 21 × 27 Baldor map in 8 M
  instructions).
"""
os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
fd, tmp_path = tempfile.mkstemp(dir=os.path.dirname(out) or ".", suffix=".tmp")
with os.fdopen(fd, "w") as f:
    f.write(page)
os.replace(tmp_path, out)
print("\n".join(table))
print(f"wrote {out}")
EOF
