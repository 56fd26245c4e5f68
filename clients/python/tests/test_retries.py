"""Retries with back-off, against a tiny local stub server that answers from a script:
the real service cannot be made to answer 503 or 507 on demand."""

from __future__ import annotations

import json
import threading
import time
from email.utils import formatdate
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any, Iterator, Optional

import pytest

import chocmodal
from chocmodal._http import RetryPolicy, retry_after_seconds

PROBLEMS = "https://chocmodal.dev/problems/"
CREATED = {"jobID": "5f0c2a8e-0000-4000-8000-000000000001", "processID": "cantilever-impact", "status": "accepted", "progress": 0}


def problem(kind: str, status: int, title: str, detail: str) -> dict[str, Any]:
    return {"type": PROBLEMS + kind, "title": title, "status": status, "detail": detail}


class Stub:
    """Answers each request with the next scripted answer (the last one repeats):
    ``(status, headers, body)``, or ``"drop"`` to close the connection unanswered."""

    def __init__(self, script: list[Any]):
        self.script = list(script)
        self.requests: list[dict[str, Any]] = []
        stub = self

        class Handler(BaseHTTPRequestHandler):
            def _answer(self) -> None:
                length = int(self.headers.get("Content-Length") or 0)
                body = self.rfile.read(length) if length else b""
                stub.requests.append(
                    {"method": self.command, "path": self.path, "headers": dict(self.headers), "body": body, "at": time.monotonic()}
                )
                answer = stub.script[min(len(stub.requests), len(stub.script)) - 1]
                if answer == "drop":
                    self.close_connection = True
                    return
                status, headers, payload = answer
                data = payload if isinstance(payload, bytes) else json.dumps(payload).encode()
                self.send_response(status)
                for name, value in headers.items():
                    self.send_header(name, value)
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            do_GET = do_POST = do_DELETE = _answer

            def log_message(self, *args: Any) -> None:
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}"
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()

    def gaps(self) -> list[float]:
        times = [r["at"] for r in self.requests]
        return [b - a for a, b in zip(times, times[1:])]


@pytest.fixture
def stub_factory() -> Iterator[Any]:
    stubs: list[Stub] = []

    def make(script: list[Any]) -> Stub:
        stub = Stub(script)
        stubs.append(stub)
        return stub

    yield make
    for stub in stubs:
        stub.close()


def busy(kind: str = "storage-unavailable", status: int = 503, retry_after: Optional[str] = "1") -> tuple:
    headers = {"Content-Type": "application/problem+json"}
    if retry_after is not None:
        headers["Retry-After"] = retry_after
    return (status, headers, problem(kind, status, "Busy", f"the storage failed ({kind}): nothing was stored"))


def created() -> tuple:
    return (201, {"Content-Type": "application/json", "Location": f"/jobs/{CREATED['jobID']}"}, CREATED)


def test_a_submission_answered_503_then_507_is_retried_after_retry_after_with_the_same_key(stub_factory: Any) -> None:
    stub = stub_factory([busy("storage-unavailable", 503), busy("storage-full", 507), created()])
    with chocmodal.Client(stub.url) as client:
        job = client.submit("cantilever-impact", {"beam": {}})
    assert job.id == CREATED["jobID"]
    assert len(stub.requests) == 3
    keys = {r["headers"].get("Idempotency-Key") for r in stub.requests}
    assert len(keys) == 1 and None not in keys, "every try repeats the one key of the submission"
    bodies = {r["body"] for r in stub.requests}
    assert len(bodies) == 1
    for gap in stub.gaps():
        assert gap >= 0.95, f"waited {gap:.3f} s, Retry-After said 1 s"


def test_without_retry_after_the_waits_grow_exponentially(stub_factory: Any) -> None:
    stub = stub_factory([busy(retry_after=None), busy(retry_after=None), busy(retry_after=None), created()])
    policy = RetryPolicy(attempts=4, backoff=0.1, max_delay=5.0)
    with chocmodal.Client(stub.url, retry=policy) as client:
        client.submit("cantilever-impact", {})
    gaps = stub.gaps()
    assert len(gaps) == 3
    for n, gap in enumerate(gaps):
        assert gap >= 0.1 * 2**n * 0.95, f"wait {n + 1}: {gap:.3f} s, expected at least {0.1 * 2**n} s"
    assert gaps[2] > gaps[0] * 2


