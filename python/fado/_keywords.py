"""Keyword slips of the Python-level functions (``simulate``, ``sweep``, ``commission``):
a keyword the function does not take is refused naming the closest one it takes and where
the keyword belongs (``ts`` is ``fado.estimate``'s, ``switching_frequency`` a key of the
simulator's ``[inverter]`` table), as the native functions refuse theirs."""

from __future__ import annotations

import functools
import inspect
from typing import Any, Callable, TypeVar, cast

from fado import _fado

F = TypeVar("F", bound=Callable[..., Any])


def checked(function: F) -> F:
    """`function` with its keywords checked before the call (its signature unchanged)."""
    accepted = list(inspect.signature(function).parameters)

    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        for key in kwargs:
            if key not in accepted:
                raise TypeError(
                    _fado._unexpected_keyword(function.__name__, key, accepted)
                )
        return function(*args, **kwargs)

    return cast(F, call)
