"""A sweep of the service (``/sweeps/{sweepId}``): many runs of one process over axes of
its inputs, followed with a progress bar, its results table and aggregates as
DataFrames."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Optional

import pandas as pd

from . import frames
from .jobs import Job
from .progress import Poller, progress_bar

if TYPE_CHECKING:  # pragma: no cover
    from .client import Client

__all__ = ["Sweep", "SWEEP_ENDED"]

#: Sweep statuses after which nothing changes any more.
SWEEP_ENDED = frozenset({"successful", "partial", "failed", "dismissed"})

_STATISTICS = ["count", "mean", "std", "min", "max", "q05", "q50", "q95", "bound_95_95", "bound_95_95_rank"]
_VERDICTS = ["runs", "good", "unchecked", "doubtful", "poor"]


class Sweep:
    """One sweep. Made by :meth:`Client.submit_sweep` or :meth:`Client.sweep`."""

    def __init__(self, client: "Client", sweep_id: str, status: Optional[dict[str, Any]] = None, *, replayed: bool = False):
        self._client = client
        self.id = sweep_id
        self.replayed = replayed
        self._status = status
        self._etag: Optional[str] = None

    def __repr__(self) -> str:
        state = self._status.get("status") if self._status else "?"
        runs = self._status.get("runs") if self._status else "?"
        return f"<Sweep {self.id} {runs} runs {state}>"

    @property
    def runs(self) -> int:
        return int((self._status or self.status()).get("runs", 0))

    def status(self) -> dict[str, Any]:
        """The sweep's status: ``status``, ``runs``, ``counts`` per job status,
        ``progress``, ``definition``..."""
        self._poll()
        assert self._status is not None
        return dict(self._status)

    def _poll(self) -> Optional[float]:
        headers = {"Accept": "application/json"}
        if self._etag and self._status is not None:
            headers["If-None-Match"] = self._etag
        response = self._client._transport.request("GET", f"/sweeps/{self.id}", headers=headers)
        if response.status_code != 304:
            self._status = response.json()
            self._etag = response.headers.get("ETag")
        from ._http import retry_after_seconds

        return retry_after_seconds(response.headers.get("Retry-After"))

    def follow(
        self,
        *,
        timeout: Optional[float] = None,
        progress: bool = True,
        poll_interval: Optional[float] = None,
    ) -> dict[str, Any]:
        """Waits until every run ended, with a progress bar of ended runs; returns the
        final status (``successful``, ``partial``, ``failed`` or ``dismissed``).
        ``timeout`` (s): :class:`TimeoutError` if runs are still pending then."""
        deadline = None if timeout is None else time.monotonic() + timeout
        poller = Poller(poll_interval)
        with progress_bar(progress, total=self.runs, desc=f"sweep {self.id[:8]}", unit="run") as bar:
            while True:
                retry_after = self._poll()
                assert self._status is not None
                counts = self._status.get("counts") or {}
                ended = sum(int(counts.get(k, 0)) for k in ("successful", "failed", "dismissed"))
                state = str(self._status.get("status", ""))
                failed = int(counts.get("failed", 0))
                bar.show(ended, state if not failed else f"{state}, {failed} failed", total=self._status.get("runs"))
                if state in SWEEP_ENDED:
                    return dict(self._status)
                delay = poller.next_delay(retry_after)
                if deadline is not None and time.monotonic() + delay > deadline:
                    raise TimeoutError(f"sweep {self.id} is still {state} ({ended} of {self.runs} runs ended) after {timeout} s")
                time.sleep(delay)

    def dismiss(self) -> dict[str, Any]:
        """Dismisses the runs not ended yet; ended runs keep their results."""
        response = self._client._transport.request("DELETE", f"/sweeps/{self.id}", headers={"Accept": "application/json"})
        self._status = response.json()
        self._etag = None
        return dict(self._status)

    def results(self) -> pd.DataFrame:
        """One row per ended run, indexed by ``run``: ``job``, ``status``, one column per
        axis (named by its pointer, ``/contact/rk``), then the run's scalar results
        flattened with dots (``comparison.f_err``, ``contacts.3.max_force``,
        ``quality.verdict``...). From the CSV form; empty cells are missing values."""
        response = self._client._transport.request(
            "GET", f"/sweeps/{self.id}/results", params={"format": "csv"}, headers={"Accept": "text/csv"}
        )
        frame = frames.table_frame(response.text, index="run")
        frame.attrs["sweep"] = self.id
        return frame

    def results_document(self) -> dict[str, Any]:
        """The JSON results: ``columns``, ``rows`` and ``aggregates``."""
        return dict(self._client._transport.get_json(f"/sweeps/{self.id}/results", params={"format": "json"}))

    def aggregates(self) -> dict[str, Any]:
        """``aggregates`` of the results: ``statistics`` (random designs), ``calibration``
        (grids reporting f_err), ``quality`` (verdict counts)."""
        return dict(self.results_document().get("aggregates") or {})

    def statistics(self) -> pd.DataFrame:
        """Statistics over the successful runs of every numeric metric (random designs):
        one row per (grid cell of the list axes, metric), columns ``count, mean, std,
        min, max, q05, q50, q95, bound_95_95, bound_95_95_rank`` (the Wilks 95 %/95 % upper
        bound and its rank from the top, NaN below 59 runs). The cell's axis values are index levels before
        ``metric``."""
        cells = self.aggregates().get("statistics") or []
        records: list[dict[str, Any]] = []
        axis_names: list[str] = []
        for cell in cells:
            values = cell.get("cell") or {}
            for axis in values:
                if axis not in axis_names:
                    axis_names.append(axis)
            for metric, stats in (cell.get("metrics") or {}).items():
                records.append({**values, "metric": metric, **{k: stats.get(k) for k in _STATISTICS}})
        frame = pd.DataFrame(records, columns=[*axis_names, "metric", *_STATISTICS])
        return frame.set_index([*axis_names, "metric"])

    def _statistics_table(self, path: str, params: dict[str, Any], index: list[str]) -> pd.DataFrame:
        """A long statistics table of the sweep (``/sweeps/{id}/statistics...``) from its
        CSV form, indexed by the columns of ``index`` it has (the list axes first)."""
        response = self._client._transport.request(
            "GET", f"/sweeps/{self.id}/{path}", params={**params, "format": "csv"}, headers={"Accept": "text/csv"}
        )
        frame = frames.table_frame(response.text)
        axes = [c for c in frame.columns if c.startswith("/")]
        keys = [*axes, *[c for c in index if c in frame.columns]]
        frame = pd.DataFrame(frame.set_index(keys)) if keys else frame
        frame.attrs["sweep"] = self.id
        return frame

    def figure_statistics(self, *, coverage: float = 0.95, confidence: float = 0.95) -> pd.DataFrame:
        """The run-wide statistics at a chosen bound: one row per (grid cell of the list
        axes, ``figure``: a numeric column of the results table), columns ``runs, count,
        mean, std, min, max, q05, q50, q95, quantile`` (the empirical ``coverage``
        quantile), ``bound, bound_rank`` (the one-sided ``coverage``/``confidence`` upper
        bound of Wilks and its rank from the top, NaN with too few runs) and
        ``runs_needed`` (the fewest runs for that rank, rank 1 while there is none)."""
        return self._statistics_table(
            "statistics", {"coverage": coverage, "confidence": confidence}, ["figure"]
        )

    def contact_statistics(
        self, figures: Optional[list[str]] = None, *, coverage: float = 0.95, confidence: float = 0.95
    ) -> pd.DataFrame:
        """Each contact's statistics over the runs (bundle processes): as
        :meth:`figure_statistics`, one row per (cell, ``contact``, ``figure``), the
        figures the numeric members of each contact's entry (``max_force``, ``impacts``,
        ``utilisation``...), only ``figures`` when given."""
        params: dict[str, Any] = {"coverage": coverage, "confidence": confidence}
        if figures:
            params["figure"] = list(figures)
        return self._statistics_table("statistics/contacts", params, ["contact", "figure"])

    def pin_statistics(
        self, figures: Optional[list[str]] = None, *, coverage: float = 0.95, confidence: float = 0.95
    ) -> pd.DataFrame:
        """Each pin's statistics over the runs: as :meth:`contact_statistics`, for the
        pins (``max_abs_deflection``, ``bending.stress``, ``utilisation``...)."""
        params: dict[str, Any] = {"coverage": coverage, "confidence": confidence}
        if figures:
            params["figure"] = list(figures)
        return self._statistics_table("statistics/pins", params, ["pin", "figure"])

    def convergence(self, figure: str, *, coverage: float = 0.95, confidence: float = 0.95) -> pd.DataFrame:
        """How ``figure`` (a numeric column of the results table) converges as runs are
        added, in the order they were drawn: one row per (cell, ``sample``) with the
        ``run``, its ``value``, and over the first ``runs`` values the empirical
        ``quantile`` and the Wilks ``bound`` with its ``bound_rank`` (NaN until enough
        runs)."""
        return self._statistics_table(
            "statistics/convergence",
            {"figure": figure, "coverage": coverage, "confidence": confidence},
            ["sample"],
        )

    def quality_counts(self) -> pd.DataFrame:
        """Successful runs per quality verdict: a row ``("all", "")`` for the total, then
        one per (axis, value) of each list axis."""
        quality = self.aggregates().get("quality")
        if not quality:
            return pd.DataFrame(columns=["axis", "value", *_VERDICTS]).set_index(["axis", "value"])
        records = [{"axis": "all", "value": "", **{k: quality.get(k, 0) for k in _VERDICTS}}]
        for axis in quality.get("by_axis") or []:
            for entry in axis.get("values") or []:
                records.append({"axis": axis["axis"], "value": entry.get("value"), **{k: entry.get(k, 0) for k in _VERDICTS}})
        return pd.DataFrame(records).set_index(["axis", "value"])

    def calibration(self) -> pd.DataFrame:
        """The calibration map of a grid reporting f_err: one row per run with its axis
        values, ``f_err`` and ``valid`` (f_err below the threshold, and the run succeeded)."""
        calibration = self.aggregates().get("calibration") or {}
        records = [
            {"run": cell.get("run"), **(cell.get("parameters") or {}), "f_err": cell.get("f_err"), "valid": cell.get("valid")}
            for cell in calibration.get("cells") or []
        ]
        frame = pd.DataFrame(records)
        if "run" in frame:
            frame = frame.set_index("run")
        frame.attrs["threshold"] = calibration.get("threshold")
        return frame

    def cheapest(self) -> pd.DataFrame:
        """For each axis the map ranks (``/solver/time_step``, ``/beam/modes``...), and each
        combination of the other axes, the cheapest valid value and its run."""
        calibration = self.aggregates().get("calibration") or {}
        records = []
        for entry in calibration.get("cheapest") or []:
            for choice in entry.get("choices") or []:
                records.append(
                    {"axis": entry.get("axis"), **(choice.get("given") or {}), "value": choice.get("value"), "run": choice.get("run")}
                )
        return pd.DataFrame(records)

    def jobs(self) -> list[Job]:
        """The sweep's runs as jobs (``/jobs?sweepID=...``), every page."""
        return self._client.jobs(sweep=self.id, limit=None)
