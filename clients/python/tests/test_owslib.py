"""A standard OGC API – Processes client against the live server: OWSLib
(``owslib.ogcapi.processes.Processes``), the OGC client library of the Python GIS world.

OWSLib reads the landing page and the conformance classes, lists the processes,
describes one and executes it, each with its own requests and expectations (its
headers, its ``Prefer``, its JSON handling). Its ``Processes`` class (0.35) has no call
for jobs: the test follows the job and reads its results with plain httpx, as a generic
OGC client does, through the ``Location`` header and the links of the status document
(``rel=…/results``), never through URLs it builds itself.

The result is checked against physics, not against a previous output: the cantilever's
first natural frequency is Euler–Bernoulli's f1 = 1.8751² / (2π L²) · √(EI / ρA).
"""

from __future__ import annotations

import copy
import math
import time
from urllib.parse import urljoin

import httpx
import pytest

from conftest import Server, example

owslib_processes = pytest.importorskip(
    "owslib.ogcapi.processes", reason="OWSLib is not installed (pip install OWSLib; CI installs it)"
)

CORE = "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/core"
RESULTS = "http://www.opengis.net/def/rel/ogc/1.0/results"


def small_cantilever() -> dict:
    inputs = copy.deepcopy(example("cantilever-impact.json")["inputs"])
    inputs["solver"]["duration"] = 0.05
    return inputs


def euler_bernoulli_f1(beam: dict) -> float:
    section = beam["section"]
    outer, inner = section["outer_diameter"], section["inner_diameter"]
    area = math.pi / 4 * (outer**2 - inner**2)
    inertia = math.pi / 64 * (outer**4 - inner**4)
    length = beam["length"]
    return 1.8751**2 / (2 * math.pi * length**2) * math.sqrt(beam["young_modulus"] * inertia / (beam["density"] * area))


def follow(url: str, timeout: float = 60.0) -> dict:
    """Polls a job's status document until it is finished."""
    deadline = time.monotonic() + timeout
    while True:
        status = httpx.get(url).raise_for_status().json()
        if status["status"] in {"successful", "failed", "dismissed"}:
            return status
        assert time.monotonic() < deadline, f"the job did not finish within {timeout} s: {status}"
        time.sleep(0.1)


def test_owslib_lists_and_describes_the_processes(server: Server) -> None:
    api = owslib_processes.Processes(server.url)
    assert any(link["rel"] == "service-desc" for link in api.links), "the landing page links its API definition"
    assert CORE in api.conformance()["conformsTo"]
    listed = {process["id"]: process for process in api.processes()}
    assert {"cantilever-impact", "bundle-dynamics", "hex-bundle-dynamics"} <= set(listed)
    assert "async-execute" in listed["cantilever-impact"]["jobControlOptions"]
    description = api.process("cantilever-impact")
    assert description["id"] == "cantilever-impact"
    assert {"beam", "contact", "solver"} <= set(description["inputs"])
    assert "tip_displacement" in description["outputs"]


@pytest.mark.parametrize("async_", [True, False], ids=["prefer-async", "prefer-sync"])
def test_owslib_executes_a_process_and_its_job_leads_to_the_results(server: Server, async_: bool) -> None:
    api = owslib_processes.Processes(server.url)
    inputs = small_cantilever()
    # OWSLib sends `response: document` and `Prefer: respond-async` (or `respond-sync`,
    # which this asynchronous-only service answers with a job all the same).
    status = api.execute("cantilever-impact", inputs=inputs, async_=async_)
    assert status["status"] in {"accepted", "running", "successful"}, status
    assert status["processID"] == "cantilever-impact"
    location = api.response_headers["Location"]
    assert location.endswith(status["jobID"])
    if async_:
        assert api.response_headers.get("Preference-Applied") == "respond-async"
    finished = follow(urljoin(server.url, location))
    assert finished["status"] == "successful", finished
    results_link = next(link for link in finished["links"] if link["rel"] == RESULTS)
    results = httpx.get(urljoin(server.url, results_link["href"])).raise_for_status().json()
    measured = results["numerical"]["frequencies_hz"][0]
    expected = euler_bernoulli_f1(inputs["beam"])
    assert measured == pytest.approx(expected, rel=0.01), f"f1 {measured} Hz, Euler–Bernoulli {expected} Hz"
    history = results["outputs"]["tip_displacement"]["href"]
    csv = httpx.get(urljoin(server.url, history), params={"format": "csv"}).raise_for_status().text
    assert csv.splitlines()[0] == "time,numerical,reference"
