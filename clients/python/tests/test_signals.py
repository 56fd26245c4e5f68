"""Stored signals against the real server: uploads from NumPy, pandas and files, their
metadata, samples, response spectra and deletion.

The record is a sine a(t) = A sin(2π f t) sampled at 200 Hz for a whole number of
cycles, so its expected figures are textbook ones: PGA = A; Arias intensity
π/(2g) · A² T / 2; the pseudo-acceleration spectrum of a long sine peaks at its
frequency with A / (2ξ) (resonance of a damped oscillator), and tends to the PGA at high
frequency (a stiff oscillator follows the ground).
"""

from __future__ import annotations

import math
import uuid
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import chocmodal

AMPLITUDE = 2.0  # m/s²
FREQUENCY = 5.0  # Hz
RATE = 200.0  # Hz
DURATION = 20.0  # s: 100 cycles
G = 9.80665


def sine() -> tuple[np.ndarray, np.ndarray]:
    time = np.arange(int(DURATION * RATE) + 1) / RATE
    return time, AMPLITUDE * np.sin(2 * math.pi * FREQUENCY * time)


def assert_is_the_sine(signal: chocmodal.Signal) -> None:
    m = signal.metadata
    assert m["samples"] == int(DURATION * RATE) + 1
    assert m["duration"] == pytest.approx(DURATION, rel=1e-9)
    assert m["sampling_rate"] == pytest.approx(RATE, rel=1e-9)
    assert m["uniform"] is True
    assert m["pga"] == pytest.approx(AMPLITUDE, rel=1e-9)
    arias = math.pi / (2 * G) * AMPLITUDE**2 * DURATION / 2
    assert m["arias_intensity"] == pytest.approx(arias, rel=0.01)


def test_a_numpy_array_with_its_time_step_uploads_as_the_sine(client: chocmodal.Client) -> None:
    _, acceleration = sine()
    signal = client.upload_signal(acceleration, time_step=1 / RATE)
    assert_is_the_sine(signal)
    samples = signal.samples()
    assert samples.index.name == "time" and samples.attrs["units"]["acceleration"] == "m/s²"
    np.testing.assert_array_equal(samples.to_numpy(), acceleration)


def test_a_pandas_series_indexed_by_time_uploads_bit_for_bit(client: chocmodal.Client) -> None:
    time, acceleration = sine()
    signal = client.upload_signal(pd.Series(acceleration, index=time))
    assert_is_the_sine(signal)
    samples = signal.samples()
    np.testing.assert_array_equal(samples.index.to_numpy(), time)
    np.testing.assert_array_equal(samples.to_numpy(), acceleration)


def test_a_csv_file_uploads_as_the_sine(client: chocmodal.Client, tmp_path: Path) -> None:
    time, acceleration = sine()
    path = tmp_path / "sine.csv"
    path.write_text("time,acceleration\n" + "".join(f"{float(t)!r},{float(a)!r}\n" for t, a in zip(time, acceleration)))
    signal = client.upload_signal(path)
    assert_is_the_sine(signal)
    with open(path, "rb") as handle:
        again = client.upload_signal(handle)
    assert again.metadata["samples"] == signal.metadata["samples"]


