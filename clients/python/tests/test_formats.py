"""Every table in every format, and traceability, against the real server (issue 33,
items 4 and 6):

- pandas reads every CSV route of the service with ``pd.read_csv(url)``, as a user with
  no client would, and joins two histories of the same output interval on ``time``,
  also with a time grid the user builds (``k / 10_000``): sample times are the decimals
  ``k · interval``;
- the per-contact statistics table is the same through the client and ``read_csv``;
- ``Accept`` quality values are honoured; a format a route cannot give is refused with
  the formats it has; gzip bodies decode to the same text;
- labels and a note travel with a job, the list filters on them, the verdict and the
  results' provenance (solver, build, inputs hash) are there.
"""

from __future__ import annotations

import decimal
import hashlib
import json
import warnings

import httpx
import numpy as np
import pandas as pd
import pytest

import chocmodal

INTERVAL = 1e-4


def row(duration: float, released: float = 1e-4) -> dict:
    """Two short pins between the walls, one released: a run of a fraction of a second."""
    contact = {"height": 0.18, "gap": 1e-5, "stiffness": 2e5}
    return {
        "pin": {
            "length": 0.2, "young_modulus": 2.1e11, "density": 7800.0,
            "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
            "elements": 6, "modes": 3,
        },
        "pins": 2,
        "contacts": [
            {"left": "wall", "right": 0, **contact},
            {"left": 0, "right": 1, **contact},
            {"left": 1, "right": "wall", **contact},
        ],
        "initial": {"tip_displacements": [released, 0.0]},
        "solver": {"duration": duration, "check": "none"},
        "output": {"interval": INTERVAL},
    }


def finished(job: chocmodal.Job) -> chocmodal.Job:
    """Waits for the job; a coarse model's QualityWarning is not what these tests check."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", chocmodal.QualityWarning)
        job.wait(progress=False, timeout=120)
    return job


def es_number(x: float) -> str:
    """``x`` as ECMAScript's ``String(x)`` writes it (RFC 8785 §3.2.2.3)."""
    if x == 0:
        return "0"
    if isinstance(x, int):
        return str(x)
    sign, digits, exponent = decimal.Decimal(repr(abs(x))).normalize().as_tuple()
    text = "".join(map(str, digits))
    k, n = len(text), len(text) + exponent
    minus = "-" if x < 0 else ""
    if k <= n <= 21:
        return minus + text + "0" * (n - k)
    if 0 < n <= 21:
        return minus + text[:n] + "." + text[n:]
    if -6 < n <= 0:
        return minus + "0." + "0" * -n + text
    mantissa = text[0] + ("." + text[1:] if k > 1 else "")
    return f"{minus}{mantissa}e{'+' if n - 1 >= 0 else '-'}{abs(n - 1)}"


def canonical(value: object) -> str:
    """RFC 8785 canonical JSON (members sorted, no whitespace, ECMAScript numbers)."""
    if isinstance(value, dict):
        return "{" + ",".join(json.dumps(k, ensure_ascii=False) + ":" + canonical(value[k]) for k in sorted(value)) + "}"
    if isinstance(value, list):
        return "[" + ",".join(canonical(v) for v in value) + "]"
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    return es_number(value)


@pytest.fixture(scope="module")
def labelled(client: chocmodal.Client) -> chocmodal.Job:
    return finished(
        client.submit("bundle-dynamics", row(0.006), labels=["formats-test", "clad B, rev. C"], note="issue 33\nitems 4 and 6")
    )


@pytest.fixture(scope="module")
def shorter(client: chocmodal.Client) -> chocmodal.Job:
    return finished(client.submit("bundle-dynamics", row(0.004, released=2e-4), labels=["formats-test"]))


