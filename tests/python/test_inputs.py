"""Bad arrays are refused with `fado.InputError` naming the argument; good ones are untouched."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import fado

N = 64
NAMES = ["v_alpha", "v_beta", "i_alpha", "i_beta"]


def good() -> list[np.ndarray]:
    rng = np.random.default_rng(7)
    return [rng.normal(size=N) for _ in range(4)]


def via_estimate(*signals: object) -> object:
    return fado.estimate(*signals, machine="paper")  # type: ignore[arg-type]


def via_run(*signals: object) -> object:
    return fado.Estimator("paper").run(*signals)  # type: ignore[arg-type]


BAD = {
    "list": lambda x: list(x),
    "scalar": lambda x: np.float64(1.0),
    "0-d": lambda x: np.array(1.0),
    "2-D": lambda x: x.reshape(8, 8),
    "column-vector": lambda x: x.reshape(N, 1),
    "every-other": lambda x: np.repeat(x, 2)[::2],
    "reversed": lambda x: x[::-1],
    "column-of-2-D": lambda x: np.stack([x, x], axis=1)[:, 0],
    "int64": lambda x: x.astype(np.int64),
    "bool": lambda x: x > 0,
    "float16": lambda x: x.astype(np.float16),
    "complex": lambda x: x.astype(np.complex128),
    "big-endian": lambda x: x.astype(">f8"),
    "object": lambda x: x.astype(object),
    "shorter": lambda x: x[:-1],
    "longer": lambda x: np.concatenate([x, x[:1]]),
}


@pytest.mark.parametrize("call", [via_estimate, via_run], ids=["estimate", "run"])
@pytest.mark.parametrize("position", range(4), ids=NAMES)
@pytest.mark.parametrize("kind", list(BAD))
def test_bad_input_names_the_argument(
    call: Callable[..., object], position: int, kind: str
) -> None:
    signals: list[object] = list(good())
    if kind in ("shorter", "longer") and position == 0:
        position = 3  # a length is judged against v_alpha's
    signals[position] = BAD[kind](signals[position])
    with pytest.raises(fado.InputError) as info:
        call(*signals)
    assert isinstance(info.value, ValueError)
    assert info.value.argument == NAMES[position]
    assert str(info.value).startswith(NAMES[position] + ":")


def test_messages_say_how_to_fix_it() -> None:
    x = good()
    with pytest.raises(fado.InputError, match="ascontiguousarray"):
        fado.estimate(x[0][::2], x[1][::2], x[2][::2], x[3][::2], machine="paper")
    with pytest.raises(fado.InputError, match="float64 or float32"):
        fado.estimate(x[0].astype(int), *x[1:], machine="paper")
    with pytest.raises(fado.InputError, match="length 63 differs from v_alpha's length 64"):
        fado.estimate(x[0], x[1][:-1], *x[2:], machine="paper")


def test_readonly_and_shared_arrays_are_accepted_and_untouched() -> None:
    x = good()
    before = [a.copy() for a in x]
    for a in x:
        a.flags.writeable = False
    result = fado.estimate(*x, machine="paper")
    same = fado.estimate(x[0], x[0], x[0], x[0], machine="paper")  # one array for all four arguments
    assert len(result) == len(same) == N
    for a, b in zip(x, before):
        np.testing.assert_array_equal(a, b, strict=True)


def test_contiguous_slice_of_a_larger_array_is_accepted() -> None:
    big = np.arange(4 * N, dtype=np.float64) * 1e-3
    parts = [big[k * N : (k + 1) * N] for k in range(4)]
    a = fado.estimate(*parts, machine="paper")
    b = fado.estimate(*(p.copy() for p in parts), machine="paper")
    np.testing.assert_array_equal(a.theta, b.theta, strict=True)


def test_mixed_float_dtypes_are_accepted() -> None:
    x = good()
    mixed = [x[0], x[1].astype(np.float32), x[2], x[3].astype(np.float32)]
    converted = [np.asarray(a, dtype=np.float64) for a in mixed]
    np.testing.assert_array_equal(
        fado.estimate(*mixed, machine="paper").theta, fado.estimate(*converted, machine="paper").theta, strict=True
    )
