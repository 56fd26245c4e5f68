//! What a calculation note (`GET /jobs/{jobId}/report`, `chocmodal run --report`) reads
//! of a results document: the run's peaks with where and when, its margins, each
//! contact's and each pin's figures, the bending envelope along the height, and which
//! histories to plot. A process says where these are in its document
//! ([`super::Simulation::note`]); the readers here are shared, so the note itself is
//! drawn once for every process (`src/calculation_note/`).
//!
//! Every figure is a [`Figure`]: the value as the document has it, its unit and the JSON
//! pointer of the member it comes from, so that a note can say where each of its numbers
//! comes from (and a test can check each against the document).

use serde_json::Value;

/// The unit of a figure, and how a note shows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Force (N).
    Newton,
    /// Impulse (N·s).
    NewtonSecond,
    /// Bending moment (N·m).
    NewtonMetre,
    /// Stress (Pa), shown in MPa.
    Pascal,
    /// A height or a length (m).
    Metre,
    /// A deflection (m), shown in mm.
    Deflection,
    /// Time (s).
    Second,
    /// Frequency (Hz).
    Hertz,
    /// A count (impacts, steps).
    Count,
    /// A ratio (utilisation, relative error, strain).
    Dimensionless,
}

impl Unit {
    /// The factor from the SI value to the shown one, and the unit shown.
    pub fn shown(self) -> (f64, &'static str) {
        match self {
            Unit::Newton => (1.0, "N"),
            Unit::NewtonSecond => (1.0, "N·s"),
            Unit::NewtonMetre => (1.0, "N·m"),
            Unit::Pascal => (1e-6, "MPa"),
            Unit::Metre => (1.0, "m"),
            Unit::Deflection => (1e3, "mm"),
            Unit::Second => (1.0, "s"),
            Unit::Hertz => (1.0, "Hz"),
            Unit::Count | Unit::Dimensionless => (1.0, ""),
        }
    }
}

/// One number of the results document.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// As the document has it (SI units).
    pub value: f64,
    pub unit: Unit,
    /// The member it comes from (`/max_contact_force/force`).
    pub pointer: String,
}

impl Figure {
    /// The number at `pointer` of `document`, if there is one (null members have none).
    pub fn at(document: &Value, pointer: impl Into<String>, unit: Unit) -> Option<Figure> {
        let pointer = pointer.into();
        let value = document.pointer(&pointer)?.as_f64()?;
        Some(Figure { value, unit, pointer })
    }
}

/// A named figure with where and when: a row of the note's peaks, margins or checks.
#[derive(Debug, Clone, PartialEq)]
pub struct Fact {
    /// What it is (`largest contact force`).
    pub quantity: String,
    pub figure: Figure,
    /// When, if the document says.
    pub time: Option<Figure>,
    /// Where, in words (`contact p3–p4 at 0.9 m`); empty when it is the whole run's.
    pub location: String,
}

/// One contact's row of the note: its largest force and its impacts.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRow {
    /// Its index (the history column `c<k>`).
    pub contact: usize,
    /// What it is (`contact wall–p0 at 0.18 m`).
    pub label: String,
    pub max_force: Figure,
    pub max_force_time: Option<Figure>,
    pub impacts: Option<Figure>,
    pub impulse: Option<Figure>,
    pub allowable_force: Option<Figure>,
    pub utilisation: Option<Figure>,
}

/// One pin's row of the note: its largest deflection and bending, its utilisation.
#[derive(Debug, Clone, PartialEq)]
pub struct PinRow {
    pub pin: usize,
    pub deflection: Option<Figure>,
    pub deflection_height: Option<Figure>,
    pub deflection_time: Option<Figure>,
    /// Its largest outer-fibre stress (Pa), or its moment (N·m) when the section has no
    /// outer fibre (`explicit` without a diameter).
    pub bending: Option<Figure>,
    pub bending_height: Option<Figure>,
    pub bending_time: Option<Figure>,
    pub utilisation: Option<Figure>,
}

/// The bending envelope along the height: one point per mesh node, from the foot.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    /// The heights (m).
    pub heights: Vec<f64>,
    /// The largest stress (Pa) at each, or the moment (N·m) when stresses are null.
    pub values: Vec<f64>,
    pub unit: Unit,
    /// The document's array (`/bending_envelope`).
    pub pointer: String,
}

