#!/usr/bin/env python3
"""The commissioning's magnetic identification on saturated machines
(docs/results/commissioning-magnetics.md), measured on the current code.

For every preset of motors/saturated/ and the made-up test machine
crates/fado-sim/tests/data/ipmsm-test-saturated.toml, current-sensor seeds 1-4
(switching-resolved, default non-idealities, the nameplate the file's [motor] values, i.e. the
datasheet's unsaturated ones):
1. `fado-sim commission`: whether saturation is detected, and the identified model's errors
   against the plant's over the rated current range (incremental and secant L_d, L_q, flux);
   the linear presets of motors/ as well, for the detection;
2. closed loop: `reversal`, `stops` and `rated-reversal` (a) with the plant's own model and
   (b) with the commissioned identified.toml, per preset the largest angle error over the seeds
   (near zero speed for the reversals, over the run for `stops`) and the seeds passing.
Prints the Markdown page; `--write` writes it to docs/results/commissioning-magnetics.md.
`--machine FILE ...` prints only the two tables (closed loop, identification) for those motor
files: the closed-loop tables of docs/results/saturated-replay.md.
Usage: python3 scripts/commission-magnetics.py [--seeds 1 2 3 4] [--out DIR | --keep] [--write]
       python3 scripts/commission-magnetics.py --machine FILE ... [--seeds ...]
"""

import argparse
import json
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from importlib import import_module  # noqa: E402

from run_directory import add_arguments, run_directory  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "results" / "commissioning-magnetics.md"
SCENARIOS = ["reversal", "stops", "rated-reversal"]
MADE_UP = ROOT / "crates" / "fado-sim" / "tests" / "data" / "ipmsm-test-saturated.toml"
# A light rotor (2e-4 kg·m²) on a fast low-voltage-margin machine: the adapted pulses.
LIGHT = ROOT / "crates" / "fado-sim" / "tests" / "data" / "spm-dq-sat-saturated.toml"
LINEAR = ["paper", "pmsyrm-5k", "outrunner-cheetah-24v"]

table = import_module("saturation-table")


CACHE = {}


