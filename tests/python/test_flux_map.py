"""`fado.Machine(..., flux_map=...)`: a saturating plant from a CSV file or arrays, the same
map in every form giving the same run bit for bit, and each refusal naming its cause."""

from __future__ import annotations

import pickle
import warnings
from pathlib import Path

import numpy as np
import pytest

import fado

IPMSM = dict(
    rs=3.6, ld=36e-3, lq=51e-3, flux_linkage=0.545, pole_pairs=3, inertia=0.015,
    rated_current=6.08, rated_speed_rpm=1500.0, rated_torque=14.0, dc_voltage=540.0,
)
SHORT = {"simulation": {"duration": 0.3}}


def grid() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A saturating map of the 2.2 kW IPMSM: secant Lq falling 30 % at 12 A, ψd dropping with
    |i_q| (cross-saturation); monotonic in its own current. Axes and (n_d, n_q) tables."""
    i_d = np.linspace(-12.0, 4.0, 9)
    i_q = np.linspace(-12.0, 12.0, 13)
    d, q = np.meshgrid(i_d, i_q, indexing="ij")
    psi_d = 0.545 + 0.036 * d - 2e-4 * q**2
    psi_q = 0.051 * q / (1.0 + 0.036 * np.abs(q))
    return i_d, i_q, psi_d, psi_q


def nodes() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The grid's nodes as four columns, shuffled."""
    i_d, i_q, psi_d, psi_q = grid()
    d, q = np.meshgrid(i_d, i_q, indexing="ij")
    cols = [d.ravel(), q.ravel(), psi_d.ravel(), psi_q.ravel()]
    order = np.random.default_rng(1).permutation(cols[0].size)
    return tuple(c[order] for c in cols)  # type: ignore[return-value]


def write_csv(path: Path, cols: tuple[np.ndarray, ...]) -> Path:
    rows = "\n".join(",".join(repr(float(x)) for x in r) for r in zip(*cols))
    path.write_text(f"# test map\ni_d,i_q,psi_d,psi_q\n{rows}\n")
    return path


def test_a_map_from_a_file_or_arrays_runs_the_same_plant(tmp_path: Path) -> None:
    path = write_csv(tmp_path / "map.csv", nodes())
    by_file = fado.Machine(**IPMSM, flux_map=path)
    assert by_file.flux_map == str(path)
    by_nodes = fado.Machine(**IPMSM, flux_map=nodes())
    by_grid = fado.Machine(**IPMSM, flux_map=grid())
    linear = fado.Machine(**IPMSM)
    assert linear.flux_map is None
    runs = [fado.simulate("reversal", SHORT, motor=m) for m in (by_file, by_nodes, by_grid)]
    for r in runs[1:]:
        for name in ("i_d", "i_q", "theta", "speed_rpm"):
            np.testing.assert_array_equal(r.traces[name], runs[0].traces[name], err_msg=name)
    # The map is the plant: the linear machine's currents differ.
    lin = fado.simulate("reversal", SHORT, motor=linear)
    assert not np.array_equal(lin.traces["i_q"], runs[0].traces["i_q"])


def test_the_map_survives_replace_pickle_and_dict(tmp_path: Path) -> None:
    m = fado.Machine(**IPMSM, flux_map=nodes())
    assert m.replace(rs=3.0).flux_map is not None
    assert m.replace(flux_map=None).flux_map is None
    assert pickle.loads(pickle.dumps(m)) == m
    assert fado.Machine(**m.to_dict()) == m
    i_d, i_q, psi_d, psi_q = m.flux_map  # i_d-major nodes
    assert i_d.shape == (9 * 13,) and np.all(np.diff(i_d) >= 0)
    assert fado.Machine(**{**IPMSM, "flux_map": str(write_csv(tmp_path / "m.csv", nodes()))})


def test_commission_takes_a_machine_with_a_map() -> None:
    r = fado.commission(fado.Machine(**IPMSM, flux_map=grid()), seed=1)
    assert r.passed, r.status
    # The plant's truth is the map's: L̂q lies between the saturated and unsaturated values.
    assert 0.035 < r.machine.lq < 0.052


