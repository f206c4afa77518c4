#!/usr/bin/env python3
"""Writes docs/results/firmware-cost.md whole from the output of scripts/firmware-cost.sh.

  firmware_cost_page.py LOG OUT

LOG is what firmware-cost.sh printed (it passes its own output); every figure of the page
comes from it, so that the page is the measurement's and nothing is copied by hand. The page
is written to a temporary file beside OUT and renamed over it (whole or not at all); a log
that lacks a figure the page needs is refused naming it, and OUT is left as it was.
"""

import os
import re
import sys
import tempfile

ROOTS = [
    "estimator_step",
    "paper_kernel_step",
    "paper_kernel_held_step",
    "drive_step",
    "flux_map_lookup",
    "flux_map_inverse",
    "uniform_table_lookup",
    "step_map_lookup",
    "estimator_step_table",
    "step_table_lookup",
]
STEP = re.compile(
    r"scenario (\d+): \d+ of \d+ steps measured: (\d+) instructions \(max \d+\), "
    r"(\d+) cycles \(max (\d+)\)"
)

BY_FILE = re.compile(r"\s+([0-9.]+) cycles\s+[0-9.]+ insns\s+(\S+)$")


def parse(log):
    """Per root and scenario (mean cycles, worst cycles); .text sizes; sizes and stacks.

    A root's scenario also gets ("own", scenario): its mean cycles without those of the image's
    own source (the out-of-line wrapper's call frame around an inlined fado-core body), from
    the trace's per-file lines."""
    cycles, text, sizes = {}, {}, {}
    root = None
    scenario = None
    titles = iter(ROOTS)
    for line in log.splitlines():
        if line.startswith("-- "):
            root = next(titles)
            cycles[root] = {}
            continue
        m = STEP.match(line)
        if m and root:
            scenario = int(m.group(1))
            cycles[root][scenario] = (int(m.group(3)), int(m.group(4)))
            cycles[root][("own", scenario)] = 0.0
            continue
        if line.startswith("    cycles by instruction class: ") and root and scenario is not None:
            cycles[root][("classes", scenario)] = line.split(": ", 1)[1].strip()
            continue
        m = BY_FILE.match(line)
        if m and root and scenario is not None and m.group(2).split(":")[0] != "image":
            cycles[root][("own", scenario)] += float(m.group(1))
            cycles[root][("file", scenario, m.group(2))] = float(m.group(1))
        m = re.match(r"\.text reachable from (\w+): (\d+) B", line)
        if m:
            text[m.group(1)] = int(m.group(2))
        for key in ("EstimatorState<f32>", "EstimatorParams<f32>"):
            m = re.search(re.escape(key) + r" = (\d+) B", line)
            if m:
                sizes[key] = int(m.group(1))
        m = re.search(r"deepest stack: (\d+) B below the idle loop.*?, (\d+) B below the caller", line)
        if m:
            sizes["stack_idle"], sizes["stack_step"] = int(m.group(1)), int(m.group(2))
    return cycles, text, sizes


class Missing(Exception):
    pass


def need(table, *keys):
    value = table
    for k in keys:
        if k not in value:
            raise Missing("/".join(str(x) for x in keys))
        value = value[k]
    return value


def fmt(x):
    return f"{x:,}"


def cell(cycles, root, s):
    mean, worst = need(cycles, root, s)
    return f"{fmt(mean)} ({fmt(worst)})"


