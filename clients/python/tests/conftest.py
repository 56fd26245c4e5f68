"""A real chocmodal server for the tests: the binary started once per test session on an
ephemeral port with a fresh data directory, stopped at the end.

The binary is ``$CHOCMODAL_BIN``, else ``target/debug/chocmodal`` under the repository
root (``cargo test --all-targets`` or ``cargo build`` makes it). Without it the server
tests are skipped with the reason, except under ``CI=true``, where they fail: CI must
never pass on tests it did not run. For the same reason, under ``CI=true`` any skipped
test fails the session.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Iterator, Optional

import pytest

import chocmodal

REPO_ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = REPO_ROOT / "examples"
IN_CI = os.environ.get("CI", "").lower() == "true"


def server_binary() -> Optional[Path]:
    given = os.environ.get("CHOCMODAL_BIN")
    candidate = Path(given) if given else REPO_ROOT / "target" / "debug" / "chocmodal"
    if not candidate.is_absolute():
        candidate = REPO_ROOT / candidate
    return candidate if candidate.is_file() and os.access(candidate, os.X_OK) else None


class Server:
    """One ``chocmodal serve`` process; its log (JSON lines) in ``log_path``."""

    def __init__(self, binary: Path, data_dir: Path, *extra: str):
        self.log_path = data_dir / "server.log"
        self._log = open(self.log_path, "w")
        self.process = subprocess.Popen(
            [
                str(binary),
                "serve",
                "--bind",
                "127.0.0.1:0",
                "--data-dir",
                str(data_dir / "data"),
                "--workers",
                "2",
                "--log-format",
                "json",
                "--shutdown-grace-seconds",
                "1",
                *extra,
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.url = self._wait_until_ready(timeout=60)

    def _wait_until_ready(self, timeout: float) -> str:
        found: dict[str, str] = {}
        ready = threading.Event()
        assert self.process.stderr is not None
        stderr = self.process.stderr

        def drain() -> None:
            # Reads every log line for the whole life of the server, so it never blocks
            # on a full pipe; the first "ready" line gives the address.
            for line in stderr:
                self._log.write(line)
                self._log.flush()
                if not ready.is_set() and "chocmodal is ready" in line:
                    try:
                        found["address"] = json.loads(line)["fields"]["address"]
                    except (ValueError, KeyError):
                        pass
                    ready.set()
            ready.set()

        self._drain = threading.Thread(target=drain, daemon=True)
        self._drain.start()
        if not ready.wait(timeout) or "address" not in found:
            self.stop()
            raise RuntimeError(
                f"chocmodal did not report ready within {timeout} s; its log:\n{self.log_path.read_text()[-4000:]}"
            )
        return f"http://{found['address']}"

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=5)
        self._drain.join(timeout=5)
        if self.process.stderr is not None:
            self.process.stderr.close()
        self._log.close()


@pytest.fixture(scope="session")
def server() -> Iterator[Server]:
    binary = server_binary()
    if binary is None:
        where = os.environ.get("CHOCMODAL_BIN") or str(REPO_ROOT / "target" / "debug" / "chocmodal")
        message = (
            f"no chocmodal binary at {where}: build it (cargo build, or cargo test --all-targets) "
            "or point CHOCMODAL_BIN at one"
        )
        if IN_CI:
            pytest.fail(message, pytrace=False)
        pytest.skip(message)
    with tempfile.TemporaryDirectory(prefix="chocmodal-pytest-") as directory:
        started = Server(binary, Path(directory))
        try:
            yield started
        finally:
            started.stop()
            if os.environ.get("TEST_LOG"):
                sys.stderr.write(started.log_path.read_text())


@pytest.fixture(scope="session")
def client(server: Server) -> Iterator[chocmodal.Client]:
    with chocmodal.Client(server.url) as session_client:
        yield session_client


def example(name: str) -> dict:
    """An example file of the repository (``examples/<name>``), parsed."""
    with open(EXAMPLES / name) as handle:
        return json.load(handle)


def pytest_terminal_summary(terminalreporter, exitstatus, config) -> None:  # type: ignore[no-untyped-def]
    skipped = terminalreporter.stats.get("skipped", [])
    if IN_CI and skipped:
        terminalreporter.write_line(
            f"CI=true: {len(skipped)} test(s) skipped; a skip under CI is a failure", red=True
        )


def pytest_sessionfinish(session, exitstatus) -> None:  # type: ignore[no-untyped-def]
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if IN_CI and reporter is not None and reporter.stats.get("skipped") and session.exitstatus == 0:
        session.exitstatus = 1
