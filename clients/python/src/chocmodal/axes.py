"""Axes of a sweep: which input (a JSON pointer into the inputs, ``/contact/rk``) takes
which values. Each helper returns the axis object ``POST /sweeps`` takes::

    from chocmodal import axes
    client.submit_sweep("cantilever-impact", inputs, [
        axes.logspace("/contact/rk", 0.1, 1e6, 8),
        axes.values("/solver/time_step", [1e-6, 1e-5, 3e-5, 1e-4]),
    ], invalid_runs="record")

List axes (``values``, ``linspace``, ``logspace``) span a grid; random axes
(``uniform``, ``normal``, ``lognormal``) draw ``samples`` points per grid cell.
"""

from __future__ import annotations

from typing import Any, Sequence

__all__ = ["values", "linspace", "logspace", "uniform", "normal", "lognormal"]


def values(pointer: str, items: Sequence[Any]) -> dict[str, Any]:
    """These values, as given (any JSON values)."""
    return {"pointer": pointer, "values": list(items)}


def linspace(pointer: str, start: float, stop: float, count: int) -> dict[str, Any]:
    """``count`` evenly spaced numbers, both ends included."""
    return {"pointer": pointer, "linspace": [start, stop, count]}


def logspace(pointer: str, start: float, stop: float, count: int) -> dict[str, Any]:
    """``count`` geometrically spaced numbers from ``start`` to ``stop`` (the values, not
    their exponents; both > 0)."""
    return {"pointer": pointer, "logspace": [start, stop, count]}


def uniform(pointer: str, low: float, high: float) -> dict[str, Any]:
    """Random, uniform on [low, high)."""
    return {"pointer": pointer, "uniform": [low, high]}


def normal(pointer: str, mean: float, std: float) -> dict[str, Any]:
    """Random, normal."""
    return {"pointer": pointer, "normal": {"mean": mean, "std": std}}


def lognormal(pointer: str, mean: float, std: float) -> dict[str, Any]:
    """Random, exp of a normal whose mean and std (of the natural log) are given."""
    return {"pointer": pointer, "lognormal": {"mean": mean, "std": std}}
