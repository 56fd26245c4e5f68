"""The service's CSV and JSON tables as pandas DataFrames, with their units.

Every frame made here keeps ``df.attrs["units"]``: a dict from column (and index) name
to its SI unit (``"N"``, ``"m"``, ``"s"``, ``"1"`` for counts and ratios). A history's
units and descriptions come from the service itself (the ``header=long`` CSV header,
``c12 [N] contact wall–p0 at 0.18 m``); the units of the results' tables (contacts,
pins, impacts) are the ones the service documents (docs/service.md, docs/impacts.md).
"""

from __future__ import annotations

import csv
import io
import re
from typing import Any, Iterable, Mapping, Optional, Sequence

import pandas as pd

__all__ = [
    "history_frame",
    "contacts_frame",
    "contact_table_frame",
    "pins_frame",
    "resultant_table_frame",
    "impacts_frame",
    "spectrum_frame",
    "table_frame",
    "IMPACT_UNITS",
    "CONTACT_UNITS",
]

# pandas 3 reads every double back exactly by default (and deprecates the option);
# older versions need the round-trip parser for that.
_EXACT: dict[str, Any] = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}

# `c12 [N] contact wall–p0 at 0.18 m`: the name, its unit in brackets, what it measures.
_LONG_HEADER = re.compile(r"^(\S+)\s+\[([^\]]*)\]\s*(.*)$")

#: Units of the per-impact table's columns (docs/impacts.md).
IMPACT_UNITS: dict[str, str] = {
    "contact": "1",
    "start": "s",
    "peak_time": "s",
    "peak_force": "N",
    "impulse": "N·s",
    "duration": "s",
    "approach_velocity": "m/s",
    "rebounds": "1",
    "dissipated": "J",
    "energy": "J",
}

#: Units of the members of a results document's ``contacts`` entries, by the last
#: segment of their dotted name (``impact_statistics.rms_force`` → ``rms_force``):
#: docs/service.md, docs/impacts.md, docs/hex-bundle.md.
CONTACT_UNITS: dict[str, str] = {
    "contact": "1",
    "height": "m",
    "gap": "m",
    "stiffness": "N/m",
    "damping": "N·s/m",
    "max_force": "N",
    "max_force_time": "s",
    "first_impact_time": "s",
    "impacts": "1",
    "contact_time": "s",
    "impulse": "N·s",
    "max_penetration": "m",
    "wear_work_rate": "W",
    "level": "1",
    "impacts_per_second": "1/s",
    "contact_fraction": "1",
    "mean_force": "N",
    "rms_force": "N",
    "mean_contact_force": "N",
    "rms_contact_force": "N",
    "loaded_time": "s",
    "mean_duration": "s",
    "min_duration": "s",
    "max_duration": "s",
    "rebounds_per_impact": "1",
    "mean_impact_energy": "J",
    "max_impact_energy": "J",
    # Contact laws (docs/contact-laws.md): the law's members, utilisation, friction, wear.
    "exponent": "1",
    "hunt_crossley": "s/m",
    "restitution": "1",
    "restitution_speed": "m/s",
    "restitution_mass": "kg",
    "force_scale": "N",
    "allowable_force": "N",
    "tangential_stiffness": "N/m",
    "utilisation": "1",
    "mean_tangential_force": "N",
    "rms_tangential_force": "N",
    "max_tangential_force": "N",
    "slip_distance": "m",
    "stick_fraction": "1",
    "wear_power": "W",
    "power": "W",
    "volume": "m³",
    "depth": "m",
}

#: Units of the members of a results document's ``pins`` entries.
PIN_UNITS: dict[str, str] = {
    "pin": "1",
    "height": "m",
    "max_abs_deflection": "m",
    "max_deflection": "m",
    "deflection": "m",
    "time": "s",
    "moment": "N·m",
    "stress": "Pa",
    "strain": "1",
    # Margins (docs/margins.md): utilisations against `output.allowables`.
    "stress_utilisation": "1",
    "contact_utilisation": "1",
    "utilisation": "1",
    # The resultant contact force on a pin at a contact height (docs/bending.md).
    "contacts": "1",
    "max_force": "N",
}