/// A history worth plotting in the note.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotRequest {
    /// The figure's caption (`force of c12, contact p3–p4 at 0.9 m`).
    pub title: String,
    /// The history (`contact_forces_peaks`).
    pub output: String,
    /// Its columns to draw (`c12`), in order.
    pub series: Vec<String>,
    /// The unit of the values.
    pub unit: Unit,
    /// The reported peak the curve must reach, marked on the plot: (time, value).
    pub peak: Option<(Figure, Figure)>,
}

/// Everything a calculation note reads of one results document.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NoteFacts {
    /// The run's peaks: contact force, deflection, bending moment and stress.
    pub peaks: Vec<Fact>,
    /// Utilisations (docs/margins.md); empty without allowables.
    pub margins: Vec<Fact>,
    /// What the process checks besides (the cantilever's agreement with its reference).
    pub checks: Vec<Fact>,
    /// How it was solved: the time step, the critical step, steps, modes, elements.
    pub solution: Vec<Fact>,
    /// Every contact (a note shows the worst).
    pub contacts: Vec<ContactRow>,
    /// Every pin (a note shows the worst).
    pub pins: Vec<PinRow>,
    pub envelope: Option<Envelope>,
    pub plots: Vec<PlotRequest>,
}

/// A fact whose figure is at `pointer`, if the document has a number there.
pub fn fact(
    document: &Value,
    quantity: &str,
    pointer: &str,
    unit: Unit,
    time: Option<&str>,
    location: String,
) -> Option<Fact> {
    Some(Fact {
        quantity: quantity.to_owned(),
        figure: Figure::at(document, pointer, unit)?,
        time: time.and_then(|t| Figure::at(document, t, Unit::Second)),
        location,
    })
}

/// "pin 3 at 0.5 m" of a bending entry at `at` (`/max_bending`), the pin left out for a
/// single beam.
fn bending_place(document: &Value, at: &str, with_pin: bool) -> String {
    let height = document
        .pointer(&format!("{at}/height"))
        .and_then(Value::as_f64)
        .map(super::columns::metres)
        .unwrap_or_default();
    let pin = document.pointer(&format!("{at}/pin")).and_then(Value::as_u64);
    match (with_pin, pin) {
        (true, Some(pin)) => format!("p{pin} at {height}"),
        _ => format!("at {height}"),
    }
}

/// The largest bending of the run (`max_bending` at `at`): stress and strain when the
/// outer fibre is known, and the moment.
pub fn bending_peaks(document: &Value, at: &str, with_pin: bool) -> Vec<Fact> {
    let place = bending_place(document, at, with_pin);
    let time = format!("{at}/time");
    [
        ("largest bending stress", "stress", Unit::Pascal),
        ("largest bending moment", "moment", Unit::NewtonMetre),
        ("largest outer-fibre strain", "strain", Unit::Dimensionless),
    ]
    .into_iter()
    .filter_map(|(quantity, member, unit)| {
        fact(
            document,
            quantity,
            &format!("{at}/{member}"),
            unit,
            Some(&time),
            place.clone(),
        )
    })
    .collect()
}

/// The margins of a run whose members are at `run` (`""` or `/numerical`): the worst
/// utilisation, the contact's (`max_utilisation`, or a single contact's `utilisation`)
/// and the stress's (`max_stress_utilisation`); `contact_label` names contact k.
pub fn margin_facts(document: &Value, run: &str, contact_label: &dyn Fn(usize) -> String) -> Vec<Fact> {
    let mut facts = Vec::new();
    facts.extend(fact(
        document,
        "worst utilisation",
        &format!("{run}/worst_utilisation"),
        Unit::Dimensionless,
        None,
        String::new(),
    ));
    let contact = format!("{run}/max_utilisation");
    if let Some(k) = document
        .pointer(&format!("{contact}/contact"))
        .and_then(Value::as_u64)
    {
        facts.extend(fact(
            document,
            "contact force utilisation",
            &format!("{contact}/utilisation"),
            Unit::Dimensionless,
            None,
            format!("c{k}, {}", contact_label(k as usize)),
        ));
    } else {
        facts.extend(fact(
            document,
            "contact force utilisation",
            &format!("{run}/utilisation"),
            Unit::Dimensionless,
            None,
            contact_label(0),
        ));
    }
    let stress = format!("{run}/max_stress_utilisation");
    facts.extend(fact(
        document,
        "bending stress utilisation",
        &format!("{stress}/utilisation"),
        Unit::Dimensionless,
        Some(&format!("{stress}/time")),
        bending_place(document, &stress, run.is_empty()),
    ));
    facts
}

