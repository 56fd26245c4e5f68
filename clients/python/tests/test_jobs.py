"""Jobs end to end against the real server: submit, wait, results, histories as
DataFrames, the impact table and the per-contact statistics.

Expected values come from the inputs and from physics, never from a previous output:

- the cantilever's first natural frequency is Euler–Bernoulli's
  f1 = 1.8751² / (2π L²) · √(EI / ρA); the tip spring's stiffness is Kc = Rk · 3EI/L³;
  with no gap and no dashpot its force at every sample is Kc · max(0, −w_tip);
- a bundle contact's force at rest is stiffness × penetration: pin 0 released at its
  tip 1 mm toward pin 1 with a 0.1 mm gap presses on it with 2e6 N/m × 0.9 mm = 1800 N;
- the contract: histories are sampled every ``output.interval`` from 0 to the
  duration; a contact's ``max_force`` is the largest value of its column of
  ``contact_forces_peaks``; the impact table holds every impact of every contact.
"""

from __future__ import annotations

import copy
import math
import re
import warnings

import numpy as np
import pandas as pd
import pytest

import chocmodal
from conftest import example

INTERVAL = 1e-4


def cantilever_inputs() -> dict:
    inputs = copy.deepcopy(example("cantilever-impact.json")["inputs"])
    inputs["solver"]["duration"] = 0.1
    inputs["output"] = {"interval": INTERVAL}
    return inputs


def bundle_inputs() -> dict:
    """The two-pin explicit bundle of the API contract, shortened to 0.05 s."""
    contact = {"height": 1.8, "gap": 1e-4, "stiffness": 2e6, "damping": 20.0}
    return {
        "pin": {
            "length": 1.8, "young_modulus": 2.1e11, "density": 7800.0,
            "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
            "added_mass_per_length": 0.6, "elements": 40, "modes": 20, "damping_ratio": 0.01,
        },
        "pins": 2,
        "contacts": [
            {"left": "wall", "right": 0, **contact},
            {"left": 0, "right": 1, **contact},
            {"left": 1, "right": "wall", **contact},
        ],
        "initial": {"tip_displacements": [0.001, 0.0]},
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 50.0, "duration": 0.01}},
        "solver": {"scheme": "central_difference", "time_step": 1e-6, "duration": 0.05},
        "output": {"interval": INTERVAL},
    }


@pytest.fixture(scope="module")
def cantilever(client: chocmodal.Client) -> chocmodal.Job:
    job = client.submit("cantilever-impact", cantilever_inputs())
    job.wait(progress=False, timeout=120)
    return job


@pytest.fixture(scope="module")
def bundle(client: chocmodal.Client) -> chocmodal.Job:
    job = client.submit("bundle-dynamics", bundle_inputs())
    # This coarse model's verdict is not good (the contract of wait: a QualityWarning).
    with pytest.warns(chocmodal.QualityWarning):
        job.wait(progress=False, timeout=120)
    return job


def assert_sampled_every_interval(frame: pd.DataFrame, duration: float) -> None:
    time = frame.index.to_numpy()
    assert frame.index.name == "time"
    assert time[0] == 0.0
    steps = np.diff(time)
    assert np.all(steps > 0), "time increases"
    np.testing.assert_allclose(steps, INTERVAL, rtol=1e-9, err_msg="samples every output.interval")
    assert time[-1] == pytest.approx(duration, rel=1e-12), "the last sample is at the duration"


# -- cantilever-impact ---------------------------------------------------------------


def test_a_submitted_cantilever_ends_successful_with_a_good_verdict_and_no_warning(
    client: chocmodal.Client,
) -> None:
    inputs = cantilever_inputs()
    inputs["solver"]["duration"] = 0.06  # another job than the module's
    job = client.submit("cantilever-impact", inputs)
    assert job.status()["status"] in {"accepted", "running", "successful"}
    with warnings.catch_warnings():
        warnings.simplefilter("error", chocmodal.QualityWarning)
        results = job.wait(progress=False, timeout=120)
    assert job.status()["status"] == "successful"
    assert job.status()["progress"] == 100
    assert results["quality"]["verdict"] == "good"
    assert isinstance(results["numerical"], dict) and isinstance(results["outputs"], dict)


