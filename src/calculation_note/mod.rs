//! The calculation note of a run: one printable HTML page (A4) with what an engineer
//! files beside a sizing: who ran what (job, process, solver version, build, inputs
//! hash, labels and note, dates), the quality verdict and every reason, the warnings,
//! the peaks with where and when, the margins, the worst contacts and pins, the bending
//! stress envelope along the height, the key histories as plots, how it was solved, and
//! the inputs.
//!
//! It is drawn the same way for every process, from what the process reads of its
//! results document ([`crate::processes::Process::note_facts`]); `GET
//! /jobs/{jobId}/report` serves it and `chocmodal run --report FILE` writes it. The page
//! is self-contained (inline style, inline SVG plots, no script, nothing fetched), so it
//! prints, saves and archives as it is seen. Every number carries the pointer of the
//! results member it comes from (`data-pointer`, and as its tooltip).

mod html;
mod inputs;
pub mod svg;

use std::fmt::Write;

use serde_json::Value;

pub use html::escape;
use html::{STYLE, figure_cell, inline, optional_cell, unit_text};

use crate::processes::History;
use crate::processes::note_facts::{ContactRow, Fact, NoteFacts, PinRow, PlotRequest, Unit};

/// How many contacts and pins the worst-of tables show.
pub const WORST: usize = 10;
/// Horizontal buckets a history is decimated to for its plot (min and max in each).
const PLOT_BUCKETS: usize = 600;

/// Who ran what, and when: what the results document does not say.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Identification {
    /// The job's id (none for `chocmodal run`).
    pub job_id: Option<String>,
    pub process_id: String,
    pub process_title: String,
    /// The job's status message (`finished; quality poor: ...`).
    pub status_message: Option<String>,
    pub labels: Vec<String>,
    pub note: Option<String>,
    /// Dated events, in order (`created`, `started`, `finished`; RFC 3339, UTC).
    pub dates: Vec<(String, String)>,
    /// Where the rest is (`results document`, `/jobs/{id}/results`), in order.
    pub links: Vec<(String, String)>,
}

/// A history prepared for a plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    pub request: PlotRequest,
    /// The curves (decimated), one per series found.
    pub curves: Vec<svg::Curve>,
    /// Where its data is (a CSV of the history's columns drawn); the figure links there.
    pub href: String,
    /// Why nothing is drawn (the history or a column is not there).
    pub missing: Option<String>,
}

impl Plot {
    /// The plot of `request` from `history` (none: not recorded), its data at `href`.
    pub fn of(request: &PlotRequest, history: Option<&History>, href: String) -> Plot {
        let (curves, missing) = match history {
            None => (
                Vec::new(),
                Some(format!("the history `{}` was not recorded", request.output)),
            ),
            Some(history) => {
                let mut curves = Vec::new();
                let mut absent = Vec::new();
                for name in &request.series {
                    match history.series.iter().find(|(n, _)| n == name) {
                        Some((_, values)) => curves.push(svg::Curve {
                            legend: name.clone(),
                            points: svg::decimate(&history.time, values, PLOT_BUCKETS),
                        }),
                        None => absent.push(format!("`{name}`")),
                    }
                }
                let missing = (!absent.is_empty()).then(|| {
                    format!(
                        "`{}` has no column {} (a hexagonal bundle records only the contacts \
                         `output.contacts` selects)",
                        request.output,
                        absent.join(", ")
                    )
                });
                (curves, missing)
            }
        };
        Plot {
            request: request.clone(),
            curves,
            href,
            missing,
        }
    }
}

/// Everything the note is drawn from.
#[derive(Debug, Clone)]
pub struct Note<'a> {
    pub identification: Identification,
    /// The `inputs` object as submitted.
    pub inputs: &'a Value,
    /// The results document.
    pub document: &'a Value,
    pub facts: NoteFacts,
    /// One per [`NoteFacts::plots`], in order.
    pub plots: Vec<Plot>,
    /// Where the bending envelope's data is (the results document).
    pub envelope_href: String,
}