/// The envelope array at `pointer`: stresses when every node has one, else moments.
pub fn envelope(document: &Value, pointer: &str) -> Option<Envelope> {
    let nodes = document.pointer(pointer)?.as_array().filter(|n| !n.is_empty())?;
    let heights: Option<Vec<f64>> = nodes.iter().map(|n| n["height"].as_f64()).collect();
    let stresses: Option<Vec<f64>> = nodes.iter().map(|n| n["stress"].as_f64()).collect();
    let (values, unit) = match stresses {
        Some(stresses) => (stresses, Unit::Pascal),
        None => (
            nodes
                .iter()
                .map(|n| n["moment"].as_f64())
                .collect::<Option<Vec<f64>>>()?,
            Unit::NewtonMetre,
        ),
    };
    Some(Envelope {
        heights: heights?,
        values,
        unit,
        pointer: pointer.to_owned(),
    })
}

/// The rows of the `contacts` list, each named by `label` (its index).
pub fn contact_rows(document: &Value, label: &dyn Fn(usize) -> String) -> Vec<ContactRow> {
    let count = document["contacts"].as_array().map_or(0, Vec::len);
    (0..count)
        .filter_map(|k| {
            let at = |member: &str, unit| Figure::at(document, format!("/contacts/{k}/{member}"), unit);
            Some(ContactRow {
                contact: k,
                label: label(k),
                max_force: at("max_force", Unit::Newton)?,
                max_force_time: at("max_force_time", Unit::Second),
                impacts: at("impacts", Unit::Count),
                impulse: at("impulse", Unit::NewtonSecond),
                allowable_force: at("allowable_force", Unit::Newton),
                utilisation: at("utilisation", Unit::Dimensionless),
            })
        })
        .collect()
}

/// Where a pin entry of `pins` keeps its largest deflection, relative to the entry
/// (`/max_abs_deflection` in a row, `/deflection/max_deflection` in a hexagonal bundle).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeflectionMembers {
    pub value: &'static str,
    pub height: &'static str,
    pub time: &'static str,
}

/// The note of a run of pins whose summary is at the document's top (the row and the
/// hexagonal bundle, `run_report`): `contact_label` names contact k, `deflection` says
/// where a pin's largest deflection is, `deflection_columns` names pin p's columns of
/// the `displacements` histories.
pub fn run_of_pins(
    document: &Value,
    contact_label: &dyn Fn(usize) -> String,
    deflection: DeflectionMembers,
    deflection_columns: &dyn Fn(usize) -> Vec<String>,
) -> NoteFacts {
    let contacts = contact_rows(document, contact_label);
    let pins: Vec<PinRow> = (0..document["pins"].as_array().map_or(0, Vec::len))
        .map(|p| {
            let entry = format!("/pins/{p}");
            let at = |member: &str, unit| Figure::at(document, format!("{entry}{member}"), unit);
            let bending =
                at("/bending/stress", Unit::Pascal).or_else(|| at("/bending/moment", Unit::NewtonMetre));
            PinRow {
                pin: p,
                deflection: at(deflection.value, Unit::Deflection),
                deflection_height: at(deflection.height, Unit::Metre),
                deflection_time: at(deflection.time, Unit::Second),
                bending,
                bending_height: at("/bending/height", Unit::Metre),
                bending_time: at("/bending/time", Unit::Second),
                utilisation: at("/utilisation", Unit::Dimensionless),
            }
        })
        .collect();
    let mut peaks = Vec::new();
    let mut plots = Vec::new();
    if let Some(k) = document
        .pointer("/max_contact_force/contact")
        .and_then(Value::as_u64)
    {
        let k = k as usize;
        let label = contact_label(k);
        peaks.extend(fact(
            document,
            "largest contact force",
            "/max_contact_force/force",
            Unit::Newton,
            Some("/max_contact_force/time"),
            format!("c{k}, {label}"),
        ));
        plots.push(PlotRequest {
            title: format!("Force of c{k}, {label}: the largest contact force of the run"),
            output: "contact_forces_peaks".into(),
            series: vec![format!("c{k}")],
            unit: Unit::Newton,
            peak: Figure::at(document, "/max_contact_force/time", Unit::Second).zip(Figure::at(
                document,
                "/max_contact_force/force",
                Unit::Newton,
            )),
        });
    }
    let deflected = pins
        .iter()
        .filter_map(|pin| pin.deflection.as_ref().map(|d| (pin, d)))
        .max_by(|a, b| a.1.value.abs().total_cmp(&b.1.value.abs()));
    if let Some((pin, deflection)) = deflected {
        let height = pin
            .deflection_height
            .as_ref()
            .map(|h| super::columns::metres(h.value))
            .unwrap_or_default();
        peaks.push(Fact {
            quantity: "largest deflection".into(),
            figure: deflection.clone(),
            time: pin.deflection_time.clone(),
            location: format!("p{} at {height}", pin.pin),
        });
        plots.push(PlotRequest {
            title: format!(
                "Tip deflection of p{}, the pin of largest deflection (relative to the pin feet)",
                pin.pin
            ),
            output: "displacements_peaks".into(),
            series: deflection_columns(pin.pin),
            unit: Unit::Deflection,
            peak: None,
        });
    }
    if let Some(pin) = document
        .pointer("/max_resultant_force/pin")
        .and_then(Value::as_u64)
    {
        let height = (document
            .pointer("/max_resultant_force/height")
            .and_then(Value::as_f64))
        .map(super::columns::metres)
        .unwrap_or_default();
        peaks.extend(fact(
            document,
            "largest resultant contact force on a pin",
            "/max_resultant_force/max_force",
            Unit::Newton,
            Some("/max_resultant_force/time"),
            format!("p{pin} at {height}"),
        ));
    }
    peaks.extend(bending_peaks(document, "/max_bending", true));
    NoteFacts {
        peaks,
        margins: margin_facts(document, "", contact_label),
        checks: Vec::new(),
        solution: solution(document, ""),
        contacts,
        pins,
        envelope: envelope(document, "/bending_envelope"),
        plots,
    }
}