def page(cycles, text, sizes):
    est = lambda s: need(cycles, "estimator_step", s)[0]  # noqa: E731
    kernel = need(cycles, "paper_kernel_step", 4)[0], need(cycles, "paper_kernel_step", 5)[0]
    held = need(cycles, "paper_kernel_held_step", 6)[0], need(cycles, "paper_kernel_held_step", 7)[0]
    fado_path = [est(s) for s in (4, 5, 6, 7)]
    own = [est(4) - kernel[0], est(5) - kernel[1], est(6) - held[0], est(7) - held[1]]
    adaptation = round(((est(0) - est(2)) + (est(1) - est(3))) / 2)
    drive = need(cycles, "drive_step", 12)[0]
    step_us = est(0) / 170.0
    uniform = need(cycles, "uniform_table_lookup", 13)
    inlined = round(need(cycles, "uniform_table_lookup", ("own", 13)))
    in_step = round(need(cycles, "step_map_lookup", ("own", 13)))
    typed = round(need(cycles, "step_table_lookup", ("own", 13)))

    def map_in_step(root):
        # The map's own instructions inside a saturating step (the lookups inlined there).
        return [round(sum(c for k, c in need(cycles, root).items()
                          if isinstance(k, tuple) and k[0] == "file" and k[1] == s
                          and k[2].startswith(("magnetics/uniform", "magnetics/lookup"))))
                for s in (10, 11)]

    map_typed, map_record = map_in_step("estimator_step_table"), map_in_step("estimator_step")
    step_typed = [need(cycles, "estimator_step_table", s)[0] for s in (10, 11)]
    step_record = [need(cycles, "estimator_step", s)[0] for s in (10, 11)]
    lo, hi = min(kernel + held), max(kernel + held)
    return f"""# Firmware cost on a Cortex-M4F

The `f32` estimator and drive built for `thumbv7em-none-eabihf` in the firmware image of
`examples/cortex-m` (cortex-m-rt, a 10 kHz SysTick interrupt standing in for the PWM
interrupt, QEMU's `mps2-an386` board), measured by the image itself.

Regenerate: `bash scripts/firmware-cost.sh` (writes this page whole; needs the
`thumbv7em-none-eabihf` target, `qemu-system-arm` and `binutils-arm-none-eabi`; a few minutes).

## Method

- **Instructions per step**: QEMU logs every executed instruction (`-d exec,nochain
  -singlestep`), filtered to the step's call graph (from the disassembly); a step is everything
  from one entry of the out-of-line step function to the next, averaged over the last 300 steps
  of each scenario (worst step in brackets).
- **Cycles**: each executed instruction weighted by the Cortex-M4 TRM (r0p1) timings (table 3-1
  and the FPU's table 7-1), zero wait states: ALU 1; LDR/STR 2, 1 when following another single
  load/store; LDM/STM/PUSH/POP 1+N; taken branch 3, not taken 1; VADD/VSUB/VMUL/VCMP/VMOV 1;
  VMLA/VFMA 3; VDIV/VSQRT 14; VLDR/VSTR 2. Not modelled: interrupt entry and exit (12 cycles
  plus lazy FPU stacking), flash wait states, bus contention, pipeline stalls. The figures are
  the step's own cycles on a zero-wait-state M4F, not a whole interrupt
  (`scripts/firmware_cost.py`).
- **Stack**: painted before each scenario, the lowest overwritten word afterwards.
- **Scenarios**: the paper's motor at 19.5 Hz and 700 Hz electrical (i_q = 0.4 × rated), and the
  salient `ipmsm-2k2` at 19.5 Hz and 75 Hz (its rated speed), with constant inductances and
  saturating (its model the 16 × 16 flux map in flash, "Flux map" below: the step compiled for
  the table and the machine record's step beside it on the same samples, whose estimates must
  agree bit for bit); every scenario must keep lock or the image fails (`bash
  scripts/firmware-run.sh`, run by CI).

## Results

Cycles per `f32` step, mean of the last 300 steps (worst step):

| step | 19.5 Hz | 700 Hz |
|---|---:|---:|
| `step_lean`, default (R̂s adaptation), the paper's motor | {cell(cycles, "estimator_step", 0)} | {cell(cycles, "estimator_step", 1)} |
| `step_lean`, the paper's fixed R̂s | {cell(cycles, "estimator_step", 2)} | {cell(cycles, "estimator_step", 3)} |
| `step_lean`, default, salient `ipmsm-2k2` (75 Hz in the second column) | {cell(cycles, "estimator_step", 8)} | {cell(cycles, "estimator_step", 9)} |
| the paper's method alone, hand-lean, gains every sample / held 0.4 ms | {fmt(kernel[0])} / {fmt(held[0])} | {fmt(kernel[1])} / {fmt(held[1])} |
| the whole drive (`SensorlessDrive<f32>`, estimator inside), the paper's motor at 300 r/min | {cell(cycles, "drive_step", 12)} | — |

| memory | bytes |
|---|---:|
| `EstimatorState<f32>` (what the step changes) | {need(sizes, "EstimatorState<f32>")} |
| `EstimatorParams<f32>` (constants, can live apart in a `static`) | {need(sizes, "EstimatorParams<f32>")} |
| deepest stack below the estimator step's caller (over its scenarios 0–11) | {need(sizes, "stack_step")} |
| deepest stack below the idle loop, interrupt and FPU frame included (the same) | {need(sizes, "stack_idle")} |

No software double precision, panic or formatting code is reachable from the interrupt, the
drive's step or the kernels (`bash scripts/check-firmware-symbols.sh`, a CI gate).

## Flux map

A saturating machine's model as a 16 × 16 flux map in flash: the table of
`examples/cortex-m/src/flux_lookup.rs` (uniform axes over ±12 A, the 2.2 kW IPMSM with q
self-saturation and cross-saturation), a `static` `FluxMap` built and checked by the compiler
(`FluxTable::const_map`) and the same table as a `static` `UniformFluxTable`
(`UniformFluxTable::from_f32_table`). Scenario 13, 300 calls each, mean (worst):

| unit | cycles | `.text` reachable |
|---|---:|---:|
| **one lookup ψ(i) as the estimator's step makes it**, the table named by its type (`EstimatorState::step_lean_in`: `FluxLookup::flux_warm` on `&UniformFluxTable<f32, 16, 16>`, inlined into the step) | {fmt(typed)} | — |
| the same out of line, its call frame included | {cell(cycles, "step_table_lookup", 13)} | {fmt(need(text, "step_table_lookup"))} B |
| one lookup ψ(i), the table borrowed at run time (`UniformFluxTable::flux` through a reference), inlined in its caller | {fmt(inlined)} | — |
| the same out of line, its call frame included | {cell(cycles, "uniform_table_lookup", 13)} | {fmt(need(text, "uniform_table_lookup"))} B |
| one lookup ψ(i) as the machine record's step makes it (`step_lean`: `MachineMagnetics::Uniform`, the model matched at run time, inlined into the step) | {fmt(in_step)} | — |
| the same out of line, its call frame included | {cell(cycles, "step_map_lookup", 13)} | {fmt(need(text, "step_map_lookup"))} B |
| one lookup ψ(i), any rectangular grid (`FluxMap::flux`, bilinear, no Jacobian) | {cell(cycles, "flux_map_lookup", 13)} | {fmt(need(text, "flux_map_lookup"))} B |
| its inverse i(ψ) from the trajectory's previous current (`FluxMap::current_from`, closed form per cell) | {cell(cycles, "flux_map_inverse", 13)} | {fmt(need(text, "flux_map_inverse"))} B |

A lookup's "inlined" cycles are the measured unit's own instructions, the ones the line tables
attribute to fado-core rather than to the image's wrapper: the `thumbv7em-none-eabihf` target
keeps a frame pointer in every function (rustc's target specification: `frame-pointer`
always), so an out-of-line call also pays `push {{r7, lr}}`, `mov r7, sp` and
`pop {{r7, pc}}` ({fmt(uniform[0] - inlined)} cycles), which a step that carries the lookup's
body does not.

The uniform table's lookup is straight-line code: each axis's index from the precomputed
inverse node spacing, t = (x − x₀)·(1/Δ) (no search, no division), converted to an integer and
clamped to the nodes (for a 16-node axis one `USAT`), and the fraction t − k; the node's eight
bilinear coefficients (ψd's and ψq's p00, p10 − p00, p01 − p00 and the twist, precomputed per
node and stored side by side; the last row and column hold the edge cell's polynomial at their
node, for the linear extension beyond the grid) loaded from one run; six multiplications and
additions per table. The array's shape is in the type, so no index is bounds-checked.
A firmware whose map is known when it is built steps the estimator with
`EstimatorState::step_lean_in(&params, &TABLE, v, i)`: the parameters' machine borrows the
same table (`MachineMagnetics::Uniform(&MAP)`, `MAP = TABLE.map()`), and the saturating step
is compiled for the table's type: the grid's origin and spacing become constants of the code,
the cells' address a register, and there is no match on the model: a lookup costs the step
{fmt(typed)} cycles (the first row), {"which meets the 60-cycle target of a lookup with " + fmt(60 - typed) + " cycles to spare" if typed <= 60 else "which misses the 60-cycle target of a lookup by " + fmt(typed - 60) + " cycles"}.
Where the table passed is not the parameters' model, `step_lean_in` is `step_lean` (one
compare of the model's tag and cells per sample decides). The machine record's own step
(`step_lean`) serves any model chosen at run time: each lookup matches on the model, loads the
borrowed map's record (origin, spacings, cells, shape) and checks the cell's index, {fmt(in_step)}
cycles (the fifth row). The unit's cycles by instruction class (the table named by its type,
out of line): {need(cycles, "step_table_lookup", ("classes", 13))} — the cell's eight
coefficients are eight single-word loads (2 cycles each: the compiler issues `VLDR`s, not a
`VLDM` of 1 + N, the registers it allocates not being consecutive). `FluxMap` keeps any
rectangular grid in four borrowed slices: a uniform axis (found so at construction) also gives
its cell with no load or division, and its two corners per row and table sit behind one bounds
check. Its inverse solves each bilinear cell's quadratic in closed form from the cell of the
warm start, jumping once to the cell of that solution's extrapolation and walking to the
neighbouring cell where the solution lies beyond the cell's edge; the scenario's trajectory
steps several cells between calls (a plant's sub-step stays in its cell or the next).

The estimator's step with the uniform table as its machine's model (`MachineModel::magnetics =
MachineMagnetics::Uniform(&UNIFORM_MAP)`, a `static` `UniformFluxMap` borrowing the table in
flash; the default configuration, scenarios 10–11, the salient `ipmsm-2k2` turned
saturating), both steps on the same samples, their estimates the same bit for bit:

| step | 19.5 Hz | 75 Hz |
|---|---:|---:|
| `step_lean_in`, default (R̂s adaptation), the 16 × 16 table named by its type | {cell(cycles, "estimator_step_table", 10)} | {cell(cycles, "estimator_step_table", 11)} |
| `step_lean`, the same, the machine record's model matched at run time | {cell(cycles, "estimator_step", 10)} | {cell(cycles, "estimator_step", 11)} |

The saturating step evaluates the map at the estimated current twice per sample (the active
flux's swing and the rotor flux, `fado_core::active_flux`), each with the secant's
ψq(î_d, 0) from the table's line i_q = 0 (a 1-D lookup that shares the 2-D lookup's d index),
none with a call of its own; the R̂s law's slots add a lookup with the Jacobian where the law
needs the incremental inductance. The map's own instructions (the lines of `magnetics/`
`uniform_table.rs`, `uniform_map.rs` and `lookup.rs`; the index conversions of `real.rs`
apart) cost the step compiled for the table {fmt(map_typed[0])} and {fmt(map_typed[1])} cycles
per sample on average in the two scenarios, the record's step {fmt(map_record[0])} and
{fmt(map_record[1])}. The rest of the two steps' difference is memory traffic: by instruction
class (scenario 10), the step compiled for the table spends
{need(cycles, "estimator_step_table", ("classes", 10))}; the record's
{need(cycles, "estimator_step", ("classes", 10))} — the borrowed model's record loaded again
around each evaluation, and the registers its matches take spilled.

## What the cycles buy

The paper's equations alone, in fado's discretisation and with nothing around them, cost
{fmt(lo)}–{fmt(hi)} cycles. fado's step adds its safeguards — sample bounds, the finite test of
the new state, the loss-of-lock detector, the held gains and the slow laws (R̂s, λ̂f, offset,
one per sample in turn) — for {fmt(min(own))}–{fmt(max(own))} cycles on the paper's path
({fmt(min(fado_path))}–{fmt(max(fado_path))} against {fmt(lo)}–{fmt(hi)}) and about
{fmt(adaptation)} more for the R̂s adaptation. A machine with constant inductances runs a copy
of the step with no test of a magnetic model in it; a saturating model's copy (the active flux at
the estimated current, `fado_core::active_flux`) is a separate function the step branches to
once per sample. On a 170 MHz Cortex-M4F the default estimator step takes
{100 * step_us / 25:.0f} % of a 40 kHz sampling period ({step_us:.1f} µs of 25 µs), and the
whole drive {100 * drive / 170.0 / 100:.0f} % of a 10 kHz period ({drive / 170.0:.0f} µs of 100 µs).
"""


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    log_path, out = sys.argv[1], sys.argv[2]
    with open(log_path, errors="replace") as f:
        log = f.read()
    try:
        text = page(*parse(log))
    except Missing as e:
        sys.exit(f"{log_path}: no figure for {e} in firmware-cost.sh's output; {out} left as it was")
    directory = os.path.dirname(out) or "."
    fd, tmp = tempfile.mkstemp(dir=directory, suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
