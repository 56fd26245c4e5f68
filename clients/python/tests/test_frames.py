"""The CSV readers on their own (no server): the long header and exact numbers."""

from __future__ import annotations

import numpy as np

from chocmodal import frames

LONG = (
    'time [s] time from the start of the run,'
    '"numerical [m] tip deflection w(L), positive away from the spring, the numerical (modal) scheme",'
    'c12 [N] contact wall–p0 at 0.18 m\n'
    "0.0,0.0010000000000000002,0.0\n"
    "0.00030000000000000003,-6.7e-4,1e-7\n"
)


def test_a_long_header_gives_names_units_and_descriptions_even_with_commas() -> None:
    frame = frames.history_frame(LONG, output="demo")
    assert list(frame.columns) == ["numerical", "c12"]
    assert frame.index.name == "time"
    assert frame.attrs["units"] == {"time": "s", "numerical": "m", "c12": "N"}
    assert frame.attrs["descriptions"]["numerical"].startswith("tip deflection w(L), positive away")
    assert frame.attrs["descriptions"]["c12"] == "contact wall–p0 at 0.18 m"


def test_numbers_read_back_as_the_same_doubles() -> None:
    frame = frames.history_frame(LONG, output="demo")
    assert frame.index[1] == 0.00030000000000000003 and frame.index[1] != 0.0003
    assert frame["numerical"].iloc[0] == 0.0010000000000000002
    values = np.random.default_rng(7).standard_normal(2000) * 10.0 ** np.random.default_rng(8).uniform(-300, 300, 2000)
    text = "time [s] t,v [N] v\n" + "".join(f"{i},{float(v)!r}\n" for i, v in enumerate(values))
    np.testing.assert_array_equal(frames.history_frame(text, output="v")["v"].to_numpy(), values)


def test_an_empty_impact_table_still_has_its_columns_and_units() -> None:
    table = frames.impacts_frame([])
    assert list(table.columns) == list(frames.IMPACT_UNITS)
    assert table.empty and table.attrs["units"]["impulse"] == "N·s"


def test_a_pins_utilisations_are_dimensionless_and_its_stress_in_pascals() -> None:
    pins = [{"pin": 0, "max_abs_deflection": 1e-3, "bending": {"stress": 2e7, "moment": 1.0},
             "stress_utilisation": 0.1, "contact_utilisation": 0.9, "utilisation": 0.9},
            {"pin": 1, "max_abs_deflection": 2e-3, "bending": {"stress": 4e7, "moment": 2.0},
             "stress_utilisation": 0.2, "contact_utilisation": None, "utilisation": 0.2}]
    frame = frames.pins_frame(pins)
    units = frame.attrs["units"]
    assert units["utilisation"] == units["stress_utilisation"] == units["contact_utilisation"] == "1"
    assert units["bending.stress"] == "Pa"
    assert frame.loc[1, "utilisation"] == 0.2 and np.isnan(frame.loc[1, "contact_utilisation"])
