"""`fado.simulate("custom", ...)`: the user's own profiles, loads and criteria from Python
(docs/experiments.md), on the examples of examples/experiments/."""

from __future__ import annotations

from pathlib import Path

import fado

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "experiments"


def test_propeller_and_hoist_examples_pass_their_own_criteria() -> None:
    for name in ("propeller.toml", "hoist.toml"):
        result = fado.simulate("custom", str(EXAMPLES / name))
        assert result.passed, (name, result.checks)
        names = [c["name"] for c in result.checks]
        assert names == ["max |θ − θ̂| (rad)", "max speed error / rated speed", "tripped"]
        assert result.metrics["max_dc_voltage"] == 311.0


def test_custom_without_criteria_reports_and_passes() -> None:
    config = {
        "speed_reference": {"points": [[0.0, 0.0], [0.7, 0.0], [0.9, 2000.0]]},
        "load": {"mode": "quadratic", "coefficient": 2e-3},
    }
    result = fado.simulate("custom", config, averaged=True)
    assert result.passed and result.checks == []
    assert result.metrics["max_speed_error_rpm"] > 300.0
    assert abs(result.metrics["simulated_seconds"] - 1.9) < 1e-9


def test_hoist_on_a_rectifier_with_a_chopper_holds_the_bus() -> None:
    text = (EXAMPLES / "hoist.toml").read_text(encoding="utf-8")
    text += '\n[dc_link]\nsource = "rectifier"\nchopper_voltage = 335.0\n'
    result = fado.simulate("custom", text)
    assert result.passed, result.checks
    assert 311.0 < result.metrics["max_dc_voltage"] < 340.0