/// The note as a complete HTML document.
pub fn render(note: &Note<'_>) -> String {
    let id = &note.identification;
    let mut page = String::with_capacity(64 * 1024);
    let title = match &id.job_id {
        Some(job) => format!("Calculation note: {} job {job}", id.process_id),
        None => format!("Calculation note: {}", id.process_id),
    };
    let _ = write!(
        page,
        "<!doctype html><html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>{}</title><style>{STYLE}</style></head><body class=\"calculation-note\">",
        escape(&title)
    );
    identification(&mut page, note);
    verdict(&mut page, note);
    warnings(&mut page, note.document);
    facts_section(
        &mut page,
        "peaks",
        "Peaks",
        "The run's largest values, when and where they occurred.",
        &note.facts.peaks,
        "This process reports no peaks.",
        Layout::Located,
    );
    facts_section(
        &mut page,
        "margins",
        "Margins",
        "Utilisations: peak over allowable (docs/margins.md); ≥ 1 means an allowable is reached. \
         Bands: green below 0.8, amber from 0.8 to 1, red from 1.",
        &note.facts.margins,
        "No allowables were given (`output.allowables`): no utilisation is computed.",
        Layout::Located,
    );
    worst_contacts(&mut page, &note.facts.contacts);
    worst_pins(&mut page, &note.facts.pins);
    envelope(&mut page, note);
    plots(&mut page, &note.plots);
    facts_section(
        &mut page,
        "solution",
        "Model and solution",
        "How the run was integrated (docs/accuracy.md).",
        &note.facts.solution,
        "Not reported.",
        Layout::Measures,
    );
    inputs::section(&mut page, note.inputs, id.job_id.as_deref());
    page.push_str("</body></html>\n");
    page
}

fn open_section(page: &mut String, id: &str, title: &str) {
    let _ = write!(
        page,
        "<section id=\"{id}\" data-section=\"{id}\"><h2>{title}</h2>"
    );
}

fn identification(page: &mut String, note: &Note<'_>) {
    let id = &note.identification;
    let provenance = &note.document["provenance"];
    let text = |member: &str| provenance[member].as_str().map(escape);
    let _ = write!(
        page,
        "<section id=\"identification\" data-section=\"identification\"><h1>Calculation note</h1>\
         <p class=\"lead\">{} (<code>{}</code>)</p><table class=\"identity\"><tbody>",
        escape(&id.process_title),
        escape(&id.process_id)
    );
    let mut row = |key: &str, value: String| {
        let _ = write!(page, "<tr><td class=\"key\">{key}</td><td>{value}</td></tr>");
    };
    if let Some(job) = &id.job_id {
        row(
            "Job",
            format!("<span class=\"mono\" data-job>{}</span>", escape(job)),
        );
    }
    row("Process", format!("<code>{}</code>", escape(&id.process_id)));
    if let Some(message) = &id.status_message {
        row("Status", escape(message));
    }
    row(
        "Solver",
        format!(
            "{} {}",
            text("solver").unwrap_or_default(),
            text("solver_version").unwrap_or_default()
        ),
    );
    row(
        "Build (git commit)",
        format!(
            "<span class=\"mono\" data-build>{}</span>",
            text("build").unwrap_or_else(|| "unknown".into())
        ),
    );
    row(
        "Inputs SHA-256 (RFC 8785 canonical JSON)",
        format!(
            "<span class=\"mono\" data-inputs-sha256>{}</span>",
            text("inputs_sha256").unwrap_or_default()
        ),
    );
    let labels = match id.labels.is_empty() {
        true => "<span class=\"muted\">none</span>".to_owned(),
        false => id
            .labels
            .iter()
            .map(|l| format!("<span class=\"label\" data-label>{}</span>", escape(l)))
            .collect::<Vec<_>>()
            .join(", "),
    };
    row("Labels", labels);
    row(
        "Note",
        id.note.as_deref().map_or_else(
            || "<span class=\"muted\">none</span>".to_owned(),
            |n| format!("<span class=\"note-text\" data-note>{}</span>", escape(n)),
        ),
    );
    for (what, when) in &id.dates {
        row(
            &escape(what),
            format!("<span data-date=\"{0}\">{0}</span>", escape(when)),
        );
    }
    for (what, href) in &id.links {
        row(
            &escape(what),
            format!("<a class=\"mono\" href=\"{0}\">{0}</a>", escape(href)),
        );
    }
    page.push_str("</tbody></table></section>");
}

