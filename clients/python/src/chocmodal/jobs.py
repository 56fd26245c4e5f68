"""A job of the service: its status, waiting with a progress bar, its results as Python
objects and pandas DataFrames, and dismissal."""

from __future__ import annotations

import os
import time
import warnings
from typing import TYPE_CHECKING, Any, Optional, Sequence, Union

import pandas as pd

from . import frames
from .errors import ChocmodalError, QualityWarning, TruncatedTableWarning
from .progress import Poller, progress_bar

if TYPE_CHECKING:  # pragma: no cover
    from .client import Client

__all__ = ["Job", "ENDED"]

#: Job statuses after which nothing changes any more.
ENDED = frozenset({"successful", "failed", "dismissed"})


class Job:
    """One job (``/jobs/{jobId}``). Made by :meth:`Client.submit` or :meth:`Client.job`."""

    def __init__(self, client: "Client", job_id: str, status: Optional[dict[str, Any]] = None, *, replayed: bool = False):
        self._client = client
        self.id = job_id
        #: True when the submission was answered with an earlier one's job
        #: (``Idempotent-Replayed: true``: the same ``Idempotency-Key`` and inputs).
        self.replayed = replayed
        #: The ``Idempotency-Key`` the submission was sent with (``None`` for a job
        #: looked up by id): submit again with it to get this job back.
        self.idempotency_key: Optional[str] = None
        self._status = status
        self._etag: Optional[str] = None
        self._results: Optional[dict[str, Any]] = None

    def __repr__(self) -> str:
        state = self._status.get("status") if self._status else "?"
        return f"<Job {self.id} {self.process_id or ''} {state}>"

    @property
    def process_id(self) -> Optional[str]:
        return self._status.get("processID") if self._status else None

    @property
    def warnings(self) -> list[dict[str, Any]]:
        """Plausibility warnings (``code``, ``pointer``, ``message``) of the last status read."""
        return list((self._status or {}).get("warnings") or [])

    # -- status -------------------------------------------------------------------

    def status(self) -> dict[str, Any]:
        """The statusInfo document (``status``, ``progress`` 0–100, ``message``, times...),
        read with ``If-None-Match`` so an unchanged status costs an empty 304."""
        self._poll()
        assert self._status is not None
        return dict(self._status)

    def _poll(self) -> Optional[float]:
        """Refreshes the status; returns the server's ``Retry-After`` (s) if it sent one."""
        headers = {"Accept": "application/json"}
        if self._etag and self._status is not None:
            headers["If-None-Match"] = self._etag
        response = self._client._transport.request("GET", f"/jobs/{self.id}", headers=headers)
        if response.status_code != 304:
            self._status = response.json()
            self._etag = response.headers.get("ETag")
        from ._http import retry_after_seconds

        return retry_after_seconds(response.headers.get("Retry-After"))

    def wait(
        self,
        *,
        timeout: Optional[float] = None,
        progress: bool = True,
        poll_interval: Optional[float] = None,
        warn_quality: bool = True,
    ) -> dict[str, Any]:
        """Waits until the job ends and returns its results document.

        Shows a tqdm progress bar (0–100 %) unless ``progress`` is false. Polls quickly
        at first, then at the pace the server asks (``Retry-After``), or every
        ``poll_interval`` seconds when given. A successful job whose ``quality.verdict``
        is not ``good`` issues a :class:`QualityWarning` (unless ``warn_quality`` is
        false); a failed or dismissed job raises :class:`ChocmodalError` with the
        server's problem (``job-failed``, ``job-dismissed``, ...). ``timeout`` (s):
        :class:`TimeoutError` if the job has not ended by then (it keeps running).
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        poller = Poller(poll_interval)
        with progress_bar(progress, total=100, desc=f"job {self.id[:8]}", unit="%") as bar:
            while True:
                retry_after = self._poll()
                assert self._status is not None
                state = self._status.get("status", "")
                bar.show(float(self._status.get("progress") or 0), state)
                if state in ENDED:
                    break
                delay = poller.next_delay(retry_after)
                if deadline is not None and time.monotonic() + delay > deadline:
                    raise TimeoutError(
                        f"job {self.id} is still {state} ({self._status.get('progress')} %) after {timeout} s"
                    )
                time.sleep(delay)
        results = self.results()
        if warn_quality:
            self._warn_quality(results)
        return results

    def _warn_quality(self, results: dict[str, Any]) -> None:
        quality = results.get("quality")
        if not isinstance(quality, dict):
            return
        verdict = quality.get("verdict")
        if verdict is not None and verdict != "good":
            warnings.warn(QualityWarning.of(self.id, str(verdict), list(quality.get("reasons") or [])), stacklevel=3)

    def dismiss(self) -> dict[str, Any]:
        """Dismisses the job (``DELETE``): a queued job never runs, a running one stops
        within a second, a finished one loses its results. Returns the new status."""
        response = self._client._transport.request("DELETE", f"/jobs/{self.id}", headers={"Accept": "application/json"})
        if response.content:
            self._status = response.json()
            self._etag = None
        self._results = None
        return dict(self._status or {})

    # -- results ------------------------------------------------------------------

    def results(self) -> dict[str, Any]:
        """The results document as Python objects (kept once read: it never changes).
        Not finished: :class:`ChocmodalError` ``result-not-ready``; failed: the job's
        problem (``job-failed``...); dismissed: ``job-dismissed``."""
        if self._results is None:
            self._results = self._client._transport.get_json(f"/jobs/{self.id}/results")
        return self._results

    def inputs(self) -> dict[str, Any]:
        """The inputs the job was submitted with (``GET /jobs/{jobId}/inputs``)."""
        return dict(self._client._transport.get_json(f"/jobs/{self.id}/inputs")["inputs"])

    @property
    def quality(self) -> dict[str, Any]:
        """The results' ``quality`` section (``verdict``, ``reasons``, measures)."""
        return dict(self.results().get("quality") or {})

    def outputs(self) -> list[str]:
        """Names of the job's outputs (histories, their ``_peaks`` envelopes, tables)."""
        return list((self.results().get("outputs") or {}).keys())

    def _output_kind(self, output: str) -> Optional[str]:
        process = self.process_id or self.status().get("processID")
        if process is None:
            return None
        described = self._client._process_outputs(process).get(output) or {}
        return described.get("kind")

    def history(
        self,
        output: str,
        *,
        t_start: Optional[float] = None,
        t_end: Optional[float] = None,
        max_points: Optional[int] = None,
        series: Union[str, list[str], None] = None,
    ) -> pd.DataFrame:
        """One history as a DataFrame indexed by ``time`` (s), a column per series
        (``c0, c1, ...``, ``p0, ...``, ``numerical, reference``), units in
        ``attrs["units"]`` and what each column measures in ``attrs["descriptions"]``.

        Read from the CSV form. ``t_start``/``t_end`` (s) cut a window, ``series``
        picks columns, ``max_points`` thins with min/max buckets that keep the peaks.
        The service thins any window longer than its ``--max-history-points`` (500 000
        rows by default): page with ``t_start``/``t_end`` for full resolution."""
        params = {
            "format": "csv",
            "header": "long",
            "t_start": t_start,
            "t_end": t_end,
            "max_points": max_points,
            "series": series,
        }
        response = self._client._transport.request(
            "GET", f"/jobs/{self.id}/results/{output}", params=params, headers={"Accept": "text/csv"}
        )
        return frames.history_frame(response.text, output=output, job_id=self.id)

    def response_spectrum(
        self,
        output: str,
        *,
        series: Optional[str] = None,
        damping: Union[float, Sequence[float], None] = None,
        f_min: Optional[float] = None,
        f_max: Optional[float] = None,
        points: Optional[int] = None,
    ) -> pd.DataFrame:
        """Pseudo-acceleration response spectrum PSA(f, ξ) (m/s²) of one column of a
        displacement history (``displacements``: the point's motion, relative to the pin
        feet) or of the ``excitation`` (the accelerations the run was given), indexed by
        ``frequency`` (Hz), one column per damping ratio (``psa_0.05``).

        Of a synthetic earthquake's column the defaults are its target's damping and
        band, and the frame gains ``target`` (the target spectrum, NaN outside its band)
        with ``attrs["max_deviation"]``, ``attrs["deviation_frequency"]`` and
        ``attrs["tolerance"]``: the stored record's spectrum against its target, computed
        apart from the generator. ``attrs["peak_acceleration"]`` is the largest |a|."""
        ratios = None if damping is None else ([damping] if isinstance(damping, (int, float)) else list(damping))
        params = {"series": series, "damping": ratios, "f_min": f_min, "f_max": f_max, "points": points, "format": "json"}
        document = self._client._transport.get_json(f"/jobs/{self.id}/results/{output}/response_spectrum", params=params)
        frame = frames.spectrum_frame(document["frequencies"], document["pseudo_acceleration"])
        frame.attrs["job"] = self.id
        frame.attrs["output"] = document.get("output", output)
        frame.attrs["series"] = document.get("series")
        frame.attrs["peak_acceleration"] = document.get("peak_acceleration")
        target = document.get("target")
        if target is not None:
            frame["target"] = [float("nan") if value is None else float(value) for value in target["pseudo_acceleration"]]
            frame.attrs["units"]["target"] = "m/s²"
            for key in ("max_deviation", "deviation_frequency", "tolerance"):
                frame.attrs[key] = target.get(key)
        return frame

    def histories(self, *, peaks: bool = True) -> dict[str, pd.DataFrame]:
        """Every history of the job (tables aside) by output name; without the
        ``_peaks`` envelopes when ``peaks`` is false."""
        out: dict[str, pd.DataFrame] = {}
        for name in self.outputs():
            kind = self._output_kind(name)
            if kind == "table" or (kind is None and name == "impacts"):
                continue
            if not peaks and (kind == "peaks" or name.endswith("_peaks")):
                continue
            out[name] = self.history(name)
        return out

    def impacts(self, *, contact: Union[int, list[int], None] = None, page_size: int = 100_000) -> pd.DataFrame:
        """The per-impact table (``/jobs/{jobId}/results/impacts``), one row per impact
        sorted by start time: ``contact, start, peak_time, peak_force, impulse,
        duration, approach_velocity, rebounds, dissipated, energy``. Every page is
        read (``total_rows``, ``next``); ``contact`` filters.

        ``attrs`` holds ``truncated``, the run's ``impacts`` and the whole table's
        ``tabulated`` rows. A truncated table (past ``output.impacts.max_rows``) holds
        the largest impacts by peak force, each contact's fair share first: reading one
        issues a :class:`TruncatedTableWarning`."""
        rows: list[dict[str, Any]] = []
        params: dict[str, Any] = {"format": "json", "limit": page_size, "offset": 0, "contact": contact}
        if isinstance(contact, int):
            params["contact"] = str(contact)
        elif isinstance(contact, list):
            params["contact"] = ",".join(str(c) for c in contact)
        while True:
            page = self._client._transport.get_json(f"/jobs/{self.id}/results/impacts", params=params)
            rows.extend(page.get("rows") or [])
            if not page.get("next") or not page.get("rows"):
                break
            params["offset"] = int(page.get("offset", 0)) + len(page["rows"])
        frame = frames.impacts_frame(rows)
        frame.attrs["job"] = self.id
        truncated = bool(page.get("truncated", False))
        frame.attrs["truncated"] = truncated
        frame.attrs["impacts"] = int(page.get("impacts", len(rows)))
        frame.attrs["tabulated"] = int(page.get("tabulated", len(rows)))
        if truncated:
            impacts, tabulated = frame.attrs["impacts"], frame.attrs["tabulated"]
            warnings.warn(
                TruncatedTableWarning(
                    f"job {self.id}: the impact table holds {tabulated} of {impacts} impacts, "
                    "the largest by peak force (each contact's fair share first)",
                    job_id=self.id,
                    impacts=impacts,
                    tabulated=tabulated,
                ),
                stacklevel=2,
            )
        return frame

    def contacts(self) -> pd.DataFrame:
        """The per-contact statistics table the service serves
        (``/jobs/{jobId}/results/contacts``, read as CSV with ``pd.read_csv``), indexed by
        contact k (history column ``c<k>``): ``left``, ``right``, ``height``, ``gap``,
        ``max_force``, ``max_force_time``, ``impacts``, ``contact_time``, ``impulse``,
        ``impact_statistics.*``... The same table as ``chocmodal run --out``'s
        ``contacts.csv``. A process without contacts raises :class:`ChocmodalError` (404)."""
        response = self._client._transport.request(
            "GET", f"/jobs/{self.id}/results/contacts", params={"format": "csv"}, headers={"Accept": "text/csv"}
        )
        frame = frames.contact_table_frame(response.text)
        frame.attrs["job"] = self.id
        return frame

    def report(self, path: Union[str, "os.PathLike[str]", None] = None) -> str:
        """The job's calculation note (``/jobs/{jobId}/report``, docs/report.md): one
        printable HTML page with the inputs, the verdict and its reasons, the peaks and
        margins, the worst contacts and pins, the bending envelope and the key plots.
        Written to ``path`` when given; the HTML is returned either way. A job without
        results raises :class:`ChocmodalError` (404)."""
        response = self._client._transport.request("GET", f"/jobs/{self.id}/report", headers={"Accept": "text/html"})
        if path is not None:
            with open(path, "w", encoding="utf-8") as out:
                out.write(response.text)
        return response.text

    def url(self, path: str = "") -> str:
        """The absolute URL of this job's resource ``path`` (``/results/contacts?format=csv``):
        ``pd.read_csv(job.url("/results/contacts?format=csv"))`` reads a table directly
        (add ``storage_options={"Authorization": "Bearer ..."}`` on a service with tokens)."""
        return self._client._transport.url(f"/jobs/{self.id}{path}")

    @property
    def labels(self) -> list[str]:
        """The labels the job was submitted with (last status read)."""
        return list((self._status or {}).get("labels") or [])

    @property
    def note(self) -> Optional[str]:
        """The note the job was submitted with (last status read)."""
        return (self._status or {}).get("note")

    @property
    def verdict(self) -> Optional[str]:
        """``quality.verdict`` of a successful job (last status read): ``good``,
        ``doubtful``, ``poor``; ``None`` before it succeeds."""
        return (self._status or {}).get("verdict")

    def provenance(self) -> dict[str, Any]:
        """Where the results come from: ``solver``, ``solver_version``, ``build`` (git
        commit, or ``None``) and ``inputs_sha256`` (SHA-256 of the canonical JSON of the
        inputs, RFC 8785: equal for equivalent submissions)."""
        return dict(self.results().get("provenance") or {})

    def pins(self) -> pd.DataFrame:
        """The per-pin extremes of the results (``pins``), indexed by pin."""
        pins = self.results().get("pins")
        if pins is None:
            raise KeyError(f"job {self.id}: its results have no per-pin extremes (`pins`)")
        frame = frames.pins_frame(pins)
        frame.attrs["job"] = self.id
        return frame

    def resultants(self) -> pd.DataFrame:
        """The resultant contact force on every pin at every contact height where a
        contact acts on it (``/jobs/{jobId}/results/resultants``, docs/bending.md), indexed
        by (``pin``, ``height``): ``contacts`` (how many act there), ``max_force`` (N: the
        largest magnitude of their vector sum over every step), ``time`` (s). A process
        without pins raises :class:`ChocmodalError` (404)."""
        response = self._client._transport.request(
            "GET", f"/jobs/{self.id}/results/resultants", params={"format": "csv"}, headers={"Accept": "text/csv"}
        )
        frame = frames.resultant_table_frame(response.text)
        frame.attrs["job"] = self.id
        return frame

    def bending(self) -> pd.DataFrame:
        """The bending envelope along the height (``bending_envelope``: per mesh node the
        largest bending moment (N·m), outer-fibre stress (Pa) and strain over every pin and
        output sample, with the ``pin`` and the ``time``), indexed by ``height`` (m); NaN
        stresses and strains for an explicit section without a diameter. The run's worst
        is ``results()["max_bending"]`` (``["numerical"]`` for ``cantilever-impact``)."""
        results = self.results()
        envelope = results.get("bending_envelope", (results.get("numerical") or {}).get("bending_envelope"))
        if envelope is None:
            raise KeyError(f"job {self.id}: its results have no bending envelope")
        frame = frames.bending_frame(envelope)
        frame.attrs["job"] = self.id
        return frame

    def to_xarray(self, output: str, **history_options: Any) -> Any:
        """A history as xarray: contact forces as a DataArray over (time, contact), with
        each contact's ``left``, ``right``, ``height``, ``gap`` as coordinates;
        deflections over (time, pin, height) (plus ``direction`` x/y for a hexagonal
        bundle); any other history as a Dataset over time. Needs ``xarray``
        (``pip install chocmodal[xarray]``)."""
        from ._xarray import history_to_xarray

        frame = self.history(output, **history_options)
        contacts = None
        pin_length = None
        results = self.results()
        if results.get("contacts") is not None:
            contacts = self.contacts()
        if any(str(c).startswith("p") for c in frame.columns):
            try:
                pin_length = float(self.inputs()["pin"]["length"])
            except (KeyError, TypeError, ValueError, ChocmodalError):
                pin_length = None
        return history_to_xarray(frame, contacts=contacts, pin_length=pin_length)