def test_the_cantilevers_frequency_and_first_impact_are_euler_bernoullis(cantilever: chocmodal.Job) -> None:
    inputs = cantilever_inputs()
    beam = inputs["beam"]
    outer, inner = beam["section"]["outer_diameter"], beam["section"]["inner_diameter"]
    inertia = math.pi * (outer**4 - inner**4) / 64
    area = math.pi * (outer**2 - inner**2) / 4
    f1 = 1.87510407**2 / (2 * math.pi * beam["length"] ** 2) * math.sqrt(
        beam["young_modulus"] * inertia / (beam["density"] * area)
    )
    results = cantilever.results()
    assert results["numerical"]["frequencies_hz"][0] == pytest.approx(f1, rel=1e-3)
    # Released from its tip-load shape at +1 mm with no gap: the tip reaches the spring
    # after about a quarter of the first period (the shape is nearly mode 1's).
    assert results["numerical"]["first_impact_time"] == pytest.approx(1 / (4 * f1), rel=0.03)
    assert results["comparison"]["agrees"] is True
    assert results["comparison"]["f_err"] < results["comparison"]["threshold"]


def test_cantilever_histories_are_frames_indexed_by_time_with_units(cantilever: chocmodal.Job) -> None:
    tip = cantilever.history("tip_displacement")
    assert list(tip.columns) == ["numerical", "reference"]
    assert_sampled_every_interval(tip, cantilever_inputs()["solver"]["duration"])
    assert tip.attrs["units"] == {"time": "s", "numerical": "m", "reference": "m"}
    assert tip.dtypes.eq(np.float64).all()
    release = cantilever_inputs()["release"]["tip_displacement"]
    assert tip["numerical"].iloc[0] == pytest.approx(release, rel=1e-9), "released from the given tip displacement"
    force = cantilever.history("contact_force")
    assert force.attrs["units"]["numerical"] == "N"


def test_the_tip_spring_force_is_its_stiffness_times_the_tip_penetration(cantilever: chocmodal.Job) -> None:
    inputs = cantilever_inputs()
    beam = inputs["beam"]
    outer, inner = beam["section"]["outer_diameter"], beam["section"]["inner_diameter"]
    inertia = math.pi * (outer**4 - inner**4) / 64
    stiffness = inputs["contact"]["rk"] * 3 * beam["young_modulus"] * inertia / beam["length"] ** 3
    tip = cantilever.history("tip_displacement")
    force = cantilever.history("contact_force")
    assert (force.index == tip.index).all()
    for series in ("numerical", "reference"):
        expected = stiffness * np.maximum(0.0, -tip[series].to_numpy())
        np.testing.assert_allclose(force[series].to_numpy(), expected, rtol=1e-9, atol=1e-12 * expected.max())
    assert force["numerical"].max() > 0, "the tip hits the spring within the run"


def test_the_csv_frame_holds_exactly_the_numbers_of_the_json_form(cantilever: chocmodal.Job) -> None:
    # The service writes the shortest text that reads back as the same double.
    document = cantilever._client._transport.get_json(
        f"/jobs/{cantilever.id}/results/tip_displacement", params={"format": "json"}
    )
    frame = cantilever.history("tip_displacement")
    assert document["thinned"] is False
    np.testing.assert_array_equal(frame.index.to_numpy(), np.array(document["time"]))
    for series in document["series"]:
        np.testing.assert_array_equal(frame[series["name"]].to_numpy(), np.array(series["values"]))
    assert {c["name"]: c["unit"] for c in document["columns"]} == frame.attrs["units"]


def test_every_history_of_a_job_is_read_and_tables_are_left_out(cantilever: chocmodal.Job) -> None:
    histories = cantilever.histories()
    assert set(histories) == {"tip_displacement", "tip_displacement_peaks", "contact_force", "contact_force_peaks"}
    assert set(cantilever.histories(peaks=False)) == {"tip_displacement", "contact_force"}