fn verdict(page: &mut String, note: &Note<'_>) {
    let quality = &note.document["quality"];
    let verdict = quality["verdict"].as_str().unwrap_or("unknown");
    open_section(page, "verdict", "Quality verdict");
    let _ = write!(
        page,
        "<p><span class=\"verdict verdict-{0}\" data-verdict=\"{0}\">{0}</span> \
         <span class=\"muted\">(docs/accuracy.md: good, unchecked, doubtful, poor)</span></p>",
        escape(verdict)
    );
    let reasons: Vec<&str> = quality["reasons"]
        .as_array()
        .map(|r| r.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    if reasons.is_empty() {
        page.push_str(
            "<p data-reasons=\"0\">No reason against it: every measure taken is within the tolerance.</p>",
        );
    } else {
        let _ = write!(page, "<ul class=\"reasons\" data-reasons=\"{}\">", reasons.len());
        for reason in reasons {
            let _ = write!(page, "<li data-reason>{}</li>", escape(reason));
        }
        page.push_str("</ul>");
    }
    let measures: Vec<Fact> = [
        ("tolerance", "/quality/tolerance"),
        ("energy residual", "/quality/energy_residual"),
        ("time step over critical", "/quality/time_step_over_critical"),
        ("steps per contact period", "/quality/steps_per_contact_period"),
        (
            "estimated peak force error, time step",
            "/quality/step_halving/estimated_peak_force_error",
        ),
        (
            "estimated peak deflection error, time step",
            "/quality/step_halving/estimated_peak_displacement_error",
        ),
        (
            "impact count change at the check's step",
            "/quality/step_halving/impact_count_change",
        ),
        ("time step of the check (s)", "/quality/step_halving/time_step"),
        (
            "estimated peak force error, modal basis",
            "/quality/modal_truncation/estimated_peak_force_error",
        ),
        (
            "estimated peak force error, mesh",
            "/quality/mesh/estimated_peak_force_error",
        ),
    ]
    .into_iter()
    .filter_map(|(quantity, pointer)| {
        crate::processes::note_facts::fact(
            note.document,
            quantity,
            pointer,
            Unit::Dimensionless,
            None,
            String::new(),
        )
    })
    .chain(note.facts.checks.iter().cloned())
    .collect();
    if quality["step_halving"].is_null() {
        page.push_str("<p>The step check was not run (<code>solver.check: \"none\"</code>).</p>");
    } else if let Some(why) = quality["step_halving"]["why_half_step"].as_str() {
        page.push_str(&format!(
            "<p>The step check repeated the run at half the step: {}.</p>",
            escape(why)
        ));
    } else {
        page.push_str("<p>The step check repeated the run at twice the step.</p>");
    }
    measure_table(page, &measures);
    page.push_str("</section>");
}

fn warnings(page: &mut String, document: &Value) {
    open_section(page, "warnings", "Warnings");
    let warnings = document["warnings"].as_array().cloned().unwrap_or_default();
    if warnings.is_empty() {
        page.push_str("<p data-warnings=\"0\">No plausibility warning about the inputs.</p>");
    } else {
        let _ = write!(
            page,
            "<ul class=\"warnings\" data-warnings=\"{}\">",
            warnings.len()
        );
        for warning in &warnings {
            let text = |m: &str| escape(warning[m].as_str().unwrap_or_default());
            let _ = write!(
                page,
                "<li data-warning=\"{}\"><code>{}</code>: {}</li>",
                text("code"),
                text("pointer"),
                text("message")
            );
        }
        page.push_str("</ul>");
    }
    page.push_str("</section>");
}

/// The band class of a utilisation (green < 0.8 ≤ amber < 1 ≤ red).
fn band(fact: &Fact) -> &'static str {
    match fact.figure.value {
        v if v >= 1.0 => "band-red",
        v if v >= 0.8 => "band-amber",
        _ => "band-green",
    }
}

fn fact_table(page: &mut String, facts: &[Fact]) {
    page.push_str(
        "<table class=\"facts\"><thead><tr><th>quantity</th><th>value</th><th>unit</th>\
         <th>time (s)</th><th>where</th></tr></thead><tbody>",
    );
    for fact in facts {
        let utilisation = fact.quantity.contains("utilisation");
        let _ = write!(
            page,
            "<tr data-fact=\"{}\"{}><td>{}</td>{}<td>{}</td>{}<td>{}</td></tr>",
            escape(&fact.quantity),
            if utilisation {
                format!(" class=\"{}\"", band(fact))
            } else {
                String::new()
            },
            escape(&fact.quantity),
            figure_cell(&fact.figure),
            unit_text(fact.figure.unit),
            optional_cell(fact.time.as_ref()),
            escape(&fact.location)
        );
    }
    page.push_str("</tbody></table>");
}

/// Figures of the whole run (no time, no place): quantity, value and unit.
fn measure_table(page: &mut String, facts: &[Fact]) {
    page.push_str(
        "<table class=\"facts compact\"><thead><tr><th>quantity</th><th>value</th><th>unit</th></tr></thead><tbody>",
    );
    for fact in facts {
        let _ = write!(
            page,
            "<tr data-fact=\"{0}\"><td>{0}</td>{1}<td>{2}</td></tr>",
            escape(&fact.quantity),
            figure_cell(&fact.figure),
            unit_text(fact.figure.unit),
        );
    }
    page.push_str("</tbody></table>");
}