def bending_frame(envelope: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    """The results' ``bending_envelope`` (per mesh node: the largest bending over every
    pin and sample, which pin and when) indexed by ``height`` (m)."""
    columns = ["height", "pin", "time", "moment", "stress", "strain"]
    frame = pd.DataFrame([dict(e) for e in envelope], columns=columns).set_index("height")
    frame[["stress", "strain"]] = frame[["stress", "strain"]].astype(float)
    frame.attrs["units"] = {c: PIN_UNITS[c] for c in columns}
    return frame


def parse_long_header(cells: Sequence[str]) -> tuple[list[str], dict[str, str], dict[str, str]]:
    """Names, units and descriptions of a ``header=long`` CSV header."""
    names: list[str] = []
    units: dict[str, str] = {}
    descriptions: dict[str, str] = {}
    for cell in cells:
        match = _LONG_HEADER.match(cell.strip())
        if match is None:
            name = cell.strip().split(" ", 1)[0]
            names.append(name)
            continue
        name, unit, description = match.groups()
        names.append(name)
        units[name] = unit
        if description:
            descriptions[name] = description
    return names, units, descriptions


def history_frame(text: str, *, output: str, job_id: Optional[str] = None) -> pd.DataFrame:
    """A history's CSV (``format=csv&header=long``) as a DataFrame indexed by ``time`` (s),
    one float column per series, ``attrs["units"]`` and ``attrs["descriptions"]`` from
    the header. Numbers are read back exactly (the service writes the shortest text
    that reads back as the same double)."""
    header_line, _, body = text.partition("\n")
    cells = next(csv.reader([header_line]))
    names, units, descriptions = parse_long_header(cells)
    if not names or names[0] != "time":
        raise ValueError(f"history {output!r}: the CSV does not start with a time column: {header_line[:200]!r}")
    frame = pd.read_csv(
        io.StringIO(body),
        header=None,
        names=names,
        dtype="float64",
        **_EXACT,
    )
    frame = pd.DataFrame(frame.set_index("time"))
    frame.columns.name = output
    frame.attrs["output"] = output
    if job_id is not None:
        frame.attrs["job"] = job_id
    frame.attrs["units"] = units
    frame.attrs["descriptions"] = descriptions
    return frame


def _units_by_last_segment(columns: Iterable[str], table: Mapping[str, str]) -> dict[str, str]:
    units: dict[str, str] = {}
    for column in columns:
        unit = table.get(str(column).rsplit(".", 1)[-1])
        if unit is not None:
            units[str(column)] = unit
    return units


def contacts_frame(contacts: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    """The results' ``contacts`` (one entry per contact, in input order) as a DataFrame
    indexed by ``contact`` (the k of history column ``c<k>``); nested members flattened
    with dots (``impact_statistics.rms_force``), lists (histograms) kept as objects."""
    frame = pd.json_normalize([dict(c) for c in contacts], sep=".")
    frame.index = pd.RangeIndex(len(frame), name="contact")
    frame.attrs["units"] = _units_by_last_segment(["contact", *frame.columns], CONTACT_UNITS)
    return frame


def contact_table_frame(text: str) -> pd.DataFrame:
    """The service's per-contact statistics table (``/jobs/{jobId}/results/contacts``,
    CSV) as a DataFrame indexed by ``contact``, the columns as the service names them
    (``max_force``, ``impact_statistics.rms_force``); a body named by its pin number reads
    as that number, a wall as ``"wall"``."""
    frame = pd.read_csv(io.StringIO(text), index_col="contact")
    for name in ("left", "right"):
        if name in frame.columns:
            frame[name] = [int(v) if str(v).lstrip("-").isdigit() else v for v in frame[name]]
    frame.attrs["units"] = _units_by_last_segment(["contact", *frame.columns], CONTACT_UNITS)
    return frame


def resultant_table_frame(text: str) -> pd.DataFrame:
    """The service's resultant contact forces (``/jobs/{jobId}/results/resultants``, CSV)
    indexed by (``pin``, ``height``): ``contacts`` acting there, ``max_force`` (N), ``time`` (s)."""
    frame = pd.read_csv(io.StringIO(text), index_col=["pin", "height"], **_EXACT)
    frame.attrs["units"] = {c: PIN_UNITS[c] for c in ["pin", "height", *frame.columns]}
    return frame


def pins_frame(pins: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    """The results' ``pins`` (per pin: largest |deflection|, where and when) indexed by
    ``pin``; the per-height resultant contact forces are :func:`resultant_table_frame`'s."""
    frame = pd.json_normalize([{k: v for k, v in p.items() if k != "resultant_forces"} for p in pins], sep=".")
    if "pin" in frame.columns:
        frame = frame.set_index("pin")
    else:
        frame.index = pd.RangeIndex(len(frame), name="pin")
    frame.attrs["units"] = _units_by_last_segment(["pin", *frame.columns], PIN_UNITS)
    return frame


def impacts_frame(rows: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    """Rows of the per-impact table (sorted by start, then contact) as a DataFrame."""
    columns = list(IMPACT_UNITS)
    frame = pd.DataFrame(list(rows))
    if frame.empty:
        frame = pd.DataFrame({c: pd.Series(dtype="int64" if c in ("contact", "rebounds") else "float64") for c in columns})
    extra = [c for c in frame.columns if c not in IMPACT_UNITS]
    frame = frame[[c for c in columns if c in frame.columns] + extra]
    frame.index.name = "impact"
    frame.attrs["units"] = {c: IMPACT_UNITS[c] for c in frame.columns if c in IMPACT_UNITS}
    return frame


def spectrum_frame(
    frequencies: Sequence[float],
    spectra: Sequence[Mapping[str, Any]],
    *,
    unit: str = "m/s²",
) -> pd.DataFrame:
    """A response spectrum (``{"frequencies", "pseudo_acceleration": [{"damping",
    "values"}]}``) indexed by ``frequency`` (Hz), one column per damping ratio named as
    in the service's CSV (``psa_0.05``); ``attrs["damping"]`` maps column to ratio."""
    data: dict[str, Any] = {}
    damping: dict[str, float] = {}
    for spectrum in spectra:
        ratio = float(spectrum["damping"])
        name = f"psa_{_short(ratio)}"
        data[name] = list(spectrum["values"])
        damping[name] = ratio
    frame = pd.DataFrame(data, index=pd.Index(list(frequencies), name="frequency", dtype="float64"))
    frame.attrs["units"] = {"frequency": "Hz", **{name: unit for name in data}}
    frame.attrs["damping"] = damping
    return frame


def table_frame(text: str, *, index: Optional[str] = None) -> pd.DataFrame:
    """A CSV table of the service (sweep results, ...), numbers read back exactly,
    empty cells as missing values."""
    frame = pd.DataFrame(pd.read_csv(io.StringIO(text), **_EXACT))
    if index is not None and index in frame.columns:
        frame = pd.DataFrame(frame.set_index(index))
    return frame


def _short(value: float) -> str:
    """The shortest text of a number (``0.05``, not ``0.05000``), as the service writes it."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text
