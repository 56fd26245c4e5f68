"""Job callbacks through the client: ``submit(..., subscriber=...)`` against a server whose
operator allows the loopback, with a receiver on it (a standard-library HTTP server), and
the signature checked with :func:`chocmodal.verify_signature` (Python's own ``hmac``:
an implementation independent of the service's). Without an allow-list the server
refuses subscribers, and the client raises its problem document.
"""

from __future__ import annotations

import copy
import json
import tempfile
import threading
import time
from email.message import Message
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Iterator

import pytest

import chocmodal
from conftest import IN_CI, Server, example, server_binary

SECRET = "pytest-callback-secret-0123456789"


def small_cantilever() -> dict:
    inputs = copy.deepcopy(example("cantilever-impact.json")["inputs"])
    inputs["solver"]["duration"] = 0.02
    return inputs


class Receiver:
    """Records every POST (path, headers as sent: names case-insensitive, raw body) and
    answers 204."""

    def __init__(self) -> None:
        self.received: list[tuple[str, Message, bytes]] = []
        self.arrived = threading.Condition()
        receiver = self

        class Handler(BaseHTTPRequestHandler):
            def do_POST(self) -> None:  # noqa: N802 (the standard library's name)
                body = self.rfile.read(int(self.headers.get("Content-Length", "0")))
                with receiver.arrived:
                    receiver.received.append((self.path, self.headers, body))
                    receiver.arrived.notify_all()
                self.send_response(204)
                self.end_headers()

            def log_message(self, *args: object) -> None:
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}"
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()

    def wait_for(self, path: str, timeout: float) -> tuple[str, Message, bytes]:
        deadline = time.monotonic() + timeout
        with self.arrived:
            while True:
                for item in self.received:
                    if item[0] == path:
                        return item
                left = deadline - time.monotonic()
                assert left > 0, f"no callback to {path} within {timeout} s: {[r[0] for r in self.received]}"
                self.arrived.wait(left)

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture(scope="module")
def callback_server() -> Iterator[Server]:
    """A second server whose operator allows callbacks to the loopback."""
    binary = server_binary()
    if binary is None:
        message = "no chocmodal binary: build it (cargo build) or point CHOCMODAL_BIN at one"
        if IN_CI:
            pytest.fail(message, pytrace=False)
        pytest.skip(message)
    with tempfile.TemporaryDirectory(prefix="chocmodal-pytest-callbacks-") as directory:
        secrets = Path(directory) / "callback-secrets"
        secrets.write_text(f"# tenant secret\ndefault {SECRET}\n")
        started = Server(
            binary, Path(directory), "--callback-allow", "127.0.0.1", "--callback-secrets", str(secrets)
        )
        try:
            yield started
        finally:
            started.stop()


def test_a_subscribed_job_posts_its_signed_status_document(callback_server: Server) -> None:
    receiver = Receiver()
    try:
        with chocmodal.Client(callback_server.url) as client:
            job = client.submit(
                "cantilever-impact",
                small_cantilever(),
                subscriber={"successUri": f"{receiver.url}/done", "failedUri": f"{receiver.url}/failed"},
            )
            job.wait(progress=False, warn_quality=False)
            path, headers, body = receiver.wait_for("/done", timeout=10)
            document = json.loads(body)
            assert document == job.status()
            assert document["status"] == "successful"
            signature = headers.get(chocmodal.SIGNATURE_HEADER)
            assert chocmodal.verify_signature(signature, body, SECRET)
            assert chocmodal.verify_signature(signature, body, ["an-old-secret-0123456789", SECRET])
            assert not chocmodal.verify_signature(signature, body, "another-secret-0123456789")
            assert not chocmodal.verify_signature(signature, body + b" ", SECRET)
            assert not chocmodal.verify_signature(signature, body, SECRET, now=time.time() + 3600)
    finally:
        receiver.close()


def test_without_an_allow_list_a_subscriber_is_refused_at_its_pointer(client: chocmodal.Client) -> None:
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.submit("cantilever-impact", small_cantilever(), subscriber={"successUri": "http://127.0.0.1:9/done"})
    error = raised.value
    assert error.status == 422
    assert [e.pointer for e in error.errors] == ["/subscriber/successUri"]
    assert "--callback-allow" in str(error)