def test_pandas_reads_every_csv_route_with_read_csv(client: chocmodal.Client, server, labelled: chocmodal.Job) -> None:
    base = f"{server.url}/jobs/{labelled.id}/results"
    sweep = client.submit_sweep(
        "bundle-dynamics", row(0.002), [{"pointer": "/contacts/1/stiffness", "values": [1e5, 2e5]}]
    )
    sweep.follow(progress=False, timeout=120)
    signal = client.upload_signal(np.sin(np.arange(200) / 10.0), time_step=0.01)
    routes = {
        f"{base}/contact_forces?format=csv": "time",
        f"{base}/displacements?format=csv": "time",
        f"{base}/contact_forces_peaks?format=csv": "time",
        f"{base}/impacts?format=csv": "contact",
        f"{base}/contacts?format=csv": "contact",
        f"{base}/pins?format=csv": "pin",
        f"{base}/resultants?format=csv": "pin",
        f"{base}/displacements/spectrum?format=csv": "frequency",
        f"{base}/displacements/response_spectrum?format=csv&damping=0.05": "frequency",
        f"{server.url}/sweeps/{sweep.id}/results?format=csv": "run",
        f"{server.url}/signals/{signal.id}/samples?format=csv": "time",
        f"{server.url}/signals/{signal.id}/spectrum?format=csv": "frequency",
    }
    for url, first in routes.items():
        frame = pd.read_csv(url)
        assert list(frame.columns)[0] == first, url
        assert len(frame) > 0, url
        # The same URL asked by Accept, not by format, is the same table.
        plain = url.replace("?format=csv&", "?").replace("?format=csv", "")
        again = pd.read_csv(plain, storage_options={"Accept": "text/csv"})
        pd.testing.assert_frame_equal(again, frame, obj=url)


def test_two_histories_of_one_interval_join_on_time_and_on_a_grid_built_by_hand(
    labelled: chocmodal.Job, shorter: chocmodal.Job, server
) -> None:
    a = pd.read_csv(f"{server.url}/jobs/{labelled.id}/results/displacements?format=csv", index_col="time")
    b = pd.read_csv(f"{server.url}/jobs/{shorter.id}/results/displacements?format=csv", index_col="time")
    joined = a.add_suffix("_a").join(b.add_suffix("_b"), how="inner")
    assert len(joined) == len(b) == 41, "0.004 s every 1e-4 s: every sample of the shorter run matches"
    grid = pd.DataFrame(index=pd.Index(np.arange(len(a)) / 10_000, name="time"))
    assert len(grid.join(a, how="inner")) == len(a) == 61, "the times are k / 10000 to the bit"
    printed = open_text(f"{server.url}/jobs/{labelled.id}/results/displacements?format=csv")
    times = [line.split(",")[0] for line in printed.splitlines()[1:]]
    assert times[9] == "0.0009" and times[60] == "0.006", times[:12]
    assert all(len(t) <= 6 for t in times), times


def open_text(url: str) -> str:
    return httpx.get(url).text


def test_the_contact_table_is_the_same_through_the_client_and_read_csv(labelled: chocmodal.Job, server) -> None:
    through_client = labelled.contacts()
    direct = pd.read_csv(labelled.url("/results/contacts?format=csv"), index_col="contact")
    assert labelled.url("/results/contacts?format=csv").startswith(server.url)
    np.testing.assert_array_equal(through_client["max_force"].to_numpy(), direct["max_force"].to_numpy())
    results = labelled.results()
    for k, contact in enumerate(results["contacts"]):
        assert through_client.loc[k, "max_force"] == contact["max_force"]
        assert through_client.loc[k, "impacts"] == contact["impacts"]
    assert through_client.loc[0, "left"] == "wall" and through_client.loc[0, "right"] == 0
    assert through_client.attrs["units"]["max_force"] == "N"


