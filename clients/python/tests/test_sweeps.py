"""Sweeps against the real server: created from axes (or a whole request file), followed
to the end, their results table and aggregates as DataFrames.

Expected values come from the sweep contract: list axes span the grid with the last axis
varying fastest; random axes draw ``samples`` points; aggregates are count, mean, std
(n − 1), min, max and quantiles of the table's columns over the successful runs, which
this test recomputes from the table with pandas.
"""

from __future__ import annotations

import copy
import math
import uuid
from typing import TYPE_CHECKING, Optional

import numpy as np
import pytest

import chocmodal
from chocmodal import axes
from conftest import example

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd


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


def _wilks_rank(runs: int, coverage: float, confidence: float) -> Optional[int]:
    """The tightest rank from the top whose value bounds the ``coverage`` quantile with
    ``confidence``: the largest r with P(Binomial(runs, 1 − coverage) ≥ r) ≥ confidence."""
    best = None
    for r in range(1, runs + 1):
        below = sum(math.comb(runs, j) * (1 - coverage) ** j * coverage ** (runs - j) for j in range(r))
        if 1 - below < confidence:
            break
        best = r
    return best


def _assert_statistics(row: "pd.Series", values: "np.ndarray", coverage: float, confidence: float) -> None:
    ordered = np.sort(values.astype(float))
    assert row["count"] == len(ordered)
    assert row["mean"] == pytest.approx(ordered.mean(), rel=1e-12)
    assert row["min"] == ordered[0] and row["max"] == ordered[-1]
    assert row["quantile"] == pytest.approx(float(np.quantile(ordered, coverage, method="linear")), rel=1e-12)
    rank = _wilks_rank(len(ordered), coverage, confidence)
    if rank is None:
        assert np.isnan(row["bound"]) and np.isnan(row["bound_rank"])
    else:
        assert row["bound_rank"] == rank
        assert row["bound"] == ordered[len(ordered) - rank]


def test_each_contacts_statistics_are_those_of_the_member_jobs_contact_tables(
    client: chocmodal.Client, monte_carlo: chocmodal.Sweep
) -> None:
    # 16 runs at 80 %/80 %: a bound exists (1 − 0.8^16 ≥ 0.8) at the rank the binomial gives.
    coverage, confidence = 0.8, 0.8
    contacts = monte_carlo.contact_statistics(coverage=coverage, confidence=confidence)
    assert contacts.index.names == ["contact", "figure"]
    tables = [client.job(job).contacts() for job in monte_carlo.results()["job"]]
    for k in tables[0].index:
        for figure in ("max_force", "impacts", "impulse", "gap"):
            values = np.array([table.loc[k, figure] for table in tables])
            _assert_statistics(contacts.loc[(k, figure)], values, coverage, confidence)
    only = monte_carlo.contact_statistics(["max_force"])
    assert set(only.index.get_level_values("figure")) == {"max_force"}


def test_each_pins_statistics_are_those_of_the_member_jobs_pins(
    client: chocmodal.Client, monte_carlo: chocmodal.Sweep
) -> None:
    pins = monte_carlo.pin_statistics(["max_abs_deflection"])
    documents = [client.job(job).results() for job in monte_carlo.results()["job"]]
    for p in range(len(documents[0]["pins"])):
        values = np.array([d["pins"][p]["max_abs_deflection"] for d in documents])
        _assert_statistics(pins.loc[(p, "max_abs_deflection")], values, 0.95, 0.95)


def test_the_convergence_of_a_figure_follows_the_runs_in_draw_order(monte_carlo: chocmodal.Sweep) -> None:
    table = monte_carlo.results()
    track = monte_carlo.convergence("max_contact_force.force", coverage=0.9, confidence=0.5)
    assert list(track.index) == list(range(len(table)))
    values = table["max_contact_force.force"].astype(float).to_numpy()
    for n, (_, step) in enumerate(track.iterrows(), start=1):
        assert step["value"] == values[n - 1]
        assert step["quantile"] == pytest.approx(float(np.quantile(values[:n], 0.9, method="linear")), rel=1e-12)
        rank = _wilks_rank(n, 0.9, 0.5)
        assert (np.isnan(step["bound_rank"]) if rank is None else step["bound_rank"] == rank), (n, step)


def test_a_bound_outside_zero_to_one_is_refused_naming_the_parameter(monte_carlo: chocmodal.Sweep) -> None:
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        monte_carlo.figure_statistics(coverage=1.0)
    assert raised.value.status == 400
    assert "`coverage`" in str(raised.value)
    runs = monte_carlo.figure_statistics(coverage=0.99, confidence=0.95)
    assert (runs["runs_needed"] == math.ceil(math.log(0.05) / math.log(0.99))).all(), "no bound from 16 runs"