def refusal(flux_map: object) -> fado.ConfigError:
    with pytest.raises(fado.ConfigError) as info:
        fado.Machine(**IPMSM, flux_map=flux_map)
    assert info.value.field == "flux_map"
    return info.value


def test_a_missing_file_is_refused_naming_it(tmp_path: Path) -> None:
    e = refusal(tmp_path / "absent.csv")
    assert "absent.csv" in str(e) and "cannot read" in str(e)


def test_a_csv_error_names_the_file_and_line(tmp_path: Path) -> None:
    cols = [c.copy() for c in nodes()]
    cols[2][4] = np.nan  # data row 5: line 7 (comment, header)
    path = write_csv(tmp_path / "nan.csv", tuple(cols))
    assert f"{path}:7:1:" in str(refusal(path))


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ("nan", "not finite"),
        ("ragged", "ragged"),
        ("not monotonic", "increase"),
        ("twice", "twice"),
    ],
)
def test_bad_arrays_are_refused_naming_the_node(change: str, words: str) -> None:
    cols = [c.copy() for c in nodes()]
    if change == "nan":
        cols[3][17] = np.nan
    elif change == "ragged":
        cols = [c[1:] for c in cols]
    elif change == "not monotonic":
        cols[3] = -cols[3]
    else:
        cols = [np.append(c, c[0]) for c in cols]
    e = refusal(tuple(cols))
    assert words in str(e), str(e)
    if change == "nan":
        assert "node 17" in str(e)


def test_bad_shapes_are_refused() -> None:
    i_d, i_q, psi_d, psi_q = grid()
    assert "four" in str(refusal((i_d, i_q, psi_d)))
    assert "shapes" in str(refusal((i_d, i_q, psi_d.T, psi_q.T)))
    assert "increase" in str(refusal((i_d, i_q, psi_d[::-1], psi_q)))


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_estimate_uses_the_machines_map(dtype: str) -> None:
    # The plant's own signals, replayed through a model with and without the map.
    every_sample = {"simulation": {"duration": 0.3, "decimation": 1}}
    run = fado.simulate("reversal", every_sample, motor=fado.Machine(**IPMSM, flux_map=grid()))
    tr = run.traces
    signals = (tr["v_alpha_ref"], tr["v_beta_ref"], tr["i_alpha"], tr["i_beta"])
    ts = float(tr["time"][1] - tr["time"][0])
    mapped = fado.Machine(**IPMSM, flux_map=grid())
    with_map = fado.estimate(*signals, machine=mapped, ts=ts, dtype=dtype)
    linear = fado.estimate(*signals, machine=fado.Machine(**IPMSM), ts=ts, dtype=dtype)
    assert np.all(np.isfinite(with_map.theta))
    assert not np.array_equal(with_map.theta, linear.theta)


def test_a_map_in_rms_currents_is_a_warning_naming_it(tmp_path: Path) -> None:
    # The same machine's map with its currents in A rms (peak / √2): both zero-current
    # inductances √2 × `ld`, `lq`, the magnet's flux unchanged.
    i_d, i_q, psi_d, psi_q = grid()
    rms = (i_d / np.sqrt(2.0), i_q / np.sqrt(2.0), psi_d, psi_q)
    with pytest.warns(UserWarning, match="A rms") as caught:
        fado.Machine(**IPMSM, flux_map=rms)
    assert "`flux_map`" in str(caught[0].message) and "`lq`" in str(caught[0].message)
    d, q = np.meshgrid(rms[0], rms[1], indexing="ij")
    path = write_csv(tmp_path / "rms.csv", (d.ravel(), q.ravel(), psi_d.ravel(), psi_q.ravel()))
    with pytest.warns(UserWarning, match="A rms"):
        fado.Machine(**IPMSM, flux_map=path)
    # The map in A peak: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fado.Machine(**IPMSM, flux_map=grid())
