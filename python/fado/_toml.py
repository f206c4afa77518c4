"""A minimal TOML writer for simulator configurations given as ``dict``.

Enough for ``fado-sim``'s configuration: tables (nested ``dict``), and values that are
``bool``, ``int``, ``float``, ``str`` or lists of those (also lists of lists, e.g.
``disturbance_feedback_off = [[3.0, 5.0]]``, and lists of dicts as inline tables). A dotted
key (``{"mismatch.rs_ratio": 1.01}``) means the nested table. Floats are written with
``repr``, which round-trips exactly. Anything else raises ``fado.ConfigError`` naming the key.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import Any

from fado._fado import ConfigError


def _error(key: str, message: str) -> ConfigError:
    err = ConfigError(f"`{key}`: {message}")
    err.field = key
    return err


def _nest(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Expands dotted keys into nested dicts, merging tables given both ways
    (``{"motor.rs": 1}`` and ``{"motor": {"ld": 2}}``); a key set both ways is refused,
    whichever comes first."""
    out: dict[str, Any] = {}
    for key, value in table.items():
        if not isinstance(key, str) or not key:
            raise _error(prefix + str(key), "table keys must be non-empty strings")
        parts = key.split(".")
        node = out
        for depth, part in enumerate(parts[:-1]):
            child = node.setdefault(part, {})
            if not isinstance(child, dict):
                raise _error(prefix + ".".join(parts[: depth + 1]), "is both a value and a table")
            node = child
        last = parts[-1]
        if isinstance(value, Mapping):
            value = _nest(value, prefix + key + ".")
            existing = node.get(last)
            if isinstance(existing, dict):
                _merge(existing, value, prefix + key + ".")
                continue
        if last in node:
            raise _error(prefix + key, "given twice (as a dotted key and inside a table)")
        node[last] = value
    return out


def _merge(into: dict[str, Any], extra: dict[str, Any], prefix: str) -> None:
    """Adds `extra`'s keys to `into`, recursing into tables both have; a value in both is
    refused."""
    for key, value in extra.items():
        if key not in into:
            into[key] = value
        elif isinstance(into[key], dict) and isinstance(value, dict):
            _merge(into[key], value, prefix + key + ".")
        else:
            raise _error(prefix + key, "given twice (as a dotted key and inside a table)")


def _key(key: str) -> str:
    bare = key.replace("_", "").replace("-", "").isalnum() and key.isascii()
    return key if bare else json.dumps(key)


def _value(key: str, value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return int.__repr__(int(value))
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        # float's own repr: numpy scalars (float subclasses) would print "np.float64(...)".
        return float.__repr__(float(value))
    if isinstance(value, str):
        return json.dumps(value)  # JSON string escapes are valid TOML basic-string escapes
    if isinstance(value, Mapping):
        pairs = ", ".join(f"{_key(k)} = {_value(f'{key}.{k}', v)}" for k, v in value.items())
        return "{" + pairs + "}"
    if isinstance(value, Sequence) or _is_array(value):
        items = [_value(f"{key}[{i}]", v) for i, v in enumerate(_to_list(value))]
        return "[" + ", ".join(items) + "]"
    if _is_number(value):
        return _value(key, value.item())
    raise _error(key, f"cannot write a {type(value).__name__} as TOML")


def _is_array(value: Any) -> bool:
    return hasattr(value, "tolist") and getattr(value, "ndim", 0) >= 1


def _is_number(value: Any) -> bool:
    return hasattr(value, "item") and getattr(value, "ndim", 1) == 0


def _to_list(value: Any) -> list[Any]:
    return list(value.tolist()) if _is_array(value) else list(value)


def _table(lines: list[str], path: str, table: Mapping[str, Any]) -> None:
    scalars = {k: v for k, v in table.items() if not isinstance(v, Mapping)}
    tables = {k: v for k, v in table.items() if isinstance(v, Mapping)}
    if path and (scalars or not tables):
        lines.append(f"[{path}]")
    for key, value in scalars.items():
        lines.append(f"{_key(key)} = {_value(f'{path}.{key}' if path else key, value)}")
    for key, value in tables.items():
        if lines and lines[-1] != "":
            lines.append("")
        _table(lines, f"{path}.{_key(key)}" if path else _key(key), value)


def dumps(config: Mapping[str, Any]) -> str:
    """The TOML document for `config` (a dict of tables; dotted keys allowed)."""
    lines: list[str] = []
    _table(lines, "", _nest(config))
    return "\n".join(lines) + "\n"