def test_the_spectrum_of_a_long_sine_peaks_at_its_frequency_at_a_over_two_xi(client: chocmodal.Client) -> None:
    _, acceleration = sine()
    signal = client.upload_signal(acceleration, sampling_rate=RATE)
    spectrum = signal.spectrum([0.02, 0.05], f_min=1.0, f_max=50.0, points=300)
    assert list(spectrum.columns) == ["psa_0.02", "psa_0.05"]
    assert spectrum.index.name == "frequency"
    assert spectrum.attrs["units"] == {"frequency": "Hz", "psa_0.02": "m/s²", "psa_0.05": "m/s²"}
    frequencies = spectrum.index.to_numpy()
    assert frequencies[0] == pytest.approx(1.0) and frequencies[-1] == pytest.approx(50.0) and len(frequencies) == 300
    assert np.all(np.diff(np.log(frequencies)) > 0)
    for column, xi in spectrum.attrs["damping"].items():
        peak_at = spectrum[column].idxmax()
        assert peak_at == pytest.approx(FREQUENCY, rel=0.03), column
        assert spectrum[column].max() == pytest.approx(AMPLITUDE / (2 * xi), rel=0.1), column
    assert spectrum["psa_0.02"].max() > spectrum["psa_0.05"].max(), "less damping, higher resonance"
    assert spectrum["psa_0.05"].iloc[-1] == pytest.approx(AMPLITUDE, rel=0.05), "a stiff oscillator follows the ground"
    assert spectrum.attrs["pga"] == pytest.approx(AMPLITUDE, rel=1e-9)


def test_signals_are_listed_fetched_and_deleted(client: chocmodal.Client) -> None:
    signal = client.upload_signal(np.array([0.0, 1.0, -1.0, 0.5]), time_step=0.01)
    assert signal.id in {s.id for s in client.signals(limit=None)}
    assert client.signal(signal.id).metadata["samples"] == 4
    signal.delete()
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.signal(signal.id)
    assert raised.value.status == 404 and raised.value.kind == "no-such-signal"
    assert signal.id not in {s.id for s in client.signals(limit=None)}


def test_an_upload_retried_with_its_key_is_the_same_signal(client: chocmodal.Client) -> None:
    key = str(uuid.uuid4())
    record = np.array([0.0, 0.25, -0.5, 0.0])
    first = client.upload_signal(record, time_step=0.005, idempotency_key=key)
    again = client.upload_signal(record, time_step=0.005, idempotency_key=key)
    assert again.id == first.id and again.replayed and not first.replayed


def test_a_record_with_a_nan_is_refused_before_it_is_sent(client: chocmodal.Client) -> None:
    with pytest.raises(ValueError, match=r"acceleration\[2\]"):
        client.upload_signal(np.array([0.0, 1.0, np.nan]), time_step=0.01)
    with pytest.raises(ValueError, match="exactly one"):
        client.upload_signal(np.array([0.0, 1.0]))


def test_a_file_whose_times_go_back_is_refused_by_the_server_at_its_line(client: chocmodal.Client, tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("time,acceleration\n0.0,0.0\n0.01,1.0\n0.005,2.0\n")
    with pytest.raises(chocmodal.ChocmodalError) as raised:
        client.upload_signal(path)
    assert raised.value.status == 422 and raised.value.kind == "invalid-signal"
    assert raised.value.errors, "the refused samples have pointers"
    assert "line 4" in str(raised.value)


def test_a_job_can_replay_a_stored_signal(client: chocmodal.Client) -> None:
    time = np.arange(0, 0.05, 1e-3)
    signal = client.upload_signal(pd.Series(5.0 * np.sin(2 * math.pi * 20 * time), index=time))
    inputs = {
        "pin": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085}},
        "bundle": {"pins": 2, "levels": [1.0], "stiffness": 1e6, "damping": 20.0, "wall_gap": 1e-3, "pin_gap": 1e-3},
        "excitation": {"base_acceleration": signal.reference(scale=2.0)},
        "solver": {"duration": 0.05, "check": "none"},
    }
    job = client.submit("bundle-dynamics", inputs)
    with pytest.warns(chocmodal.QualityWarning):  # a coarse model, and no step-halving check
        results = job.wait(progress=False, timeout=120)
    assert job.inputs()["excitation"]["base_acceleration"] == {"type": "signal", "id": signal.id, "scale": 2.0}
    assert results["quality"]["verdict"] != "good"