def test_a_history_window_and_thinning_follow_the_query(cantilever: chocmodal.Job) -> None:
    window = cantilever.history("tip_displacement", t_start=0.02, t_end=0.03, series="numerical")
    assert list(window.columns) == ["numerical"]
    assert window.index.min() >= 0.02 and window.index.max() <= 0.03
    assert len(window) == pytest.approx(0.01 / INTERVAL + 1, abs=1)
    thinned = cantilever.history("contact_force", max_points=50)
    full = cantilever.history("contact_force")
    assert len(thinned) <= 50
    assert thinned["numerical"].max() == full["numerical"].max(), "thinning keeps the peak"


def test_the_xarray_view_of_a_cantilever_history_is_a_dataset_over_time(cantilever: chocmodal.Job) -> None:
    dataset = cantilever.to_xarray("tip_displacement")
    assert set(dataset.data_vars) == {"numerical", "reference"}
    assert dataset["numerical"].attrs["units"] == "m"
    assert dataset.sizes["time"] == len(cantilever.history("tip_displacement"))


# -- bundle-dynamics -----------------------------------------------------------------


def test_bundle_histories_have_one_column_per_contact_and_per_pin(bundle: chocmodal.Job) -> None:
    inputs = bundle_inputs()
    forces = bundle.history("contact_forces")
    assert list(forces.columns) == [f"c{k}" for k in range(len(inputs["contacts"]))]
    assert set(forces.attrs["units"].values()) == {"s", "N"}
    assert_sampled_every_interval(forces, inputs["solver"]["duration"])
    deflections = bundle.history("displacements")
    assert list(deflections.columns) == [f"p{p}" for p in range(inputs["pins"])]
    assert deflections.attrs["units"]["p0"] == "m"
    assert deflections["p0"].iloc[0] == pytest.approx(inputs["initial"]["tip_displacements"][0], rel=1e-9)


def test_a_contact_pressed_at_rest_carries_stiffness_times_penetration(bundle: chocmodal.Job) -> None:
    inputs = bundle_inputs()
    between = inputs["contacts"][1]
    penetration = inputs["initial"]["tip_displacements"][0] - inputs["initial"]["tip_displacements"][1] - between["gap"]
    forces = bundle.history("contact_forces")
    assert forces["c1"].iloc[0] == pytest.approx(between["stiffness"] * penetration, rel=1e-9)
    assert forces["c0"].iloc[0] == 0.0 and forces["c2"].iloc[0] == 0.0, "the walls' contacts start open"


def test_per_contact_statistics_are_a_frame_whose_max_force_is_the_peak_envelopes_maximum(bundle: chocmodal.Job) -> None:
    inputs = bundle_inputs()
    contacts = bundle.contacts()
    assert list(contacts.index) == list(range(len(inputs["contacts"])))
    assert contacts.index.name == "contact"
    for k, given in enumerate(inputs["contacts"]):
        assert str(contacts.loc[k, "left"]) == str(given["left"])
        assert str(contacts.loc[k, "right"]) == str(given["right"])
        assert contacts.loc[k, "height"] == given["height"]
    assert contacts.attrs["units"]["max_force"] == "N"
    assert contacts.attrs["units"]["impulse"] == "N·s"
    assert contacts.attrs["units"]["impact_statistics.rms_force"] == "N"
    peaks = bundle.history("contact_forces_peaks")
    sampled = bundle.history("contact_forces")
    for k in contacts.index:
        column = f"c{k}"
        assert contacts.loc[k, "max_force"] == pytest.approx(peaks[column].max(), rel=1e-9), column
        assert sampled[column].max() <= contacts.loc[k, "max_force"] * (1 + 1e-12), "samples never exceed the peak"


def test_resultant_contact_forces_are_a_frame_by_pin_and_height_bounded_by_the_contacts(bundle: chocmodal.Job) -> None:
    resultants = bundle.resultants()
    assert resultants.index.names == ["pin", "height"]
    assert resultants.attrs["units"]["max_force"] == "N" and resultants.attrs["units"]["height"] == "m"
    contacts = bundle.contacts()
    for (pin, height), row in resultants.iterrows():
        here = contacts[(contacts["height"] == height) & ((contacts["left"] == pin) | (contacts["right"] == pin))]
        assert row["contacts"] == len(here), (pin, height)
        if len(here) == 1:
            assert row["max_force"] == pytest.approx(here["max_force"].iloc[0], rel=1e-12), "a lone contact's resultant is its peak"
        else:
            assert row["max_force"] <= here["max_force"].sum() * (1 + 1e-12)
    results = bundle.results()
    for entry in results["pins"]:
        largest = resultants.loc[entry["pin"], "max_force"].max()
        assert entry["max_resultant_force"]["max_force"] == largest
    assert results["max_resultant_force"]["max_force"] == resultants["max_force"].max()
    # The per-pin frame keeps one row per pin; the per-height list is the frame above.
    assert "resultant_forces" not in bundle.pins().columns


