"""Sweeps against the real server: created from axes (or a whole request file), followed
to the end, their results table and aggregates as DataFrames.

Expected values come from the sweep contract: list axes span the grid with the last axis
varying fastest; random axes draw ``samples`` points; aggregates are count, mean, std
(n − 1), min, max and quantiles of the table's columns over the successful runs, which
this test recomputes from the table with pandas.
"""

from __future__ import annotations

import copy
import uuid

import numpy as np
import pytest

import chocmodal
from chocmodal import axes
from conftest import example


@pytest.fixture(scope="module")
def monte_carlo(client: chocmodal.Client) -> chocmodal.Sweep:
    sweep = client.submit_sweep_request(example("sweep-gaps.json"))
    sweep.follow(progress=False, timeout=180)
    return sweep


@pytest.fixture(scope="module")
def grid(client: chocmodal.Client) -> chocmodal.Sweep:
    inputs = copy.deepcopy(example("cantilever-impact.json")["inputs"])
    inputs["solver"]["duration"] = 0.05
    # 0.1 ms is above the critical step: those runs are recorded as failed, not refused.
    sweep = client.submit_sweep(
        "cantilever-impact",
        inputs,
        [axes.linspace("/contact/rk", 1.0, 100.0, 2), axes.values("/solver/time_step", [1e-5, 2e-5, 1e-4])],
        invalid_runs="record",
    )
    sweep.follow(progress=False, timeout=180)
    return sweep


def test_a_monte_carlo_sweep_runs_every_sample_and_tabulates_one_row_per_run(monte_carlo: chocmodal.Sweep) -> None:
    request = example("sweep-gaps.json")
    status = monte_carlo.status()
    assert status["status"] == "successful"
    assert status["runs"] == request["samples"]
    assert status["counts"]["successful"] == request["samples"]
    table = monte_carlo.results()
    assert table.index.name == "run"
    assert list(table.index) == list(range(request["samples"]))
    assert set(table["status"]) == {"successful"}
    seeds = table["/bundle/gaps/seed"]
    assert seeds.dtype.kind == "i", "seeds are integers"
    low, high = request["axes"][0]["uniform"]
    assert seeds.between(low, high).all()
    assert seeds.nunique() == len(seeds)
    assert {"max_contact_force.force", "quality.verdict", "contacts.0.max_force"} <= set(table.columns)


def test_monte_carlo_statistics_are_those_of_the_results_table(monte_carlo: chocmodal.Sweep) -> None:
    table = monte_carlo.results()
    statistics = monte_carlo.statistics()
    assert statistics.index.names == ["metric"], "one cell: no list axis"
    assert list(statistics.columns) == [
        "count", "mean", "std", "min", "max", "q05", "q50", "q95", "bound_95_95", "bound_95_95_rank"]
    assert not any(name.endswith("seed") for name in statistics.index), "seeds name draws, not metrics"
    for metric in ("max_contact_force.force", "impacts", "contacts.1.max_force"):
        values = table[metric].astype(float)
        row = statistics.loc[metric]
        assert row["count"] == len(values)
        assert row["mean"] == pytest.approx(values.mean(), rel=1e-12)
        assert row["std"] == pytest.approx(values.std(ddof=1), rel=1e-9)
        assert row["min"] == values.min() and row["max"] == values.max()
        for q in (0.05, 0.5, 0.95):
            expected = float(np.quantile(values.to_numpy(), q, method="linear"))
            assert row[f"q{round(q * 100):02d}"] == pytest.approx(expected, rel=1e-12), (metric, q)


def test_the_quality_counts_add_up_to_the_successful_runs(monte_carlo: chocmodal.Sweep) -> None:
    counts = monte_carlo.quality_counts()
    total = counts.loc[("all", "")]
    assert total["runs"] == monte_carlo.status()["counts"]["successful"]
    assert total[["good", "unchecked", "doubtful", "poor"]].sum() == total["runs"]
    verdicts = monte_carlo.results()["quality.verdict"].value_counts()
    for verdict in ("good", "unchecked", "doubtful", "poor"):
        assert total[verdict] == verdicts.get(verdict, 0)


def test_a_grid_from_axes_spans_the_product_with_the_last_axis_fastest(grid: chocmodal.Sweep) -> None:
    table = grid.results()
    assert len(table) == 6
    expected = [(rk, dt) for rk in (1.0, 100.0) for dt in (1e-5, 2e-5, 1e-4)]
    assert list(zip(table["/contact/rk"], table["/solver/time_step"])) == expected
    failed = table["status"] == "failed"
    assert list(table.index[failed]) == [2, 5], "the runs above the critical step"
    assert grid.status()["status"] == "partial"
    assert grid.status()["counts"]["failed"] == 2


def test_waiting_for_a_failed_run_raises_its_problem(client: chocmodal.Client, grid: chocmodal.Sweep) -> None:
    table = grid.results()
    job = client.job(table.loc[2, "job"])
    assert job.status()["status"] == "failed"
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        job.wait(progress=False, timeout=30)
    assert raised.value.status == 422
    assert "/inputs/solver/time_step" in str(raised.value)


def test_the_calibration_map_marks_runs_valid_below_the_f_err_threshold(grid: chocmodal.Sweep) -> None:
    table = grid.results()
    calibration = grid.calibration()
    threshold = calibration.attrs["threshold"]
    assert threshold == 0.2
    assert list(calibration.index) == list(table.index)
    for run, cell in calibration.iterrows():
        if table.loc[run, "status"] == "failed":
            assert not cell["valid"], "a failed run is not valid"
            continue
        assert cell["f_err"] == table.loc[run, "comparison.f_err"]
        assert bool(cell["valid"]) == (cell["f_err"] < threshold)
    cheapest = grid.cheapest()
    assert set(cheapest["axis"]) == {"/solver/time_step"}
    for _, choice in cheapest.iterrows():
        runs = calibration[(calibration["/contact/rk"] == choice["/contact/rk"]) & calibration["valid"]]
        assert choice["value"] == runs["/solver/time_step"].max(), "the largest valid step"


def test_the_runs_of_a_sweep_are_jobs(grid: chocmodal.Sweep) -> None:
    jobs = grid.jobs()
    assert sorted(job.id for job in jobs) == sorted(grid.results()["job"])


def test_an_axis_naming_no_input_is_refused_at_its_pointer(client: chocmodal.Client) -> None:
    inputs = example("cantilever-impact.json")["inputs"]
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.submit_sweep("cantilever-impact", inputs, [axes.values("/contact/rkk", [1.0, 2.0])])
    assert raised.value.status == 422
    assert "/axes/0/pointer" in str(raised.value)
    assert "rkk" in str(raised.value)


def test_a_sweep_resubmitted_with_its_key_is_the_same_sweep_and_can_be_dismissed(client: chocmodal.Client) -> None:
    inputs = copy.deepcopy(example("cantilever-impact.json")["inputs"])
    inputs["solver"]["duration"] = 40.0  # runs far longer than this test
    inputs["output"] = {"interval": 1e-3}
    inputs["solver"]["check"] = "none"
    key = str(uuid.uuid4())
    axis = [axes.values("/contact/rk", [1.0, 2.0, 3.0])]
    sweep = client.submit_sweep("cantilever-impact", inputs, axis, idempotency_key=key)
    again = client.submit_sweep("cantilever-impact", inputs, axis, idempotency_key=key)
    assert again.id == sweep.id and again.replayed
    status = sweep.dismiss()
    assert status["status"] == "dismissed"
    assert sweep.follow(progress=False, timeout=30)["status"] == "dismissed"