/// How the run at `run` was solved, and on which basis (`/basis`).
pub fn solution(document: &Value, run: &str) -> Vec<Fact> {
    [
        ("time step", format!("{run}/time_step"), Unit::Second),
        (
            "critical time step",
            format!("{run}/critical_time_step"),
            Unit::Second,
        ),
        ("steps", format!("{run}/steps"), Unit::Count),
        ("output interval", format!("{run}/output_interval"), Unit::Second),
        ("modes", "/basis/modes".to_owned(), Unit::Count),
        ("elements", "/basis/elements".to_owned(), Unit::Count),
        ("first frequency", format!("{run}/frequencies_hz/0"), Unit::Hertz),
    ]
    .into_iter()
    .filter_map(|(quantity, pointer, unit)| fact(document, quantity, &pointer, unit, None, String::new()))
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn figures_carry_the_pointer_of_the_member_they_come_from_and_nulls_are_absent() {
        let document = json!({"max_bending": {"pin": 2, "height": 0.5, "time": 0.01,
                                               "moment": 3.0, "stress": null, "strain": null}});
        let peaks = bending_peaks(&document, "/max_bending", true);
        assert_eq!(peaks.len(), 1, "{peaks:?}");
        assert_eq!(peaks[0].figure.pointer, "/max_bending/moment");
        assert_eq!(peaks[0].figure.value, 3.0);
        assert_eq!(peaks[0].time.as_ref().map(|t| t.value), Some(0.01));
        assert_eq!(peaks[0].location, "p2 at 0.5 m");
    }

    #[test]
    fn an_envelope_falls_back_to_moments_when_a_stress_is_null() {
        let document = json!({"e": [{"height": 0.0, "moment": 2.0, "stress": null},
                                    {"height": 1.0, "moment": 1.0, "stress": null}]});
        let envelope = envelope(&document, "/e").unwrap();
        assert_eq!(envelope.unit, Unit::NewtonMetre);
        assert_eq!(envelope.values, [2.0, 1.0]);
        assert_eq!(envelope.heights, [0.0, 1.0]);
    }

    #[test]
    fn margins_name_the_contact_and_the_place_of_the_stress() {
        let document = json!({"worst_utilisation": 0.9,
            "max_utilisation": {"contact": 4, "utilisation": 0.9},
            "max_stress_utilisation": {"pin": 1, "height": 0.0, "time": 0.2, "utilisation": 0.5}});
        let facts = margin_facts(&document, "", &|k| format!("label {k}"));
        let located: Vec<(&str, &str)> = facts
            .iter()
            .map(|f| (f.figure.pointer.as_str(), f.location.as_str()))
            .collect();
        assert_eq!(
            located,
            [
                ("/worst_utilisation", ""),
                ("/max_utilisation/utilisation", "c4, label 4"),
                ("/max_stress_utilisation/utilisation", "p1 at 0 m")
            ]
        );
        assert!(margin_facts(&json!({"worst_utilisation": null}), "", &|_| String::new()).is_empty());
    }
}