def test_the_calculation_note_is_written_where_asked(bundle: chocmodal.Job, tmp_path) -> None:
    target = tmp_path / "note.html"
    html = bundle.report(target)
    assert target.read_text(encoding="utf-8") == html
    assert html.startswith("<!doctype html>")
    assert f"Calculation note: bundle-dynamics job {bundle.id}" in html
    # Every figure carries the results member it comes from, with its exact value.
    peak = bundle.results()["max_contact_force"]["force"]
    shown = re.search(r'data-pointer="/max_contact_force/force" data-value="([^"]+)"', html)
    assert shown is not None and float(shown.group(1)) == peak


def test_the_impact_table_holds_every_impact_of_every_contact(bundle: chocmodal.Job) -> None:
    results = bundle.results()
    assert results["impact_summary"]["untabulated"] == 0
    impacts = bundle.impacts()
    assert list(impacts.columns) == [
        "contact", "start", "peak_time", "peak_force", "impulse",
        "duration", "approach_velocity", "rebounds", "dissipated", "energy",
    ]
    assert impacts.attrs["units"]["peak_force"] == "N" and impacts.attrs["units"]["start"] == "s"
    assert impacts["start"].is_monotonic_increasing
    assert (impacts["peak_time"] >= impacts["start"]).all()
    contacts = bundle.contacts()
    per_contact = impacts.groupby("contact")
    for k in contacts.index:
        assert int(per_contact.size().get(k, 0)) == contacts.loc[k, "impacts"]
        if contacts.loc[k, "impacts"]:
            assert per_contact["peak_force"].max()[k] == pytest.approx(contacts.loc[k, "max_force"], rel=1e-9)
            assert per_contact["impulse"].sum()[k] == pytest.approx(contacts.loc[k, "impulse"], rel=1e-9)
    only = bundle.impacts(contact=1)
    assert set(only["contact"]) == {1}
    assert len(only) == contacts.loc[1, "impacts"]


def test_a_truncated_impact_table_warns_and_holds_each_contacts_largest(client: chocmodal.Client, bundle: chocmodal.Job) -> None:
    """The same bundle with fewer rows than impacts: the client warns with the counts,
    and each contact's rows are its largest impacts of the complete table."""
    complete = bundle.impacts()
    assert complete.attrs["truncated"] is False
    assert complete.attrs["impacts"] == complete.attrs["tabulated"] == len(complete)
    inputs = bundle_inputs()
    contacts = len(inputs["contacts"])
    max_rows = len(complete) // 2
    assert max_rows > contacts, "the bundle must impact often enough"
    inputs["output"] = {**inputs.get("output", {}), "impacts": {"max_rows": max_rows}}
    job = client.submit("bundle-dynamics", inputs)
    with pytest.warns(chocmodal.QualityWarning):
        job.wait(progress=False, timeout=120)
    summary = job.results()["impact_summary"]
    assert summary["truncated"] is True
    assert (summary["tabulated"], summary["untabulated"]) == (max_rows, len(complete) - max_rows)
    with pytest.warns(chocmodal.TruncatedTableWarning) as caught:
        capped = job.impacts()
    assert (caught[0].message.impacts, caught[0].message.tabulated) == (len(complete), max_rows)
    assert capped.attrs["truncated"] is True and len(capped) == max_rows
    for k, rows in capped.groupby("contact"):
        largest = complete[complete["contact"] == k]["peak_force"].nlargest(len(rows))
        assert sorted(rows["peak_force"]) == sorted(largest), f"contact {k}"
    assert capped["peak_force"].max() == complete["peak_force"].max()
    # The CSV says it too, with pandas' defaults.
    csv = pd.read_csv(job.url("/results/impacts?format=csv"))
    assert csv["truncated"].all() and (csv["impacts"] == len(complete)).all()
    assert (csv["tabulated"] == max_rows).all()


