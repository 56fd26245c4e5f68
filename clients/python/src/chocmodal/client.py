"""The entry point: :class:`Client`, one HTTP session to a chocmodal service."""

from __future__ import annotations

import json
import uuid
from typing import Any, Iterator, Mapping, Optional, Sequence, Union

import httpx

from ._http import Repeated, RetryPolicy, Transport
from .jobs import Job
from .signals import Signal, SignalSource, upload_body
from .sweeps import Sweep

__all__ = ["Client"]

IDEMPOTENCY_HEADER = "Idempotency-Key"
REPLAYED_HEADER = "Idempotent-Replayed"


class Client:
    """A chocmodal service at ``url`` (``http://127.0.0.1:8080``).

    ``token``: the tenant's bearer token when the service has an auth file. One
    ``httpx.Client`` is shared by every call (``close()`` it, or use ``with``).
    ``retry`` says how requests are retried on 503/507/429 answers and lost
    connections (:class:`RetryPolicy`); ``timeout`` is per request (s).

    >>> with Client("http://127.0.0.1:8080") as client:          # doctest: +SKIP
    ...     job = client.submit("cantilever-impact", inputs)
    ...     results = job.wait()
    ...     tip = job.history("tip_displacement")
    """

    def __init__(
        self,
        url: str,
        token: Optional[str] = None,
        *,
        timeout: float = 60.0,
        retry: Optional[RetryPolicy] = None,
        http_client: Optional[httpx.Client] = None,
    ):
        self.url = url.rstrip("/")
        self._transport = Transport(
            self.url, token=token, timeout=timeout, retry=retry or RetryPolicy(), http_client=http_client
        )
        self._descriptions: dict[str, dict[str, Any]] = {}

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._transport.close()

    def __repr__(self) -> str:
        return f"<chocmodal.Client {self.url}>"

    # -- service ------------------------------------------------------------------

    def health(self) -> dict[str, Any]:
        """``GET /healthz``: ``{"status": "ok", "writable": ...}``."""
        return dict(self._transport.get_json("/healthz"))

    # -- processes ----------------------------------------------------------------

    def processes(self) -> list[dict[str, Any]]:
        """The processes the service runs: ``id``, ``title``, ``description``, ``version``,
        ``jobControlOptions``, ``links``."""
        return list(self._transport.get_json("/processes")["processes"])

    def process(self, process_id: str) -> dict[str, Any]:
        """A process's description: the summary plus ``inputs`` (JSON Schema of each
        input, SI units in the descriptions, defaults and bounds) and ``outputs`` (each
        with its ``kind``: ``force``, ``displacement``, ``peaks``, ``table``)."""
        description = dict(self._transport.get_json(f"/processes/{process_id}"))
        self._descriptions[process_id] = description
        return description

    def _process_outputs(self, process_id: str) -> dict[str, Any]:
        if process_id not in self._descriptions:
            self.process(process_id)
        return dict(self._descriptions[process_id].get("outputs") or {})

    # -- jobs ---------------------------------------------------------------------

    def submit(
        self,
        process: str,
        inputs: Mapping[str, Any],
        *,
        idempotency_key: Optional[str] = None,
        subscriber: Optional[Mapping[str, str]] = None,
        labels: Optional[Sequence[str]] = None,
        note: Optional[str] = None,
    ) -> Job:
        """Validates and queues a run of ``process`` with ``inputs`` (the members of the
        execution request's ``inputs``, not the ``{"inputs": ...}`` wrapper). Returns
        its :class:`Job`; refused inputs raise :class:`ChocmodalError` (422, one
        ``errors`` entry per field with its JSON pointer).

        The request carries an ``Idempotency-Key`` (a new UUID, or ``idempotency_key``)
        that every retry repeats: a submission whose answer was lost and is sent again
        gets the same job back (``job.replayed`` is then true), never a second one.

        ``subscriber`` asks for job callbacks (OGC API – Processes): any of
        ``successUri``, ``failedUri``, ``inProgressUri``, absolute http(s) URIs the
        service POSTs the job's status document to, signed (``Chocmodal-Signature``,
        see :func:`chocmodal.verify_signature`). The service's operator must allow their
        hosts (``--callback-allow``): others are refused with a 422 at
        ``/subscriber/successUri`` (...).

        ``labels`` (at most 20 texts of 1 to 64 characters) and ``note`` (at most 2000
        characters) are stored with the job and returned in its status; find the jobs
        with a label by ``client.jobs(label=...)``. Bad ones are refused with a 422 at
        ``/labels/k`` or ``/note``.
        """
        key = idempotency_key or str(uuid.uuid4())
        body: dict[str, Any] = {"inputs": dict(inputs)}
        if subscriber is not None:
            body["subscriber"] = dict(subscriber)
        if labels is not None:
            body["labels"] = list(labels)
        if note is not None:
            body["note"] = note
        response = self._transport.request(
            "POST",
            f"/processes/{process}/execution",
            json_body=body,
            headers={IDEMPOTENCY_HEADER: key, "Accept": "application/json"},
        )
        status = response.json()
        job = Job(self, status["jobID"], status, replayed=_replayed(response))
        job.idempotency_key = key
        return job

    def job(self, job_id: str) -> Job:
        """An existing job by id (its status read now: an unknown id raises 404)."""
        job = Job(self, job_id)
        job.status()
        return job

    def jobs(
        self,
        *,
        status: Union[str, Sequence[str], None] = None,
        process: Union[str, Sequence[str], None] = None,
        sweep: Union[str, Sequence[str], None] = None,
        in_sweep: Optional[bool] = None,
        label: Union[str, Sequence[str], None] = None,
        limit: Optional[int] = 100,
    ) -> list[Job]:
        """Jobs newest first, filtered by ``status``, ``process``, ``sweep`` (runs of these
        sweeps), ``in_sweep`` and ``label`` (jobs that have every label given); at most
        ``limit`` of them (``None``: every page)."""
        labels = [label] if isinstance(label, str) else list(label or [])
        params = {"status": status, "processID": process, "sweepID": sweep, "inSweep": in_sweep, "label": Repeated(labels) if labels else None}
        return [Job(self, s["jobID"], s) for s in self._pages("/jobs", "jobs", params, limit)]

    # -- sweeps -------------------------------------------------------------------

    def submit_sweep(
        self,
        process: str,
        inputs: Mapping[str, Any],
        axes: Sequence[Mapping[str, Any]],
        *,
        design: Optional[str] = None,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
        policy: Optional[str] = None,
        invalid_runs: Optional[str] = None,
        idempotency_key: Optional[str] = None,
        labels: Optional[Sequence[str]] = None,
        note: Optional[str] = None,
    ) -> Sweep:
        """Queues a sweep: ``process`` run with ``inputs`` over ``axes`` (see
        :mod:`chocmodal.axes`). ``design`` (``grid``, ``monte_carlo``,
        ``latin_hypercube``), ``samples`` (draws per grid cell, with random axes),
        ``seed``, ``policy`` (``continue`` or ``fail_fast``), ``invalid_runs``
        (``refuse`` or ``record``): left out, the service's defaults apply. ``labels``
        and ``note`` are the sweep's (``client.sweeps(label=...)``)."""
        request: dict[str, Any] = {"process": process, "inputs": dict(inputs), "axes": [dict(a) for a in axes]}
        options = {
            "design": design, "samples": samples, "seed": seed, "policy": policy, "invalid_runs": invalid_runs,
            "labels": list(labels) if labels is not None else None, "note": note,
        }
        request.update({k: v for k, v in options.items() if v is not None})
        return self.submit_sweep_request(request, idempotency_key=idempotency_key)

    def submit_sweep_request(self, request: Mapping[str, Any], *, idempotency_key: Optional[str] = None) -> Sweep:
        """Queues a sweep from a whole ``POST /sweeps`` document (``process``, ``inputs``,
        ``axes``, ...), e.g. ``examples/sweep-gaps.json``."""
        response = self._transport.request(
            "POST",
            "/sweeps",
            json_body=dict(request),
            headers={IDEMPOTENCY_HEADER: idempotency_key or str(uuid.uuid4()), "Accept": "application/json"},
        )
        status = response.json()
        return Sweep(self, status["sweepID"], status, replayed=_replayed(response))

    def sweep(self, sweep_id: str) -> Sweep:
        """An existing sweep by id."""
        sweep = Sweep(self, sweep_id)
        sweep.status()
        return sweep

    def sweeps(self, *, label: Union[str, Sequence[str], None] = None, limit: Optional[int] = 100) -> list[Sweep]:
        """Sweeps newest first, those with every ``label`` given, at most ``limit``
        (``None``: every page)."""
        labels = [label] if isinstance(label, str) else list(label or [])
        params = {"label": Repeated(labels) if labels else None}
        return [Sweep(self, s["sweepID"], s) for s in self._pages("/sweeps", "sweeps", params, limit)]

    # -- signals ------------------------------------------------------------------

    def upload_signal(
        self,
        source: SignalSource,
        *,
        time_step: Optional[float] = None,
        time: Optional[Sequence[float]] = None,
        sampling_rate: Optional[float] = None,
        unit: Optional[str] = None,
        idempotency_key: Optional[str] = None,
        labels: Optional[Sequence[str]] = None,
        note: Optional[str] = None,
    ) -> Signal:
        """Stores an accelerogram and returns it: a NumPy array with ``time_step``
        (s), ``sampling_rate`` (Hz) or ``time`` (s); a pandas Series indexed by time;
        or a file (path or open file) of CSV ``time,acceleration`` (or JSON), of one
        column after a ``dt=0.005`` line, or a PEER AT2 file (in g, read as it is).
        ``unit`` is ``"m/s2"`` (the default) or ``"g"`` for a CSV file or an array in g;
        the server stores every record in m/s². ``labels`` and ``note`` are stored with
        it (``client.signals(label=...)``)."""
        body, content_type, params = upload_body(source, time_step=time_step, time=time, sampling_rate=sampling_rate)
        params = dict(params)
        if unit is not None:
            if content_type == "application/json":
                # A JSON body carries its unit as a member (the query's is for CSV).
                record = json.loads(body)
                record["unit"] = unit
                body = json.dumps(record).encode()
            else:
                params["unit"] = unit
        if labels:
            params["label"] = Repeated(labels)
        if note is not None:
            params["note"] = note
        response = self._transport.request(
            "POST",
            "/signals",
            content=body,
            params=params,
            headers={
                "Content-Type": content_type,
                IDEMPOTENCY_HEADER: idempotency_key or str(uuid.uuid4()),
                "Accept": "application/json",
            },
        )
        return Signal(self, response.json(), replayed=_replayed(response))

    def signal(self, signal_id: str) -> Signal:
        """A stored signal by id."""
        return Signal(self, self._transport.get_json(f"/signals/{signal_id}"))

    def signals(self, *, label: Union[str, Sequence[str], None] = None, limit: Optional[int] = 100) -> list[Signal]:
        """Stored signals newest first, those with every ``label`` given, at most
        ``limit`` (``None``: every page)."""
        labels = [label] if isinstance(label, str) else list(label or [])
        params = {"label": Repeated(labels) if labels else None}
        return [Signal(self, s) for s in self._pages("/signals", "signals", params, limit)]

    # -- paging -------------------------------------------------------------------

    def _pages(self, path: str, member: str, params: Mapping[str, Any], limit: Optional[int]) -> Iterator[dict[str, Any]]:
        """The items of a list route, following ``rel=next`` links, at most ``limit``."""
        page_size = 1000 if limit is None else max(1, min(limit, 1000))
        query: Optional[dict[str, Any]] = {**params, "limit": page_size}
        url = path
        seen = 0
        while True:
            document = self._transport.get_json(url, params=query)
            for item in document.get(member) or []:
                if limit is not None and seen >= limit:
                    return
                seen += 1
                yield item
            following = next((link["href"] for link in document.get("links") or [] if link.get("rel") == "next"), None)
            if following is None or (limit is not None and seen >= limit):
                return
            url, query = following, None


def _replayed(response: httpx.Response) -> bool:
    return str(response.headers.get(REPLAYED_HEADER, "")).strip().lower() == "true"
