"""Problem documents as exceptions, and idempotent submissions, against the real server."""

from __future__ import annotations

import copy
import uuid

import pytest

import chocmodal
from conftest import example


def small_cantilever(duration: float = 0.02) -> dict:
    inputs = copy.deepcopy(example("cantilever-impact.json")["inputs"])
    inputs["solver"]["duration"] = duration
    return inputs


def test_refused_inputs_raise_a_422_whose_text_names_the_pointer_and_the_servers_detail(client: chocmodal.Client) -> None:
    inputs = small_cantilever()
    inputs["beam"]["modes"] = 0
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.submit("cantilever-impact", inputs)
    error = raised.value
    assert error.status == 422
    assert error.kind == "invalid-inputs"
    assert [e.pointer for e in error.errors] == ["/inputs/beam/modes"]
    text = str(error)
    assert text.splitlines()[0] == error.problem.detail, "the text starts with the server's detail"
    assert "/inputs/beam/modes" in text
    assert "422" in text and error.problem.title in text and error.problem.type in text


def test_every_refused_field_is_listed_with_its_pointer(client: chocmodal.Client) -> None:
    # The contract: a missing member and the values refused elsewhere, all at once.
    inputs = small_cantilever()
    inputs["beam"]["modes"] = 0
    inputs["beam"]["density"] = -1.0
    del inputs["beam"]["length"]
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.submit("cantilever-impact", inputs)
    pointers = {e.pointer for e in raised.value.errors}
    assert pointers == {"/inputs/beam/modes", "/inputs/beam/density", "/inputs/beam/length"}
    for pointer in pointers:
        assert pointer in str(raised.value)


def test_an_unknown_member_is_refused_at_its_own_pointer(client: chocmodal.Client) -> None:
    inputs = small_cantilever()
    inputs["beam"]["section"]["inner_diamter"] = 0.009
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.submit("cantilever-impact", inputs)
    assert raised.value.status == 422
    assert "/inputs/beam/section/inner_diamter" in str(raised.value)


def test_a_bad_query_parameter_is_the_servers_400_problem(client: chocmodal.Client) -> None:
    job = client.submit("cantilever-impact", small_cantilever())
    job.wait(progress=False, timeout=60)
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        job.history("tip_displacement", series="no_such_series")
    assert raised.value.status == 400
    assert "no_such_series" in str(raised.value)


def test_an_unknown_job_is_a_404_problem(client: chocmodal.Client) -> None:
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.job(str(uuid.uuid4()))
    assert raised.value.status == 404 and raised.value.kind == "no-such-job"


def test_a_resubmission_with_the_same_idempotency_key_returns_the_same_job(client: chocmodal.Client) -> None:
    inputs = small_cantilever(0.021)
    first = client.submit("cantilever-impact", inputs)
    assert first.idempotency_key and not first.replayed
    again = client.submit("cantilever-impact", inputs, idempotency_key=first.idempotency_key)
    assert again.id == first.id
    assert again.replayed
    other = client.submit("cantilever-impact", inputs)
    assert other.id != first.id, "a new logical submission (a new key) is a new job"


def test_the_same_idempotency_key_with_other_inputs_is_refused(client: chocmodal.Client) -> None:
    key = str(uuid.uuid4())
    client.submit("cantilever-impact", small_cantilever(0.022), idempotency_key=key)
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.submit("cantilever-impact", small_cantilever(0.023), idempotency_key=key)
    assert raised.value.status == 422 and raised.value.kind == "idempotency-key-reused"
    assert key in str(raised.value)