def commission(binary: Path, args: list, out: Path) -> dict:
    if out in CACHE:
        return CACHE[out]
    cmd = [str(binary), "commission", *args, "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode not in (0, 1):
        sys.exit(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    CACHE[out] = json.loads((out / "metrics.json").read_text())
    return CACHE[out]


def pc(x: float) -> str:
    return f"{100 * x:.2f}"


def accuracy_rows(binary: Path, machines: list, seeds: list, work: Path) -> list:
    rows = ["| machine | seed | saturation | change (%) | residual / linear | "
            "incr. L_d max / rms (%) | incr. L_q max / rms (%) | sec. L_d max (%) | "
            "sec. L_q max (%) | flux max (%) | turn per pair, estimated (rad) | "
            "plant's turn (rad) |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, args in machines:
        for seed in seeds:
            m = commission(binary, [*args, "--seed", str(seed)], work / f"{name}-{seed}")
            g = m.get("magnetics")
            if g is None:
                rows.append(f"| {name} | {seed} | {m['status']} | | | | | | | | | "
                            f"{m['rotor_motion_magnetics']:.3f} |")
                continue
            a = g["accuracy"]
            ratio = g["residual_rms"] / g["linear_residual_rms"]
            verdict = {"detected": "detected", "not_detected": "none"}.get(
                g["verdict"], g["verdict"].replace("_", " "))
            if not m["passed"]:
                # Aborted after the pulses: the fit with the nameplate's λf.
                verdict += f" ({m['status'].split('(')[0].lower()} later, λf nameplate)"
            rows.append(
                f"| {name} | {seed} | {verdict} "
                f"| {pc(g['inductance_change'])} | {ratio:.3f} "
                f"| {pc(a['incremental_ld']['max'])} / {pc(a['incremental_ld']['rms'])} "
                f"| {pc(a['incremental_lq']['max'])} / {pc(a['incremental_lq']['rms'])} "
                f"| {pc(a['secant_ld']['max'])} | {pc(a['secant_lq']['max'])} "
                f"| {pc(a['flux']['max'])} | {g['pulse_motion']:.3f} "
                f"| {m['rotor_motion_magnetics']:.3f} |")
    return rows


def closed_loop(binary: Path, preset: Path, seeds: list, work: Path) -> list:
    rows = []
    cells = {}
    for seed in seeds:
        true_cfg = table.with_seed(preset, seed, work)
        out = work / f"{preset.stem}-{seed}"
        m = commission(binary, ["--config", str(true_cfg), "--seed", str(seed)], out)
        ident = out / "identified.toml" if m["passed"] else None
        for scenario in SCENARIOS:
            for label, cfg in (("a", true_cfg), ("b", ident)):
                key = (scenario, label)
                cells.setdefault(key, [])
                if cfg is None:
                    cells[key].append(None)
                    continue
                r = table.run(binary, scenario, cfg, work / f"{preset.stem}-{scenario}-{label}-{seed}")
                angle_key = "max_angle_error" if scenario == "stops" else "max_angle_error_zero_speed"
                angle = float("inf") if r["tripped"] else r[angle_key]
                cells[key].append((angle, bool(r["passed"])))
    for scenario in SCENARIOS:
        row = [preset.stem, scenario]
        for label in ("a", "b"):
            got = cells[(scenario, label)]
            done = [c for c in got if c is not None]
            if not done:
                row += ["commissioning aborted", "0"]
                continue
            worst = max(a for a, _ in done)
            row += ["trip" if worst == float("inf") else f"{worst:.3f}",
                    str(sum(p for _, p in done))]
        rows.append("| " + " | ".join(row) + " |")
    return rows


HEAD = """# Magnetic identification at standstill

`fado-sim commission` on saturated machines: the flux-linkage pulses of
[`fado_core::commissioning`](../reference/rust.md) (module docs, step 5) fit the algebraic
saturation model (with the saturating rib of Lelli et al. where it explains the data),
tabulated as the flux map `identified-flux-map.csv` that `[model] flux_map` of
`identified.toml` names (the model's own `[model.saturation]` in its header). Every machine starts
from its datasheet (unsaturated, zero-current) `ld`, `lq`, `flux_linkage`; switching-resolved
inverter with dead time and threshold, default sensor offset, gain, noise and ADC, sensor seeds
{seeds}. Errors are identified/true − 1 over the rated current range (a 21 × 21 grid of
|i| ≤ I_rated; `fado_sim::magnetic_accuracy`): incremental L = ∂ψ/∂i on every point, secant
L_q = ψq/i_q where |i_q| ≥ 0.1·I_rated, secant L_d = (ψd(i_d, i_q) − ψd(0, i_q))/i_d where
|i_d| ≥ 0.1·I_rated, the flux |ψ̂ − ψ| relative to the magnet's. "change" is the detection
statistic (the fitted model's largest incremental-inductance change over the pulses' range),
"residual / linear" the fit's RMS current residual against the constant-inductance model's:
saturation is reported when the change exceeds 5 % and the ratio is below 0.5. The rotor is
not locked; "turn per pair, estimated" is the procedure's own estimate of the rotor's largest
turn over one pair of pulses (from the flux at the pair's end), the figure the verdict compares
with its 0.15 rad limit; "plant's turn" the plant's largest excursion from the pulses' start,
which the procedure does not see (electrical). "saturation" is the verdict: "inconclusive"
where the best fit changes its inductances by more than a quarter without explaining the
data, "rotor moved" where the estimated turn over a pair exceeds 0.15 rad (both keep
constant inductances).
`ipmsm-test-saturated` is a made-up machine of other exponents
(`crates/fado-sim/tests/data/ipmsm-test-saturated.toml`); `spm-dq-sat-saturated` a made-up
750 W servo SPM whose d axis saturates on the magnet, with a light rotor (2e-4 kg·m²) and an
electrical time constant of 28 samples at its derived carrier, on which the pulses adapt (docs/commissioning.md,
"Light rotors and fast machines"); the linear presets check the detection.

Regenerate: `python3 scripts/commission-magnetics.py --write` (about {minutes} minutes on one
core).

## Identification against the plant

"""

LOOP_HEAD = """
## Closed loop with the commissioned model

`reversal`, `stops` and `rated-reversal`, (a) with the plant's own magnetic model as the
drive's (`[model]` inherits it) and (b) with the commissioned `identified.toml` as it is
written, same seeds. Largest angle error over the seeds in rad (near zero speed for the
reversals, over the run for `stops`), "trip" when a seed tripped, and the seeds passing.

| preset | scenario | (a) true model | (a) passing | (b) commissioned | (b) passing |
|---|---|---|---|---|---|
"""


LIMITS = """
## Limits

- Every preset passes the three scenarios on every seed with its true and with its
  commissioned model. On the PM-SyRM's measured map the commissioned model's incremental
  inductances are off by up to a third at the edges of the rated range (below); the estimator
  holds with it because its turning R̂s law freezes where the frame coupling is large
  (docs/method/saturation.md, "The offset law's gate"), where it would read that model error
  as resistance.
- On these machines the identified λ̂f is high by 3 % (algebraic model) and 8 % (measured
  map): the back-EMF windows run at a d current of −½ the test limit and read the active flux
  through constant L̂d, L̂q. The pulses' fit takes this λ̂f as the magnet's flux, so it
  carries into every flux value (the "flux max" column) and into the inductances where the
  rib bends them.
- The measured map's own asymmetry in i_d and its noise are beyond the algebraic model (with
  the rib: the residual ratio 0.12–0.13 against 0.003–0.05 on the algebraic machines);
  its incremental inductances are off by up to a third at the edges of the rated range.
- A fitted model is used only where it has a physical meaning: its incremental inductances
  at the inductance tests' operating point within 20 % of those tests', and its incremental
  inductance matrix above a tenth of its zero-current one over the pulses' range. On the
  measured 1.1 kW PMSM map (`pmsm-gem-1k1-measured`, its saliency 1.2) the best fits of
  seeds 1, 3 and 4 (with the rib) fold back: their law i(ψ) gives a second flux for some
  currents inside the rated range, where the incremental inductance is about zero; those
  seeds keep constant inductances ("none" above), seed 2's fit stays invertible and is used.
- The identified flux map spans ± the drive's default current limit; the pulses measure only
  up to the rated current, and beyond it the table holds the model's extrapolation. A model
  that does not tabulate as a monotonic map there is written as `[model.saturation]`
  instead (with a warning).
- A magnetically linear machine's fit moves its inductances by up to a tenth on the strongly
  salient low-inductance `pmsyrm-5k` (the integration's own errors: inverter error at the
  current zero crossings) without explaining the data, which the residual criterion rejects.
- On `spm-dq-sat-saturated`, at the 10 kHz carrier its ripple rule derives, the adapted
  pulses hold the light rotor to about 0.15 rad and identify its saturation (the table);
  the commissioned model passes `reversal` and `stops` on seeds 1–4
  (`crates/fado-sim/tests/commission_magnetics.rs`). On a 5 kHz carrier the inverter error
  (4/3·V̂ = 6.7 V on its 320 V link) is a third of the pulse voltage, and where a phase
  current passes through zero inside a sample its error is known only to within that: the
  verdict is "inconclusive" and the model keeps constant inductances. With them the online
  R̂s law reads the flux error at load as resistance and `stops` fails, so identified.toml
  fixes R̂s at the commissioned value (`[estimator.rs_adaptation] enabled = false`, as for
  every inconclusive or rotor-moved verdict), with which `reversal` and `stops` pass on
  seeds 1–4 (the same test file).
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4])
    add_arguments(ap)
    ap.add_argument("--write", action="store_true", help=f"write {PAGE.relative_to(ROOT)}")
    ap.add_argument("--machine", type=Path, nargs="+",
                    help="only the closed-loop and identification rows of these motor files")
    args = ap.parse_args()
    if args.machine and args.write:
        ap.error("--machine prints rows for another page; it does not --write")
    subprocess.run(["cargo", "build", "--release", "--quiet", "-p", "fado-sim", "--bin",
                    "fado-sim"], cwd=ROOT, check=True)
    binary = ROOT / "target" / "release" / "fado-sim"
    with run_directory(args.out, args.keep, "fado-commission-magnetics-") as work:
        if args.machine:
            page = machine_rows(binary, [p.resolve() for p in args.machine], args.seeds, work)
        else:
            page = measured_page(binary, args.seeds, work)
    if args.write:
        PAGE.write_text(page, encoding="utf-8")
    print(page)


def machine_rows(binary: Path, files: list, seeds: list, work: Path) -> str:
    """The closed-loop rows, then the identification rows, of the motor `files`."""
    loop = []
    for f in files:
        loop += closed_loop(binary, f, seeds, work)
    ident = accuracy_rows(binary, [(f.stem, ["--config", str(f)]) for f in files], seeds, work)
    return "\n".join(loop) + "\n\n" + "\n".join(ident) + "\n"


def measured_page(binary: Path, seeds: list[int], work: Path) -> str:
    """Runs the closed loop and the accuracy table in `work`; the page."""
    presets = sorted((ROOT / "motors" / "saturated").glob("*.toml"))
    loop = []
    for preset in [*presets, MADE_UP]:
        loop += closed_loop(binary, preset, seeds, work)
    # The closed loop's commissions (same machine, seed and output directory) are reused.
    machines = [(p.stem, ["--config", str(p)]) for p in [*presets, MADE_UP]]
    machines += [(LIGHT.stem, ["--config", str(LIGHT)])]
    machines += [(name, ["--motor", name]) for name in LINEAR]
    lines = accuracy_rows(binary, machines, seeds, work)
    seeds_text = "–".join(str(s) for s in (seeds[0], seeds[-1])) \
        if len(seeds) > 1 else str(seeds[0])
    return HEAD.format(seeds=seeds_text, minutes=5) + "\n".join(lines) + "\n" + LOOP_HEAD \
        + "\n".join(loop) + "\n" + LIMITS


if __name__ == "__main__":
    main()