/// How a section's facts are tabled: with their times and places, or as measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    Located,
    Measures,
}

fn facts_section(
    page: &mut String,
    id: &str,
    title: &str,
    lead: &str,
    facts: &[Fact],
    empty: &str,
    layout: Layout,
) {
    open_section(page, id, title);
    let _ = write!(page, "<p class=\"lead\">{lead}</p>");
    if facts.is_empty() {
        let _ = write!(page, "<p data-empty>{}</p>", escape_code(empty));
    } else if layout == Layout::Measures {
        measure_table(page, facts);
    } else {
        fact_table(page, facts);
    }
    page.push_str("</section>");
}

/// Text with `code` spans for the parts in backticks (the sentences above are ours).
fn escape_code(text: &str) -> String {
    escape(text)
        .split('`')
        .enumerate()
        .map(|(k, part)| {
            if k % 2 == 1 {
                format!("<code>{part}</code>")
            } else {
                part.to_owned()
            }
        })
        .collect()
}

fn worst_contacts(page: &mut String, contacts: &[ContactRow]) {
    open_section(page, "contacts", "Worst contacts");
    if contacts.is_empty() {
        page.push_str("<p data-empty>This process reports no contacts.</p></section>");
        return;
    }
    let mut order: Vec<&ContactRow> = contacts.iter().collect();
    order.sort_by(|a, b| {
        b.max_force
            .value
            .total_cmp(&a.max_force.value)
            .then(a.contact.cmp(&b.contact))
    });
    order.truncate(WORST);
    let _ = write!(
        page,
        "<p class=\"lead\">The {} of {} contacts of largest peak force, largest first \
         (all of them: the contact table, <code>/results/contacts</code>).</p>\
         <table class=\"worst\" data-rows=\"{}\"><thead><tr><th>contact</th><th>what</th>\
         <th>peak force (N)</th><th>at time (s)</th><th>impacts</th><th>impulse (N·s)</th>\
         <th>allowable (N)</th><th>utilisation</th></tr></thead><tbody>",
        order.len(),
        contacts.len(),
        order.len()
    );
    for row in order {
        let _ = write!(
            page,
            "<tr data-contact=\"{}\"><td>c{}</td><td class=\"what\">{}</td>{}{}{}{}{}{}</tr>",
            row.contact,
            row.contact,
            escape(&row.label),
            figure_cell(&row.max_force),
            optional_cell(row.max_force_time.as_ref()),
            optional_cell(row.impacts.as_ref()),
            optional_cell(row.impulse.as_ref()),
            optional_cell(row.allowable_force.as_ref()),
            optional_cell(row.utilisation.as_ref()),
        );
    }
    page.push_str("</tbody></table></section>");
}

fn worst_pins(page: &mut String, pins: &[PinRow]) {
    if pins.is_empty() {
        return;
    }
    open_section(page, "pins", "Worst pins");
    let by_utilisation = pins.iter().any(|p| p.utilisation.is_some());
    let key = |p: &PinRow| match by_utilisation {
        true => p.utilisation.as_ref().map_or(f64::NEG_INFINITY, |u| u.value),
        false => p.bending.as_ref().map_or(f64::NEG_INFINITY, |b| b.value),
    };
    let mut order: Vec<&PinRow> = pins.iter().collect();
    order.sort_by(|a, b| key(b).total_cmp(&key(a)).then(a.pin.cmp(&b.pin)));
    order.truncate(WORST);
    let bending_unit = pins
        .iter()
        .find_map(|p| p.bending.as_ref().map(|b| b.unit))
        .unwrap_or(Unit::Pascal);
    let bending_title = match bending_unit {
        Unit::Pascal => "bending stress (MPa)",
        _ => "bending moment (N·m)",
    };
    let _ = write!(
        page,
        "<p class=\"lead\">The {} of {} pins of largest {}, largest first.</p>\
         <table class=\"worst\" data-rows=\"{}\"><thead><tr><th>pin</th><th>deflection (mm)</th>\
         <th>at height (m)</th><th>at time (s)</th><th>{bending_title}</th><th>at height (m)</th>\
         <th>at time (s)</th><th>utilisation</th></tr></thead><tbody>",
        order.len(),
        pins.len(),
        if by_utilisation {
            "utilisation"
        } else {
            bending_title
        },
        order.len()
    );
    for pin in order {
        let _ = write!(
            page,
            "<tr data-pin=\"{}\"><td>p{}</td>{}{}{}{}{}{}{}</tr>",
            pin.pin,
            pin.pin,
            optional_cell(pin.deflection.as_ref()),
            optional_cell(pin.deflection_height.as_ref()),
            optional_cell(pin.deflection_time.as_ref()),
            optional_cell(pin.bending.as_ref()),
            optional_cell(pin.bending_height.as_ref()),
            optional_cell(pin.bending_time.as_ref()),
            optional_cell(pin.utilisation.as_ref()),
        );
    }
    page.push_str("</tbody></table></section>");
}

