"""Motors entered as their datasheets state them: `fado.Machine.from_datasheet` and
`fado-sim`'s `[motor]` table convert the same keys the same way, and derive the same values
(`--dump-config` against the Python machine, field by field)."""

from __future__ import annotations

import math
import subprocess
import tomllib
from pathlib import Path

import pytest

import fado
from test_simulate import fado_sim_cli  # noqa: F401  (the fixture)

# A 4-pole 310 V servo (crates/fado-sim/tests/data/datasheets/servo-310v-2pp.toml) and the
# slotless maxon EC 22 40 W (maxon-ec22-40w-24v.toml), in the datasheets' units.
DATASHEETS = {
    "servo-310v": {
        "rs_line_to_line": 3.07,
        "l_line_to_line": 6.57e-3,
        "ke_vll_peak_per_krpm": 51.0,
        "pole_pairs": 2,
        "rated_current": 5.22,
        "rated_speed_rpm": 4600.0,
        "rated_torque": 2.2,
    },
    "maxon-ec22": {
        "rs_line_to_line": 0.641,
        "l_line_to_line": 0.0546e-3,
        "ke_vll_peak_per_krpm": 1000.0 / 1470.0,
        "pole_pairs": 1,
        "rated_current_arms": 3.68 / math.sqrt(2.0),
        "rated_speed_rpm": 31800.0,
        "rated_torque": 20.7e-3,
        "inertia": 2.39e-7,
    },
    "servo-kt-rms": {
        "rs_line_to_line": 1.2,
        "l_line_to_line": 8e-3,
        "kt_nm_per_arms": 1.05,
        "pole_pairs": 4,
        "rated_current_arms": 4.0,
        "rated_speed_rpm": 3000.0,
        "rated_torque": 4.2,
    },
}


def _toml(fields: dict[str, float]) -> str:
    return "[motor]\n" + "".join(f"{k} = {float(v)!r}\n" if k != "pole_pairs" else f"{k} = {v}\n"
                                 for k, v in fields.items())


@pytest.mark.parametrize("name", sorted(DATASHEETS))
def test_the_cli_and_python_convert_and_derive_alike(name: str, fado_sim_cli: Path, tmp_path: Path) -> None:  # noqa: F811
    fields = DATASHEETS[name]
    machine = fado.Machine.from_datasheet(**fields)
    path = tmp_path / "motor.toml"
    path.write_text(_toml(fields), encoding="utf-8")
    dump = subprocess.run(
        [str(fado_sim_cli), "run", "reversal", "--config", str(path), "--dump-config"],
        capture_output=True, text=True, check=True, timeout=60,
    ).stdout
    assert "# derived: from " in dump
    config = tomllib.loads(dump)
    motor = config["motor"]
    for field in ("rs", "ld", "lq", "flux_linkage", "rated_current", "inertia", "viscous_friction"):
        assert getattr(machine, field) == pytest.approx(motor[field], rel=1e-12), field
    assert machine.dc_voltage == pytest.approx(config["inverter"]["dc_voltage"], rel=1e-12)


def test_the_conversions_follow_the_datasheet_conventions() -> None:
    m = fado.Machine.from_datasheet(**DATASHEETS["servo-310v"])
    assert m.rs == pytest.approx(1.535) and m.ld == m.lq == pytest.approx(3.285e-3)
    assert m.flux_linkage == pytest.approx(51.0 / math.sqrt(3) / (2 * 1000 * math.pi / 30))
    k = fado.Machine.from_datasheet(**DATASHEETS["servo-kt-rms"])
    assert k.flux_linkage == pytest.approx(1.05 / (1.5 * math.sqrt(2) * 4))
    assert k.rated_current == pytest.approx(4.0 * math.sqrt(2))


def test_a_key_given_both_ways_is_refused_naming_both() -> None:
    fields = dict(DATASHEETS["servo-310v"], rs=1.5)
    with pytest.raises(fado.ConfigError, match="rs_line_to_line") as info:
        fado.Machine.from_datasheet(**fields)
    assert info.value.field == "rs"
    fields = dict(DATASHEETS["servo-310v"], kt_nm_per_arms=0.6)
    with pytest.raises(fado.ConfigError, match="both give `flux_linkage`"):
        fado.Machine.from_datasheet(**fields)
    fields = {k: v for k, v in DATASHEETS["servo-310v"].items() if k != "pole_pairs"}
    with pytest.raises(fado.ConfigError, match="pole_pairs"):
        fado.Machine.from_datasheet(**fields)


# The slotless maxon EC 22 40 W on 24 V, and the same with a tenth of its inductance.
MAXON_FIELDS = {
    "rs": 0.3205,
    "ld": 27.3e-6,
    "lq": 27.3e-6,
    "flux_linkage": 3.75e-3,
    "pole_pairs": 1,
    "rated_current": 3.68,
    "rated_speed_rpm": 31800.0,
    "rated_torque": 20.7e-3,
    "dc_voltage": 24.0,
}


def test_the_carrier_rule_refuses_and_warns_as_the_cli() -> None:
    """`fado_core::ratings::check_carrier` through `fado.simulate`: a derived carrier above
    the 100 kHz of realistic inverters is refused naming the bound's keys and the carrier it
    needs, one above 40 kHz and a given carrier with a ripple above 1.2 times the rated
    current are warnings (crates/fado-sim/tests/datasheet_carrier.rs reads the same rows
    from a motor file)."""
    thin = fado.Machine(**{**MAXON_FIELDS, "ld": 2.73e-6, "lq": 2.73e-6})
    with pytest.raises(fado.ConfigError) as e:
        fado.simulate("stops", motor=thin)
    assert e.value.field == "motor.ld"
    for part in ("664 kHz", "100 kHz", "`motor.lq`", "`inverter.dc_voltage`", "`motor.rated_current`"):
        assert part in str(e.value), part
    short = {"simulation": {"duration": 0.01, "eval_start": 0.0}}
    maxon = fado.Machine(**MAXON_FIELDS)
    with pytest.warns(UserWarning, match="67 kHz"):
        fado.simulate("stops", config=short, averaged=True, motor=maxon)
    slow = {**short, "inverter": {"switching_frequency": 12000.0}}
    with pytest.warns(UserWarning, match="`inverter.switching_frequency` = 12000 Hz"):
        fado.simulate("stops", config=slow, averaged=True, motor=maxon)