def test_reading_the_impact_table_in_small_pages_gives_the_same_rows(bundle: chocmodal.Job) -> None:
    whole = bundle.impacts()
    paged = bundle.impacts(page_size=7)
    pd.testing.assert_frame_equal(whole, paged)


def test_contact_forces_as_xarray_are_time_by_contact_with_the_contacts_as_coordinates(bundle: chocmodal.Job) -> None:
    inputs = bundle_inputs()
    forces = bundle.to_xarray("contact_forces")
    assert forces.dims == ("time", "contact")
    assert list(forces["contact"].values) == [0, 1, 2]
    assert list(forces["left"].values) == [str(c["left"]) for c in inputs["contacts"]]
    assert forces.attrs["units"] == "N"
    np.testing.assert_array_equal(forces.sel(contact=1).values, bundle.history("contact_forces")["c1"].values)
    deflections = bundle.to_xarray("displacements")
    assert deflections.dims == ("time", "pin", "height")
    assert list(deflections["height"].values) == [inputs["pin"]["length"]], "tips are at the pin length"


def test_the_bending_envelope_is_a_frame_by_height_whose_stress_is_the_moment_over_the_section_modulus(
    bundle: chocmodal.Job,
) -> None:
    envelope = bundle.bending()
    inputs = bundle_inputs()["pin"]
    outer, inner = inputs["section"]["outer_diameter"], inputs["section"]["inner_diameter"]
    inertia = math.pi / 64.0 * (outer**4 - inner**4)
    assert len(envelope) == inputs["elements"] + 1, "one row per mesh node"
    assert envelope.index[0] == 0.0 and abs(envelope.index[-1] - inputs["length"]) < 1e-12
    assert envelope.attrs["units"]["moment"] == "N·m" and envelope.attrs["units"]["stress"] == "Pa"
    # σ = M c / I at the outer fibre, ε = σ / E.
    stress = envelope["moment"] * (outer / 2.0) / inertia
    assert ((envelope["stress"] - stress).abs() <= 1e-9 * stress.abs().max()).all()
    assert ((envelope["strain"] - envelope["stress"] / inputs["young_modulus"]).abs() <= 1e-15).all()
    worst = bundle.results()["max_bending"]
    assert envelope["moment"].max() == worst["moment"]
    assert envelope["moment"].idxmax() == worst["height"]
    assert set(envelope["pin"]) <= {0, 1}


def test_a_dismissed_job_stops_and_waiting_for_it_raises_the_servers_problem(client: chocmodal.Client) -> None:
    inputs = cantilever_inputs()
    inputs["solver"]["duration"] = 60.0  # far longer than this test
    inputs["solver"]["check"] = "none"
    job = client.submit("cantilever-impact", inputs)
    status = job.dismiss()
    assert status["status"] == "dismissed"
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        job.wait(progress=False, timeout=30)
    assert raised.value.kind == "job-dismissed"
    assert job.id in str(raised.value)


def test_results_of_a_job_still_running_are_not_ready(client: chocmodal.Client) -> None:
    inputs = cantilever_inputs()
    inputs["solver"]["duration"] = 50.0
    inputs["solver"]["check"] = "none"
    job = client.submit("cantilever-impact", inputs)
    try:
        with pytest.raises(chocmodal.ChocmodalError) as raised:
            job.results()
        assert raised.value.status == 404 and raised.value.kind == "result-not-ready"
        with pytest.raises(TimeoutError):
            job.wait(progress=False, timeout=0.3)
    finally:
        job.dismiss()


def test_the_job_list_finds_a_submitted_job(client: chocmodal.Client, cantilever: chocmodal.Job) -> None:
    listed = client.jobs(process="cantilever-impact", status="successful", limit=None)
    assert cantilever.id in {job.id for job in listed}
    assert client.job(cantilever.id).status()["processID"] == "cantilever-impact"