def test_a_signal_a_queued_or_running_job_refers_to_cannot_be_deleted(client: chocmodal.Client) -> None:
    signal = client.upload_signal(np.array([0.0, 1.0, 0.0, -1.0, 0.0]), time_step=0.01)
    inputs = {
        "pin": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085}},
        "bundle": {"pins": 2, "levels": [1.0], "stiffness": 1e6, "damping": 20.0, "wall_gap": 1e-3, "pin_gap": 1e-3},
        "excitation": {"base_acceleration": signal.reference()},
        "solver": {"duration": 60.0, "check": "none"},  # far longer than this test
    }
    job = client.submit("bundle-dynamics", inputs)
    try:
        with pytest.raises(chocmodal.ChocmodalError) as raised:
            signal.delete()
        assert raised.value.status == 409 and raised.value.kind == "signal-in-use"
    finally:
        job.dismiss()
    signal.delete()


def test_a_record_in_g_from_an_at2_file_or_an_array_is_stored_in_metres_per_second_squared(
    client: chocmodal.Client, tmp_path: Path
) -> None:
    # The sine in g, as a PEER AT2 file (NGA-West2 layout, 5 values to a line) and as an
    # array with unit="g": both come back in m/s², the PGA the amplitude.
    _, acceleration = sine()
    in_g = acceleration / G
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", "Test sine, 1/1/2000, Station, 000",
             "ACCELERATION TIME SERIES IN UNITS OF G", f"NPTS= {len(in_g):5d}, DT=   {1 / RATE:.4f} SEC"]
    lines += ["".join(f"{a:16.8E}" for a in in_g[k:k + 5]) for k in range(0, len(in_g), 5)]
    path = tmp_path / "sine.AT2"
    path.write_text("\n".join(lines) + "\n")
    for signal in (client.upload_signal(path), client.upload_signal(in_g, time_step=1 / RATE, unit="g")):
        m = signal.metadata
        assert m["samples"] == len(in_g)
        assert m["duration"] == pytest.approx(DURATION, rel=1e-9)
        assert m["pga"] == pytest.approx(AMPLITUDE, rel=1e-7)
    with pytest.raises(chocmodal.ChocmodalError) as refused:
        client.upload_signal(path, unit="m/s2")
    assert "/unit" in str(refused.value)


def test_a_synthetic_earthquake_is_an_output_whose_spectrum_meets_its_target(client: chocmodal.Client) -> None:
    target = {"frequencies": [1.0, 2.5, 6.67, 20.0], "accelerations": [3.0, 7.5, 7.5, 4.5], "damping": 0.05}
    inputs = {
        "pin": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085}},
        "bundle": {"pins": 2, "levels": [1.0], "stiffness": 1e6, "damping": 20.0, "wall_gap": 1e-3, "pin_gap": 1e-3},
        "excitation": {"base_acceleration": {"type": "spectrum_compatible", "target": target,
                                             "duration": 8.0, "strong_motion": 4.0, "seed": 3}},
        "solver": {"duration": 0.2, "check": "none"},
    }
    job = client.submit("bundle-dynamics", inputs)
    with pytest.warns(chocmodal.QualityWarning):  # unchecked, and the run ends before the record
        results = job.wait(progress=False, timeout=120)
    (generated,) = results["generated_records"]
    assert generated["member"] == "base_acceleration" and generated["seed"] == 3

    record = job.history("excitation")
    assert list(record.columns) == ["base_acceleration"]
    assert record.attrs["units"]["base_acceleration"] == "m/s²"
    # The whole record, past the run's 0.2 s: its samples and their peak.
    assert record.index[-1] == pytest.approx(generated["duration"])
    assert record["base_acceleration"].abs().max() == generated["peak_acceleration"]

    spectrum = job.response_spectrum("excitation", series="base_acceleration")
    assert list(spectrum.columns) == ["psa_0.05", "target"]
    assert spectrum.index[0] == 1.0 and spectrum.index[-1] == 20.0
    deviation = (spectrum["psa_0.05"] / spectrum["target"] - 1.0).abs()
    assert deviation.max() == pytest.approx(spectrum.attrs["max_deviation"], rel=1e-12)
    assert spectrum.attrs["max_deviation"] <= spectrum.attrs["tolerance"] == 0.1