/// A figure whose plot links to its data (`href`), with a caption.
fn figure(page: &mut String, name: &str, href: &str, svg: &str, caption: &str) {
    let _ = write!(
        page,
        "<figure class=\"plot\" data-figure=\"{}\"><a class=\"data\" href=\"{}\" title=\"the data plotted\">{svg}</a>\
         <figcaption>{caption}</figcaption></figure>",
        escape(name),
        escape(href)
    );
}

fn envelope(page: &mut String, note: &Note<'_>) {
    open_section(page, "envelope", "Bending envelope along the height");
    let Some(envelope) = &note.facts.envelope else {
        page.push_str("<p data-empty>This process reports no bending envelope.</p></section>");
        return;
    };
    let (factor, unit) = envelope.unit.shown();
    let what = match envelope.unit {
        Unit::Pascal => "outer-fibre bending stress",
        _ => "bending moment",
    };
    let curve = svg::Curve {
        legend: "envelope".into(),
        points: envelope
            .values
            .iter()
            .zip(&envelope.heights)
            .map(|(v, h)| (v * factor, *h))
            .collect(),
    };
    let largest = envelope
        .values
        .iter()
        .zip(&envelope.heights)
        .max_by(|a, b| a.0.total_cmp(b.0));
    let mark = largest.map(|(v, h)| {
        (
            (v * factor, *h),
            format!(
                "{} {unit} at {} m",
                html::shown(*v, envelope.unit),
                crate::physics::number(*h)
            ),
        )
    });
    let x_label = format!("{what} ({unit})");
    let svg = svg::draw(&svg::Plot {
        x_label: &x_label,
        y_label: "height from the foot (m)",
        curves: std::slice::from_ref(&curve),
        mark,
        values_along: svg::Axis::X,
    });
    let caption = format!(
        "The largest {what} at each of the {} mesh nodes over every pin and output sample \
         (<code>{}</code>, docs/bending.md): sampled at the output times.",
        envelope.heights.len(),
        escape(&envelope.pointer)
    );
    figure(page, "envelope", &note.envelope_href, &svg, &caption);
    page.push_str("</section>");
}

fn plots(page: &mut String, plots: &[Plot]) {
    open_section(page, "plots", "Key histories");
    if plots.is_empty() {
        page.push_str("<p data-empty>This process names no history to plot.</p>");
    }
    for (k, plot) in plots.iter().enumerate() {
        let request = &plot.request;
        let (factor, unit) = request.unit.shown();
        let y_label = match request.unit {
            Unit::Newton => format!("contact force ({unit})"),
            Unit::Deflection => format!("deflection ({unit})"),
            other => format!("value ({})", unit_text(other)),
        };
        let curves: Vec<svg::Curve> = plot
            .curves
            .iter()
            .map(|c| svg::Curve {
                legend: c.legend.clone(),
                points: c.points.iter().map(|(t, v)| (*t, v * factor)).collect(),
            })
            .collect();
        let mut caption = format!(
            "{} (<code>{}</code>",
            escape(&request.title),
            escape(&request.output)
        );
        if let Some((time, value)) = &request.peak {
            let _ = write!(
                caption,
                "; the reported peak {} at {} is circled",
                inline(value),
                inline(time)
            );
        }
        caption.push(')');
        if let Some(missing) = &plot.missing {
            let _ = write!(
                caption,
                ". <strong data-missing>Not drawn: {}</strong>",
                escape_code(missing)
            );
        }
        if curves.is_empty() {
            let _ = write!(page, "<p data-figure=\"history-{k}\" data-missing>{caption}.</p>");
            continue;
        }
        let mark = request.peak.as_ref().map(|(time, value)| {
            (
                (time.value, value.value * factor),
                format!("{} {unit}", html::shown(value.value, value.unit)),
            )
        });
        let svg = svg::draw(&svg::Plot {
            x_label: "time (s)",
            y_label: &y_label,
            curves: &curves,
            mark,
            values_along: svg::Axis::Y,
        });
        figure(page, &format!("history-{k}"), &plot.href, &svg, &caption);
    }
    page.push_str("</section>");
}