def test_retries_are_bounded_and_the_last_problem_is_raised_with_its_detail(stub_factory: Any) -> None:
    stub = stub_factory([busy("storage-full", 507, retry_after="0")])
    with chocmodal.Client(stub.url, retry=RetryPolicy(attempts=3)) as client:
        with pytest.raises(chocmodal.ChocmodalError) as raised:
            client.submit("cantilever-impact", {})
    assert len(stub.requests) == 3
    assert raised.value.status == 507 and raised.value.kind == "storage-full"
    assert str(raised.value).startswith("the storage failed (storage-full)")


def test_a_retry_after_beyond_the_total_budget_is_not_waited_for(stub_factory: Any) -> None:
    stub = stub_factory([busy(retry_after="100")])
    started = time.monotonic()
    with chocmodal.Client(stub.url, retry=RetryPolicy(max_total=5.0)) as client:
        with pytest.raises(chocmodal.ChocmodalError):
            client.processes()
    assert time.monotonic() - started < 2.0
    assert len(stub.requests) == 1


def test_a_refusal_is_not_retried(stub_factory: Any) -> None:
    refusal = problem("invalid-inputs", 422, "Invalid inputs", "/inputs/beam/modes: must be between 1 and 78")
    refusal["errors"] = [{"pointer": "/inputs/beam/modes", "detail": "must be between 1 and 78"}]
    stub = stub_factory([(422, {"Content-Type": "application/problem+json"}, refusal)])
    with chocmodal.Client(stub.url) as client:
        with pytest.raises(chocmodal.ChocmodalError) as raised:
            client.submit("cantilever-impact", {})
    assert len(stub.requests) == 1
    assert "/inputs/beam/modes: must be between 1 and 78" in str(raised.value)


def test_a_dropped_connection_is_retried_with_the_same_key(stub_factory: Any) -> None:
    stub = stub_factory(["drop", created()])
    with chocmodal.Client(stub.url, retry=RetryPolicy(backoff=0.05)) as client:
        job = client.submit("cantilever-impact", {})
    assert job.id == CREATED["jobID"]
    assert len(stub.requests) == 2
    assert stub.requests[0]["headers"]["Idempotency-Key"] == stub.requests[1]["headers"]["Idempotency-Key"]


def test_an_unreachable_service_raises_a_connection_error_after_the_retries() -> None:
    stub = Stub([created()])
    url = stub.url
    stub.close()  # nothing listens there any more
    with chocmodal.Client(url, retry=RetryPolicy(attempts=2, backoff=0.01)) as client:
        with pytest.raises(chocmodal.ChocmodalConnectionError) as raised:
            client.processes()
    assert "after 2 tries" in str(raised.value)


def test_an_error_without_a_problem_document_still_says_what_the_server_said(stub_factory: Any) -> None:
    stub = stub_factory([(502, {"Content-Type": "text/html"}, b"<html>upstream went away</html>")])
    with chocmodal.Client(stub.url) as client:
        with pytest.raises(chocmodal.ChocmodalError) as raised:
            client.processes()
    assert raised.value.status == 502
    assert "upstream went away" in str(raised.value)


def test_the_bearer_token_is_sent_with_every_request(stub_factory: Any) -> None:
    stub = stub_factory([(200, {"Content-Type": "application/json"}, {"processes": [], "links": []})])
    with chocmodal.Client(stub.url, token="s3cret-token-0123456789") as client:
        client.processes()
        client.processes()
    assert [r["headers"].get("Authorization") for r in stub.requests] == ["Bearer s3cret-token-0123456789"] * 2


def test_retry_after_is_read_as_seconds_or_as_a_date() -> None:
    assert retry_after_seconds("5") == 5.0
    assert retry_after_seconds(None) is None
    assert retry_after_seconds("soon") is None
    in_ten = retry_after_seconds(formatdate(time.time() + 10, usegmt=True))
    assert in_ten is not None and 8.0 <= in_ten <= 10.5
    assert RetryPolicy(max_delay=3.0).delay(1, 100.0) == 3.0
