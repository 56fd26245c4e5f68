"""Processes and their descriptions (OGC API – Processes: /processes, /processes/{id})."""

from __future__ import annotations

import pytest

import chocmodal

SHIPPED = {"cantilever-impact", "bundle-dynamics", "hex-bundle-dynamics"}


def test_the_process_list_names_the_shipped_processes_with_their_job_controls(client: chocmodal.Client) -> None:
    processes = client.processes()
    ids = {p["id"] for p in processes}
    assert SHIPPED <= ids
    for process in processes:
        assert {"id", "title", "description", "jobControlOptions", "links"} <= set(process), process
        assert "async-execute" in process["jobControlOptions"]


def test_a_description_carries_the_input_schema_with_units_and_the_outputs_kinds(client: chocmodal.Client) -> None:
    description = client.process("cantilever-impact")
    beam = description["inputs"]["beam"]["schema"]["properties"]
    assert {"length", "young_modulus", "density", "section", "modes"} <= set(beam)
    assert "(m)" in beam["length"]["description"], "lengths are described in SI units"
    outputs = description["outputs"]
    assert outputs["tip_displacement"]["kind"] == "displacement"
    assert outputs["contact_force_peaks"]["kind"] == "peaks"
    assert outputs["impacts"]["kind"] == "table"


def test_an_unknown_process_is_a_404_whose_text_is_the_servers_detail(client: chocmodal.Client) -> None:
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.process("no-such-thing")
    error = raised.value
    assert error.status == 404
    assert error.kind == "no-such-process"
    assert str(error).startswith(error.problem.detail)
    assert "no-such-thing" in str(error)
