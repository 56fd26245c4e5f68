"""Stored accelerograms (``/signals``): uploads from NumPy arrays, pandas Series or files,
their metadata, samples and response spectra."""

from __future__ import annotations

import io
import math
import os
from typing import TYPE_CHECKING, Any, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import frames

if TYPE_CHECKING:  # pragma: no cover
    from .client import Client

__all__ = ["Signal", "upload_body"]

SignalSource = Union["np.ndarray[Any, Any]", Sequence[float], pd.Series, str, "os.PathLike[str]", io.IOBase]


class Signal:
    """One stored signal. ``metadata`` holds ``samples``, ``start``, ``duration``,
    ``sampling_interval``, ``sampling_rate``, ``uniform``, ``pga``, ``pga_time``,
    ``arias_intensity``, ``created``, ``labels``, ``note``. Refer to it from a job's
    inputs with :meth:`reference`."""

    def __init__(self, client: "Client", metadata: dict[str, Any], *, replayed: bool = False):
        self._client = client
        self.metadata = metadata
        self.id: str = metadata["id"]
        self.replayed = replayed

    def __repr__(self) -> str:
        m = self.metadata
        return f"<Signal {self.id} {m.get('samples')} samples, {m.get('duration')} s, PGA {m.get('pga')} m/s²>"

    def refresh(self) -> dict[str, Any]:
        """Reads the metadata again."""
        self.metadata = self._client._transport.get_json(f"/signals/{self.id}")
        return self.metadata

    def reference(self, scale: float = 1.0) -> dict[str, Any]:
        """The base acceleration that replays this record, ``{"type": "signal", "id", "scale"}``."""
        return {"type": "signal", "id": self.id, "scale": scale}

    def samples(self) -> pd.Series:
        """The record as a Series of accelerations (m/s²) indexed by ``time`` (s)."""
        response = self._client._transport.request(
            "GET", f"/signals/{self.id}/samples", params={"format": "csv"}, headers={"Accept": "text/csv"}
        )
        table = frames.table_frame(response.text)
        series = pd.Series(table["acceleration"].to_numpy(), index=pd.Index(table["time"].to_numpy(), name="time"), name="acceleration")
        series.attrs["units"] = {"time": "s", "acceleration": "m/s²"}
        series.attrs["signal"] = self.id
        return series

    def spectrum(
        self,
        damping: Union[float, Sequence[float]] = 0.05,
        *,
        f_min: Optional[float] = None,
        f_max: Optional[float] = None,
        points: Optional[int] = None,
    ) -> pd.DataFrame:
        """Pseudo-acceleration response spectrum PSA(f, ξ) = ω² max|u| (m/s²), indexed by
        ``frequency`` (Hz, log-spaced, 200 points from 0.1 to 100 Hz by default), one
        column per damping ratio (``psa_0.05``); ``attrs["pga"]`` is the record's PGA."""
        ratios = [damping] if isinstance(damping, (int, float)) else list(damping)
        params = {"damping": ratios, "f_min": f_min, "f_max": f_max, "points": points, "format": "json"}
        document = self._client._transport.get_json(f"/signals/{self.id}/spectrum", params=params)
        frame = frames.spectrum_frame(document["frequencies"], document["pseudo_acceleration"])
        frame.attrs["signal"] = self.id
        frame.attrs["pga"] = document.get("pga")
        return frame

    def delete(self) -> None:
        """Deletes the signal (409 ``signal-in-use`` while a queued or running job refers to it)."""
        self._client._transport.request("DELETE", f"/signals/{self.id}")


def upload_body(
    source: SignalSource,
    *,
    time_step: Optional[float] = None,
    time: Optional[Sequence[float]] = None,
    sampling_rate: Optional[float] = None,
) -> tuple[bytes, str, dict[str, Any]]:
    """The body, content type and query of ``POST /signals`` for a record given as

    - a NumPy array (or list) of accelerations (m/s²) with ``time_step`` (s),
      ``sampling_rate`` (Hz) or ``time`` (s, one per sample);
    - a pandas Series of accelerations indexed by time (s);
    - a file: a path or an open file of CSV ``time,acceleration`` (header optional),
      of one column with ``sampling_rate``, or of JSON (``.json``).
    """
    if isinstance(source, (str, os.PathLike)):
        path = os.fspath(source)
        with open(path, "rb") as handle:
            data = handle.read()
        return _file_body(data, path.lower().endswith(".json"), sampling_rate)
    if isinstance(source, io.IOBase):
        data = source.read()
        if isinstance(data, str):
            data = data.encode()
        name = str(getattr(source, "name", ""))
        return _file_body(data, name.lower().endswith(".json"), sampling_rate)
    if isinstance(source, pd.Series):
        if time is not None or time_step is not None or sampling_rate is not None:
            raise ValueError("a Series carries its times in its index: give no time, time_step or sampling_rate")
        return _json_body({"time": _finite(source.index.to_numpy(dtype=float), "time"), "acceleration": _finite(source.to_numpy(dtype=float), "acceleration")})
    acceleration = _finite(np.asarray(source, dtype=float), "acceleration")
    given = sum(x is not None for x in (time_step, time, sampling_rate))
    if given != 1:
        raise ValueError("give exactly one of time_step (s), sampling_rate (Hz) or time (s) with an array of accelerations")
    if time is not None:
        times = _finite(np.asarray(time, dtype=float), "time")
        if len(times) != len(acceleration):
            raise ValueError(f"time has {len(times)} values and acceleration {len(acceleration)}")
        return _json_body({"time": times, "acceleration": acceleration})
    if time_step is not None:
        if not (math.isfinite(time_step) and time_step > 0):
            raise ValueError(f"time_step must be a positive number of seconds, not {time_step}")
        sampling_rate = 1.0 / time_step
    return _json_body({"sampling_rate": float(sampling_rate), "acceleration": acceleration})  # type: ignore[arg-type]


def _finite(values: "np.ndarray[Any, Any]", name: str) -> list[float]:
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise ValueError(f"{name}[{bad[0]}] is {values[bad[0]]}: a record holds finite numbers only")
    return [float(v) for v in values]


def _json_body(document: dict[str, Any]) -> tuple[bytes, str, dict[str, Any]]:
    from ._http import dumps

    return dumps(document).encode(), "application/json", {}


def _file_body(data: bytes, is_json: bool, sampling_rate: Optional[float]) -> tuple[bytes, str, dict[str, Any]]:
    if is_json:
        if sampling_rate is not None:
            raise ValueError("a JSON record gives its sampling_rate as a member, not as an argument")
        return data, "application/json", {}
    return data, "text/csv", {"sampling_rate": sampling_rate}