def test_accept_quality_values_and_unsupported_formats(labelled: chocmodal.Job, server) -> None:
    url = f"{server.url}/jobs/{labelled.id}/results/contacts"
    answer = httpx.get(url, headers={"Accept": "text/csv;q=0.1, application/json"})
    assert answer.headers["content-type"].startswith("application/json")
    assert answer.json()["columns"][0] == "contact"
    answer = httpx.get(url, headers={"Accept": "application/json;q=0.1, text/csv"})
    assert answer.headers["content-type"].startswith("text/csv")
    refused = httpx.get(f"{server.url}/jobs/{labelled.id}/results", params={"format": "xml"})
    assert refused.status_code == 400
    assert refused.json()["type"].endswith("/invalid-query")
    assert "`json`" in refused.json()["detail"]
    refused = httpx.get(url, params={"format": "xml"})
    assert "`csv`" in refused.json()["detail"] and "`json`" in refused.json()["detail"]


def test_a_gzip_body_decodes_to_the_same_text(labelled: chocmodal.Job, server) -> None:
    url = f"{server.url}/jobs/{labelled.id}/results/displacements?format=csv"
    plain = httpx.get(url, headers={"Accept-Encoding": "identity"})
    gzipped = httpx.get(url, headers={"Accept-Encoding": "gzip"})
    assert "content-encoding" not in plain.headers
    assert gzipped.headers["content-encoding"] == "gzip"
    assert gzipped.text == plain.text
    frame = pd.read_csv(url, storage_options={"Accept-Encoding": "gzip"})
    assert len(frame) == 61


def test_labels_a_note_the_verdict_and_the_provenance_travel_with_the_job(
    client: chocmodal.Client, labelled: chocmodal.Job, shorter: chocmodal.Job
) -> None:
    labelled.status()
    assert labelled.labels == ["formats-test", "clad B, rev. C"]
    assert labelled.note == "issue 33\nitems 4 and 6"
    assert labelled.verdict == labelled.results()["quality"]["verdict"]
    both = client.jobs(label="formats-test")
    assert [job.id for job in both] == [shorter.id, labelled.id]
    only = client.jobs(label=["formats-test", "clad B, rev. C"])
    assert [job.id for job in only] == [labelled.id]
    assert all(job.verdict is not None for job in both)
    provenance = labelled.provenance()
    assert provenance["solver"] == "chocmodal"
    assert provenance["solver_version"] == chocmodal.__version__
    # The hash of the inputs' RFC 8785 form, computed here from the Python dict.
    assert provenance["inputs_sha256"] == hashlib.sha256(canonical(row(0.006)).encode()).hexdigest()
    assert es_number(2.1e11) == "210000000000" and es_number(1e-5) == "0.00001" and es_number(7800.0) == "7800"
    same = finished(client.submit("bundle-dynamics", json.loads(json.dumps(row(0.006))), labels=["other"]))
    assert same.provenance()["inputs_sha256"] == provenance["inputs_sha256"]
    assert shorter.provenance()["inputs_sha256"] != provenance["inputs_sha256"]


def test_bad_labels_are_refused_at_their_pointers(client: chocmodal.Client) -> None:
    with pytest.raises(chocmodal.ChocmodalError) as refused:
        client.submit("bundle-dynamics", row(0.002), labels=["ok", "x" * 65], note="n" * 2001)
    pointers = [e.pointer for e in refused.value.errors]
    assert pointers == ["/labels/1", "/note"]


def test_sweeps_and_signals_carry_labels_and_notes_too(client: chocmodal.Client) -> None:
    sweep = client.submit_sweep(
        "bundle-dynamics", row(0.002), [{"pointer": "/contacts/1/stiffness", "values": [1e5]}],
        labels=["formats-sweep"], note="one run",
    )
    assert sweep.status()["labels"] == ["formats-sweep"] and sweep.status()["note"] == "one run"
    assert [s.id for s in client.sweeps(label="formats-sweep")] == [sweep.id]
    signal = client.upload_signal(np.zeros(10), time_step=0.01, labels=["formats-signal", "a, b"], note="zeros")
    assert signal.metadata["labels"] == ["formats-signal", "a, b"] and signal.metadata["note"] == "zeros"
    assert [s.id for s in client.signals(label=["formats-signal", "a, b"])] == [signal.id]
    sweep.follow(progress=False, timeout=120)
