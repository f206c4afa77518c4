"""``fado.simulate``: the closed-loop simulator with a configuration given any convenient way."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Union

from fado import _fado, _toml
from fado._keywords import checked

ConfigLike = Union[str, "os.PathLike[str]", Mapping[str, Any], None]


def _looks_like_toml(text: str) -> bool:
    return "\n" in text or "=" in text or text.lstrip().startswith("[")


def config_text(config: ConfigLike) -> str | None:
    """The TOML text of `config`: TOML itself, a path to a TOML file, or a dict of tables."""
    if config is None:
        return None
    if isinstance(config, Mapping):
        return _toml.dumps(config)
    if isinstance(config, os.PathLike):
        return Path(config).read_text(encoding="utf-8")
    if isinstance(config, str):
        if _looks_like_toml(config) or not config.strip():
            return config
        path = Path(config)
        if path.is_file():
            return path.read_text(encoding="utf-8")
        raise FileNotFoundError(
            f"config {config!r} is neither TOML text (no '=' or newline) nor an existing file"
        )
    raise TypeError(
        f"config must be TOML text, a path, a dict or None, got {type(config).__name__}"
    )


@checked
def simulate(
    scenario: str = "fig11",
    config: ConfigLike = None,
    averaged: bool = False,
    *,
    progress: bool = False,
    motor: str | _fado.Machine | dict[str, Any] | None = None,
) -> _fado.SimResult:
    """Runs one of the paper's experiments on the simulated drive (Rust, GIL released).

    `scenario` is one of :func:`fado.scenarios` (``fig8`` … ``fig12`` in the paper's units;
    ``reversal``, ``stops``, ``rated-reversal``, ``lowspeed``, ``loaded-start``,
    ``fullrange``, ``regen-stop`` scaled by the motor's ratings; ``custom``: the
    configuration's own profiles, judged only by its ``[criteria]``).
    `motor` replaces the paper's motor first: a preset name of :func:`fado.machine_presets`
    (its whole ``motors/`` file: ``[motor]`` and its ``[inverter]``), a :class:`fado.Machine`
    or a ``dict`` of its fields (as ``[motor]`` and ``[inverter] dc_voltage``). `config` then overrides
    the scenario's configuration key by key, given as TOML text, a path (``str`` or
    :class:`pathlib.Path`) to a TOML file, or a ``dict`` of tables such as
    ``{"simulation": {"duration": 1.0}, "mismatch.rs_ratio": 1.01}``; see
    :func:`fado.default_config` for every key. `averaged` selects the averaged inverter model
    (fast) instead of the switching-resolved one. `progress` prints a progress bar to stderr.

    Ctrl-C stops the run within milliseconds (``KeyboardInterrupt``). The trace is kept in
    memory, so a run whose trace would exceed 4 million rows (1.25 GB) is refused before it
    starts (:class:`fado.ConfigError` on ``simulation.decimation``); ``fado-sim run`` streams
    longer traces to disk.

    Returns a :class:`fado.SimResult` holding what ``fado-sim run`` writes: ``.metrics``
    (``metrics.json``), ``.traces`` (``traces.csv`` columns as float64 arrays), ``.passed``,
    ``.checks``, ``.config_toml``. A bad key or value raises :class:`fado.ConfigError` whose
    ``.field`` is the TOML path (e.g. ``"inverter.dead_time"``) and ``.line``, ``.column`` the
    place of its value in the TOML (for a file, the message reads ``FILE:LINE:COLUMN: ...``
    as from ``fado-sim``); an unknown scenario raises :class:`fado.InputError`; both are
    ``ValueError``.
    """
    text = config_text(config)
    try:
        return _fado.simulate(scenario, text, averaged, progress=progress, motor=motor)
    except _fado.ConfigError as e:
        path = _config_path(config)
        if path is not None and getattr(e, "line", None) is not None:
            rest = str(e).split(": ", 1)[-1]
            e.args = (f"{path}:{e.line}:{e.column}: {rest}",)
        raise


def _config_path(config: ConfigLike) -> str | None:
    """The file `config` names, if it is a path rather than TOML text or a dict."""
    if isinstance(config, os.PathLike):
        return os.fspath(config)
    if isinstance(config, str) and not _looks_like_toml(config) and config.strip():
        return config
    return None
