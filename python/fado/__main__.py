"""Command line: ``python -m fado reproduce`` (the paper's Fig. 8–12 as figures and a metrics
table) and ``python -m fado simulate`` (one scenario).

::

    python -m fado reproduce --out out/repro [--averaged] [--scenarios fig8,fig11]
    python -m fado simulate fig11 [--config my.toml] [--averaged] [--out DIR] [--plot]
    python -m fado simulate reversal --motor ipmsm-2k2
    python -m fado scenarios
    python -m fado motors
    python -m fado default-config fig11 [--averaged] [--motor NAME]

Exit codes: 0 success (``simulate``: criteria passed), 1 criteria failed (``simulate`` only;
``reproduce`` reports failures in its table), 2 usage or configuration error.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

from fado._fado import (
    FadoError,
    Machine,
    default_config,
    describe_scenario,
    machine_presets,
    scenarios,
)
from fado._simulation import simulate


def _scenario_list(text: str) -> list[str]:
    names = [s.strip() for s in text.split(",") if s.strip()]
    if not names:
        raise argparse.ArgumentTypeError("give at least one scenario, e.g. fig8,fig11")
    return names


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m fado",
        description="Sensorless PMSM drive of Park & Sul (FADO): simulate the paper's "
        "experiments.",
    )
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser(
        "reproduce",
        help="run the scenarios, write DIR/figN.png, DIR/figN_metrics.json, DIR/metrics.md",
    )
    r.add_argument("--out", type=Path, required=True, help="output directory")
    r.add_argument("--averaged", action="store_true", help="averaged inverter model (fast)")
    r.add_argument(
        "--scenarios",
        type=_scenario_list,
        default=None,
        help="comma-separated subset, e.g. fig8,fig11 (default: all)",
    )
    r.add_argument("--config", type=Path, help="TOML file applied to every scenario")
    r.add_argument("--no-plots", action="store_true", help="metrics only (no matplotlib)")

    s = sub.add_parser("simulate", help="run one scenario and print its metrics")
    s.add_argument("scenario", help="scenario name (see `scenarios`)")
    s.add_argument("--config", type=Path, help="TOML file overriding the scenario")
    s.add_argument("--motor", help="motor preset (see `motors`) replacing the paper's motor")
    s.add_argument("--averaged", action="store_true", help="averaged inverter model (fast)")
    s.add_argument("--out", type=Path, help="write DIR/metrics.json and DIR/traces.csv")
    s.add_argument("--plot", action="store_true", help="also write DIR/SCENARIO.png")

    sub.add_parser("scenarios", help="list the scenarios")
    sub.add_parser("motors", help="list the motor presets")

    d = sub.add_parser("default-config", help="print a scenario's configuration as TOML")
    d.add_argument("scenario")
    d.add_argument("--averaged", action="store_true")
    d.add_argument("--motor", help="motor preset replacing the paper's motor")
    return p


def _write_csv(path: Path, traces: Mapping[str, object]) -> None:
    import numpy as np

    names = list(traces)
    table = np.column_stack([np.asarray(traces[n]) for n in names])
    # repr() of a float round-trips, like the CLI's shortest-representation output.
    with path.open("w", encoding="utf-8") as f:
        f.write(",".join(names) + "\n")
        for row in table:
            f.write(",".join(repr(float(x)) for x in row) + "\n")


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "scenarios":
            for name in scenarios():
                info = describe_scenario(name)
                print(f"{name:<7} {info['title']}\n        criterion: {info['criterion']}")
            return 0
        if args.command == "motors":
            for name in machine_presets():
                m = Machine.preset(name)
                print(
                    f"{name:<22} p={m.pole_pairs:<3} Rs={m.rs:g} Ω  Ld={m.ld:g} H  "
                    f"Lq={m.lq:g} H  λf={m.flux_linkage:g} Wb  {m.rated_current:g} A  "
                    f"{m.rated_speed_rpm:g} r/min  {m.rated_torque:g} N·m  {m.dc_voltage:g} V"
                )
            return 0
        if args.command == "default-config":
            print(default_config(args.scenario, args.averaged, motor=args.motor), end="")
            return 0
        if args.command == "reproduce":
            from fado.reproduce import reproduce

            reproduce(
                args.out,
                args.scenarios,
                args.averaged,
                args.config,
                plots=not args.no_plots,
            )
            return 0
        # simulate
        result = simulate(
            args.scenario, args.config, args.averaged, progress=True, motor=args.motor
        )
        metrics = result.metrics
        print(json.dumps({k: v for k, v in metrics.items() if k != "checks"}, indent=2))
        for c in result.checks:
            print(f"  [{'pass' if c['passed'] else 'FAIL'}] {c['name']}: {c['value']:.4g}")
        if args.out is not None:
            args.out.mkdir(parents=True, exist_ok=True)
            (args.out / "metrics.json").write_text(json.dumps(metrics, indent=2) + "\n")
            _write_csv(args.out / "traces.csv", result.traces)
            if args.plot:
                from fado.plot import plot_scenario

                plot_scenario(result, args.out / f"{args.scenario}.png")
            print(f"wrote {args.out}")
        return 0 if result.passed else 1
    except (FadoError, ValueError, OSError, ImportError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
