"""One HTTP session to the service: the bearer token, retries with back-off, and problem
documents turned into :class:`~chocmodal.errors.ChocmodalError`.

Every request this client makes may be retried: reads and ``DELETE`` are idempotent,
and every creation (``POST``) carries an ``Idempotency-Key`` made once per logical
submission and sent unchanged with each retry, so a retried submission whose first
answer was lost gets the resource the first one created instead of a second one.
"""

from __future__ import annotations

import json
import random
import time
from dataclasses import dataclass
from email.utils import parsedate_to_datetime
from typing import Any, Callable, Mapping, Optional

import httpx

from .errors import ChocmodalConnectionError, ChocmodalError, ProblemDocument

__all__ = ["RetryPolicy", "Transport"]


@dataclass(frozen=True)
class RetryPolicy:
    """When and how long to wait before trying a request again.

    A request is tried at most ``attempts`` times. It is tried again after a
    connection error (nothing answered, or the answer was lost) or an answer whose
    status is in ``statuses``: 503 (``server-busy``, ``storage-unavailable``,
    ``shutting-down``), 507 (``storage-full``) and 429 (``too-many-queued-jobs``), all of
    which the service sends with ``Retry-After``. The wait before try n (from 1) is the
    answer's ``Retry-After`` when it has one, else ``backoff × 2^(n-1)`` with up to 10 %
    jitter; never more than ``max_delay`` seconds, and all the waits of one request
    together never more than ``max_total`` seconds (then the last answer is raised).
    """

    attempts: int = 6
    backoff: float = 0.5
    max_delay: float = 30.0
    max_total: float = 120.0
    statuses: frozenset[int] = frozenset({429, 503, 507})

    def delay(self, attempt: int, retry_after: Optional[float]) -> float:
        """Seconds to wait after failed try number ``attempt`` (from 1)."""
        if retry_after is not None:
            wait = retry_after
        else:
            wait = self.backoff * 2 ** (attempt - 1)
            wait *= 1.0 + 0.1 * random.random()
        return max(0.0, min(wait, self.max_delay))


NO_RETRIES = RetryPolicy(attempts=1)


def retry_after_seconds(value: Optional[str]) -> Optional[float]:
    """``Retry-After`` as seconds: delta-seconds or an HTTP date; ``None`` if absent or unreadable."""
    if value is None:
        return None
    value = value.strip()
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:
        when = parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    return max(0.0, when.timestamp() - time.time())


def problem_of(response: httpx.Response) -> ProblemDocument:
    """The problem document of an error answer; one made from the status and the body's
    text when the answer is not one (a proxy's HTML page, an empty body)."""
    try:
        document = response.json()
    except (json.JSONDecodeError, UnicodeDecodeError, ValueError):
        document = None
    if isinstance(document, Mapping) and ("detail" in document or "type" in document):
        return ProblemDocument.from_json(document, response.status_code)
    text = response.text.strip()
    if len(text) > 500:
        text = text[:500] + "…"
    reason = response.reason_phrase or "HTTP error"
    return ProblemDocument(
        type="about:blank",
        title=reason,
        status=response.status_code,
        detail=text or f"the service answered {response.status_code} {reason} without a problem document",
    )


class Transport:
    """The shared ``httpx.Client``, its retry policy and error handling."""

    def __init__(
        self,
        base_url: str,
        *,
        token: Optional[str] = None,
        timeout: float = 60.0,
        retry: RetryPolicy = RetryPolicy(),
        http_client: Optional[httpx.Client] = None,
        sleep: Callable[[float], None] = time.sleep,
    ):
        headers = {"User-Agent": f"chocmodal-python/{_version()}"}
        if token:
            headers["Authorization"] = f"Bearer {token}"
        self.base_url = base_url.rstrip("/")
        self.retry = retry
        self._sleep = sleep
        self._owns_client = http_client is None
        self.http = http_client or httpx.Client(base_url=self.base_url, timeout=timeout)
        self.http.headers.update(headers)

    def close(self) -> None:
        if self._owns_client:
            self.http.close()

    def url(self, path: str) -> str:
        return path if path.startswith(("http://", "https://")) else self.base_url + path

    def request(
        self,
        method: str,
        path: str,
        *,
        params: Optional[Mapping[str, Any]] = None,
        json_body: Any = None,
        content: Optional[bytes] = None,
        headers: Optional[Mapping[str, str]] = None,
        ok: tuple[int, ...] = (200, 201, 204),
        retry: Optional[RetryPolicy] = None,
    ) -> httpx.Response:
        """Sends the request, retrying as the policy says; returns an answer whose status
        is in ``ok`` (or 304), raises :class:`ChocmodalError` with the problem of any
        other, :class:`ChocmodalConnectionError` when the service stays unreachable."""
        policy = retry or self.retry
        url = self.url(path)
        request_headers = dict(headers or {})
        body = content
        if json_body is not None:
            body = dumps(json_body).encode()
            request_headers.setdefault("Content-Type", "application/json")
        waited = 0.0
        attempt = 0
        while True:
            attempt += 1
            retry_after: Optional[float] = None
            failure: Exception
            try:
                answer = self.http.request(method, url, params=_query(params), content=body, headers=request_headers)
            except httpx.TransportError as error:
                failure = error
            else:
                if answer.status_code in ok or answer.status_code == 304:
                    return answer
                failure = ChocmodalError(problem_of(answer), method=method, url=str(answer.request.url))
                if answer.status_code not in policy.statuses:
                    raise failure
                retry_after = retry_after_seconds(answer.headers.get("Retry-After"))
            delay = policy.delay(attempt, retry_after)
            if attempt >= policy.attempts or waited + delay > policy.max_total:
                if isinstance(failure, ChocmodalError):
                    raise failure
                raise ChocmodalConnectionError(
                    f"{method} {url}: {type(failure).__name__}: {failure} (after {attempt} tries over {waited:.1f} s)"
                ) from failure
            self._sleep(delay)
            waited += delay

    def get_json(self, path: str, params: Optional[Mapping[str, Any]] = None) -> Any:
        return self.request("GET", path, params=params, headers={"Accept": "application/json"}).json()


def dumps(document: Any) -> str:
    """JSON text of a request body: NumPy numbers and arrays as JSON numbers and lists;
    NaN and infinities refused here (JSON has none) rather than sent as invalid JSON."""
    return json.dumps(document, allow_nan=False, default=_json_default)


def _json_default(value: Any) -> Any:
    tolist = getattr(value, "tolist", None)  # NumPy scalars and arrays
    if callable(tolist):
        return tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


class Repeated(list):
    """A query parameter sent once per value (``label=a&label=b``), not comma-joined."""


def _query(params: Optional[Mapping[str, Any]]) -> Optional[dict[str, Any]]:
    """Drops ``None`` values; lists become comma-separated (a :class:`Repeated` list is
    repeated); booleans ``true``/``false``."""
    if params is None:
        return None
    out: dict[str, Any] = {}
    for key, value in params.items():
        if value is None:
            continue
        if isinstance(value, bool):
            out[key] = "true" if value else "false"
        elif isinstance(value, Repeated):
            out[key] = [str(v) for v in value]
        elif isinstance(value, (list, tuple)):
            out[key] = ",".join(str(v) for v in value)
        else:
            out[key] = value
    return out


def _version() -> str:
    from ._version import __version__

    return __version__
