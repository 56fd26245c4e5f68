"""Histories as xarray objects, where their columns have dimensions: contact forces over
(time, contact), deflections over (time, pin, height[, direction]). xarray is optional
(``pip install chocmodal[xarray]``): it is imported only here, when asked for."""

from __future__ import annotations

import re
from typing import Any, Optional

import numpy as np
import pandas as pd

__all__ = ["history_to_xarray"]

_CONTACT = re.compile(r"^c(\d+)$")
# p3 (tip), p3@0.9 (at 0.9 m), p3x / p3y@0.9 (hexagonal bundle: along x or y)
_PIN = re.compile(r"^p(\d+)([xy]?)(?:@(.+))?$")


def _xarray() -> Any:
    try:
        import xarray
    except ImportError as error:  # pragma: no cover - exercised without the extra
        raise ImportError("to_xarray needs xarray: pip install 'chocmodal[xarray]'") from error
    return xarray


def history_to_xarray(
    frame: pd.DataFrame,
    *,
    contacts: Optional[pd.DataFrame] = None,
    pin_length: Optional[float] = None,
) -> Any:
    """A history DataFrame (from :meth:`Job.history`) as an ``xarray`` object.

    - ``c<k>`` columns: a DataArray over (``time``, ``contact``); with ``contacts`` (from
      :meth:`Job.contacts`), each contact's ``left``, ``right`` (as text: a pin number
      or ``wall``), ``height`` and ``gap`` become coordinates along ``contact``.
    - ``p<pin>[x|y][@<height>]`` columns: a DataArray over (``time``, ``pin``,
      ``height``) and ``direction`` when the columns name one; a column without
      ``@`` is the pin tip, at height ``pin_length`` (NaN when not given).
    - anything else: a Dataset over ``time`` with one variable per column.

    Units and descriptions go to each object's ``attrs``.
    """
    xr = _xarray()
    units: dict[str, str] = dict(frame.attrs.get("units") or {})
    descriptions: dict[str, str] = dict(frame.attrs.get("descriptions") or {})
    output = frame.attrs.get("output", frame.columns.name)
    time = xr.IndexVariable("time", frame.index.to_numpy(), attrs={"units": units.get("time", "s")})
    columns = [str(c) for c in frame.columns]

    matches = [_CONTACT.match(c) for c in columns]
    if columns and all(matches):
        indices = [int(m.group(1)) for m in matches if m]
        coords: dict[str, Any] = {"time": time, "contact": ("contact", indices)}
        if contacts is not None:
            picked = contacts.loc[indices]
            for name in ("left", "right"):
                if name in picked:
                    coords[name] = ("contact", picked[name].astype(str).to_numpy())
            for name in ("height", "gap"):
                if name in picked:
                    coords[name] = ("contact", picked[name].to_numpy(dtype=float), {"units": "m"})
        return xr.DataArray(
            frame.to_numpy(),
            dims=("time", "contact"),
            coords=coords,
            name=output,
            attrs={"units": _common(units, columns)},
        )

    pin_matches = [_PIN.match(c) for c in columns]
    if columns and all(pin_matches):
        keys = []
        for m in pin_matches:
            assert m is not None
            height = float(m.group(3)) if m.group(3) else (pin_length if pin_length is not None else np.nan)
            keys.append((int(m.group(1)), height, m.group(2)))
        pins = sorted({k[0] for k in keys})
        heights = sorted({k[1] for k in keys}, key=lambda h: (np.isnan(h), h))
        directions = sorted({k[2] for k in keys})
        shape = (len(frame.index), len(pins), len(heights), len(directions))
        data = np.full(shape, np.nan)
        for column, (pin, height, direction) in zip(columns, keys):
            h = next(i for i, value in enumerate(heights) if value == height or (np.isnan(value) and np.isnan(height)))
            data[:, pins.index(pin), h, directions.index(direction)] = frame[column].to_numpy()
        coords = {
            "time": time,
            "pin": ("pin", pins),
            "height": ("height", heights, {"units": "m"}),
        }
        dims: tuple[str, ...] = ("time", "pin", "height")
        if directions == [""]:
            data = data[..., 0]
        else:
            coords["direction"] = ("direction", directions)
            dims = dims + ("direction",)
        return xr.DataArray(data, dims=dims, coords=coords, name=output, attrs={"units": _common(units, columns)})

    dataset = frame.to_xarray()
    dataset["time"].attrs["units"] = units.get("time", "s")
    for column in columns:
        attrs = {}
        if column in units:
            attrs["units"] = units[column]
        if column in descriptions:
            attrs["description"] = descriptions[column]
        dataset[column].attrs.update(attrs)
    dataset.attrs["output"] = output
    return dataset


def _common(units: dict[str, str], columns: list[str]) -> str:
    found = {units[c] for c in columns if c in units}
    return found.pop() if len(found) == 1 else ""
