//! The calculation note (`GET /jobs/{jobId}/report`), over HTTP on real runs of each
//! process, and in headless Chromium:
//!
//! - every section is there (identification, verdict, warnings, peaks, margins, worst
//!   contacts and pins, envelope, key histories, solution, inputs), and every number of
//!   the note equals the member of the same job's results document it names
//!   (`data-pointer`): never a constant of a past run;
//! - the peaks are the document's largest contact force, deflection and bending stress;
//!   the worst contacts are the largest forces of the document, in order; the verdict
//!   and each reason are the document's; the provenance is the document's;
//! - labels and notes are escaped; a job not finished has no note (404
//!   `result-not-ready`), nor a dismissed one; the note is HTML only (`?format=json`: 400);
//! - in Chromium every section is visible on screen and in print (and the job's dashboard
//!   page links to the note), and printing to PDF
//!   (A4) puts each plot whole on one page: each plot links to its data, and the link
//!   annotations Chromium writes into the PDF (one per fragment of the link's box) say
//!   on which page and how tall each plot came out.

use std::collections::BTreeMap;
use std::time::Duration;

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::Registry;

use crate::dashboard::{chromium, screenshot_dir};
use crate::devtools::{Browser, base64_decode};
use crate::helpers::{TestApp, assert_problem, spawn_app, spawn_app_with_processes};

async fn spawn() -> TestApp {
    spawn_app_with_processes(Registry::builtin().all().to_vec(), |_| {}).await
}

fn pin() -> Value {
    json!({"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
           "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "damping_ratio": 0.01})
}

/// A row of three pins released toward each other, contacts at two levels, allowables
/// low enough that some are reached.
fn row() -> Value {
    json!({"pin": pin(),
           "bundle": {"pins": 3, "levels": [0.3, 0.6], "stiffness": 2e5, "damping": 2.0,
                      "wall_gap": 1e-4, "pin_gap": 5e-5},
           "initial": {"tip_displacements": [1e-3, -1e-3, 1e-3]},
           "solver": {"duration": 0.04, "check": "none"},
           "output": {"allowables": {"contact_force": {"pin_pin": 2.0, "pin_wall": 3.0}, "stress": 2.0e7}}})
}

/// Seven wire-wrapped pins shaken against each other and the wrapper, every contact recorded.
fn hex() -> Value {
    json!({"pin": pin(),
           "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                      "wrapper_flat_to_flat": 0.0305},
           "contact": {"stiffness": 2e5, "damping": 2.0},
           "gaps": {"type": "uniform", "pin_pin": 0.0, "pin_wall": 0.0},
           "excitation": {"base_acceleration": {"type": "sine", "amplitude": 20.0, "frequency": 30.0, "cycles": 2},
                          "direction": 30.0},
           "solver": {"duration": 0.04, "check": "none"},
           "output": {"contacts": {"type": "all"}}})
}

/// The paper's cantilever, shortened, with the step-halving check (the default).
fn cantilever() -> Value {
    json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                    "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                    "elements": 20, "modes": 6},
           "contact": {"rk": 1.0},
           "solver": {"duration": 0.1},
           "reference": {"modes": 10},
           "output": {"allowables": {"contact_force": 0.05}}})
}

const LABEL: &str = "<b>clad</b> & \"B\"";
const NOTE: &str = "ticket <4512> 'rev. C' & <script>alert(1)</script>";

/// Runs `inputs` with a label and a note full of markup; returns the job id.
async fn run(app: &TestApp, process: &str, inputs: Value) -> String {
    let body = json!({"inputs": inputs, "labels": [LABEL, "plain"], "note": NOTE});
    app.succeed(process, &body).await
}

async fn note(app: &TestApp, job: &str) -> String {
    let response = app.get(&format!("/jobs/{job}/report")).await;
    assert_eq!(response.status(), StatusCode::OK, "GET /jobs/{job}/report");
    let content_type = response.headers()["content-type"].to_str().unwrap().to_owned();
    assert_eq!(content_type, "text/html; charset=utf-8");
    response.text().await.unwrap()
}

/// The value of the attribute `name` in each opening tag that has it, in order.
fn attributes(html: &str, name: &str) -> Vec<String> {
    let key = format!(" {name}=\"");
    html.match_indices(&key)
        .map(|(at, _)| {
            let start = at + key.len();
            html[start..start + html[start..].find('"').unwrap()].to_owned()
        })
        .collect()
}

/// Every (pointer, value) the note carries, in order.
fn figures(html: &str) -> Vec<(String, f64)> {
    let pointers = attributes(html, "data-pointer");
    let values = attributes(html, "data-value");
    assert_eq!(
        pointers.len(),
        values.len(),
        "every figure has a pointer and a value"
    );
    pointers
        .into_iter()
        .zip(values)
        .map(|(p, v)| (p, v.parse().unwrap_or_else(|e| panic!("data-value {v}: {e}"))))
        .collect()
}

/// The note's figures equal the document's members they name; returns them by pointer.
fn check_figures(html: &str, document: &Value) -> BTreeMap<String, f64> {
    let figures = figures(html);
    assert!(figures.len() >= 20, "only {} figures in the note", figures.len());
    for (pointer, value) in &figures {
        let served = document
            .pointer(pointer)
            .and_then(Value::as_f64)
            .unwrap_or_else(|| {
                panic!("the note shows {pointer} = {value}, the document has no number there")
            });
        assert_eq!(
            *value, served,
            "{pointer}: note {value}, results document {served}"
        );
    }
    figures.into_iter().collect()
}

const SECTIONS: [&str; 10] = [
    "identification",
    "verdict",
    "warnings",
    "peaks",
    "margins",
    "contacts",
    "envelope",
    "plots",
    "solution",
    "inputs",
];

/// `text` as HTML text: `&`, `<`, `>` and both quotes as entities.
fn escaped(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&#39;")
}

/// What every note holds, from its own job's documents.
fn check_common(html: &str, document: &Value, job: &str) {
    let sections = attributes(html, "data-section");
    for section in SECTIONS {
        assert!(
            sections.iter().any(|s| s == section),
            "no {section} section: {sections:?}"
        );
    }
    // Provenance and identification.
    for member in ["build", "inputs_sha256", "solver_version"] {
        let text = document["provenance"][member].as_str().unwrap();
        assert!(html.contains(text), "the note lacks provenance.{member} {text}");
    }
    assert!(html.contains(&format!("data-job>{job}<")), "job id");
    // Labels and note escaped, never as markup.
    assert!(
        html.contains("&lt;b&gt;clad&lt;/b&gt; &amp; &quot;B&quot;"),
        "the label, escaped"
    );
    assert!(
        html.contains("ticket &lt;4512&gt; &#39;rev. C&#39; &amp; &lt;script&gt;alert(1)&lt;/script&gt;"),
        "the note, escaped"
    );
    assert!(
        !html.contains("<b>clad") && !html.contains("<script"),
        "markup of the job's texts leaked"
    );
    // The verdict and every reason.
    let quality = &document["quality"];
    assert_eq!(
        attributes(html, "data-verdict"),
        [quality["verdict"].as_str().unwrap()]
    );
    let reasons = quality["reasons"].as_array().unwrap();
    assert_eq!(attributes(html, "data-reasons"), [reasons.len().to_string()]);
    for reason in reasons {
        let escaped = escaped(reason.as_str().unwrap());
        assert!(
            html.contains(&format!("<li data-reason>{escaped}</li>")),
            "reason {reason}"
        );
    }
    // Each warning, or none.
    let warnings = document["warnings"].as_array().unwrap();
    assert_eq!(attributes(html, "data-warnings"), [warnings.len().to_string()]);
    // Plots: the envelope and the key histories, drawn.
    let drawn = attributes(html, "data-figure");
    assert!(drawn.iter().any(|f| f == "envelope"), "{drawn:?}");
    assert!(drawn.iter().any(|f| f == "history-0"), "{drawn:?}");
    assert!(html.contains("<polyline data-curve="), "no curve drawn");
    assert!(
        html.contains("data-mark=\"peak\""),
        "the reported peak is not marked"
    );
    assert!(!html.contains("data-missing"), "a plot is missing");
    // The inputs, at their pointers.
    assert!(
        html.contains("<td class=\"mono\">/inputs/solver/duration</td>"),
        "inputs table"
    );
}

/// The worst contacts are the document's largest peak forces, largest first.
fn check_worst_contacts(html: &str, document: &Value, pointer_of: impl Fn(usize) -> String) {
    let shown: Vec<usize> = attributes(html, "data-contact")
        .iter()
        .map(|k| k.parse().unwrap())
        .collect();
    let contacts = document["contacts"].as_array().unwrap();
    let mut expected: Vec<usize> = (0..contacts.len()).collect();
    let force = |k: usize| contacts[k]["max_force"].as_f64().unwrap();
    expected.sort_by(|&a, &b| force(b).total_cmp(&force(a)).then(a.cmp(&b)));
    expected.truncate(10);
    assert_eq!(shown, expected, "worst contacts shown, largest forces served");
    assert_eq!(
        shown[0],
        document["max_contact_force"]["contact"].as_u64().unwrap() as usize
    );
    assert!(html.contains(&format!("data-pointer=\"{}\"", pointer_of(shown[0]))));
}

#[tokio::test]
async fn a_rows_note_shows_its_results_peaks_margins_worst_contacts_and_pins() {
    let app = spawn().await;
    let job = run(&app, "bundle-dynamics", row()).await;
    let document = app.get_json(&format!("/jobs/{job}/results")).await;
    let html = note(&app, &job).await;
    check_common(&html, &document, &job);
    let figures = check_figures(&html, &document);
    for pointer in [
        "/max_contact_force/force",
        "/max_contact_force/time",
        "/max_bending/stress",
        "/max_bending/moment",
        "/worst_utilisation",
        "/max_utilisation/utilisation",
        "/max_stress_utilisation/utilisation",
        "/time_step",
        "/critical_time_step",
    ] {
        assert!(figures.contains_key(pointer), "the note lacks {pointer}");
    }
    assert!(document["worst_utilisation"].as_f64().unwrap() > 0.0);
    check_worst_contacts(&html, &document, |k| format!("/contacts/{k}/max_force"));
    // The largest deflection is the largest of the pins'.
    let pins = document["pins"].as_array().unwrap();
    let deflected = (0..pins.len())
        .max_by(|&a, &b| {
            let d = |p: usize| pins[p]["max_abs_deflection"].as_f64().unwrap().abs();
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    assert!(figures.contains_key(&format!("/pins/{deflected}/max_abs_deflection")));
    assert_eq!(attributes(&html, "data-pin").len(), pins.len());
    // The force plot is of the worst contact, and links to its data.
    let worst = document["max_contact_force"]["contact"].as_u64().unwrap();
    assert!(
        html.contains(&format!(
            "href=\"/jobs/{job}/results/contact_forces_peaks?format=csv&amp;series=c{worst}\""
        )),
        "the force plot's data link"
    );
}

#[tokio::test]
async fn a_hexagonal_bundles_note_reads_its_resultant_deflections_and_wire_contacts() {
    let app = spawn().await;
    let job = run(&app, "hex-bundle-dynamics", hex()).await;
    let document = app.get_json(&format!("/jobs/{job}/results")).await;
    let html = note(&app, &job).await;
    check_common(&html, &document, &job);
    let figures = check_figures(&html, &document);
    assert!(figures.contains_key("/max_contact_force/force"));
    assert!(figures.contains_key("/max_bending/stress"));
    assert!(
        figures.keys().any(|p| p.ends_with("/deflection/max_deflection")),
        "the resultant deflections"
    );
    check_worst_contacts(&html, &document, |k| format!("/contacts/{k}/max_force"));
    // No allowables: the margins say so.
    assert!(html.contains("No allowables were given"));
    // The worst contact described as its history's column is.
    let worst = document["max_contact_force"]["contact"].as_u64().unwrap();
    let wire = document["contacts"][worst as usize]["wire_pin"].as_u64().unwrap();
    assert!(
        html.contains(&format!("contact of p{wire}&#39;s wire on")),
        "the worst contact's words"
    );
}

#[tokio::test]
async fn a_cantilevers_note_sets_its_peaks_beside_the_reference() {
    let app = spawn().await;
    let job = run(&app, "cantilever-impact", cantilever()).await;
    let document = app.get_json(&format!("/jobs/{job}/results")).await;
    let html = note(&app, &job).await;
    check_common(&html, &document, &job);
    let figures = check_figures(&html, &document);
    for pointer in [
        "/numerical/max_contact_force",
        "/reference/max_contact_force",
        "/numerical/min_tip_displacement",
        "/numerical/max_bending/stress",
        "/comparison/f_err",
        "/numerical/utilisation",
        "/numerical/worst_utilisation",
        "/quality/step_halving/estimated_peak_force_error",
    ] {
        assert!(figures.contains_key(pointer), "the note lacks {pointer}");
    }
    assert_eq!(attributes(&html, "data-contact"), ["0"], "its one contact");
    assert!(
        html.contains("series=numerical,reference"),
        "both solutions plotted"
    );
}

#[tokio::test]
async fn a_job_not_finished_or_dismissed_has_no_note_and_the_note_is_html_only() {
    let app = spawn_app().await;
    let running = app.submit(json!({"steps": 400, "step_ms": 10})).await;
    app.wait_for(&running, &["running"], Duration::from_secs(5)).await;
    let response = app.get(&format!("/jobs/{running}/report")).await;
    assert!(response.headers().contains_key("retry-after"));
    assert_problem(response, StatusCode::NOT_FOUND, "/result-not-ready").await;
    assert_eq!(
        app.delete(&format!("/jobs/{running}")).await.status(),
        StatusCode::OK
    );
    app.wait_for(&running, &["dismissed"], Duration::from_secs(5))
        .await;
    let dismissed = app.get(&format!("/jobs/{running}/report")).await;
    assert_problem(dismissed, StatusCode::NOT_FOUND, "/job-dismissed").await;
    let unknown = app.get("/jobs/no-such-job/report").await;
    assert_problem(unknown, StatusCode::NOT_FOUND, "/no-such-job").await;

    // A finished job of a process that names no figure still has its note, saying so.
    let done = app.submit(json!({"steps": 3})).await;
    app.wait_until_finished(&done).await;
    let status = app.status(&done).await;
    let link = status["links"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["rel"] == "https://chocmodal.dev/rel/report")
        .unwrap_or_else(|| panic!("no report link in {status}"));
    assert_eq!(link["href"], format!("/jobs/{done}/report"));
    assert_eq!(link["type"], "text/html");
    let html = note(&app, &done).await;
    assert!(html.contains("This process reports no peaks."), "{html}");
    let by_wildcard = app
        .client
        .get(app.url(&format!("/jobs/{done}/report")))
        .header("accept", "*/*")
        .send()
        .await
        .unwrap();
    assert_eq!(by_wildcard.status(), StatusCode::OK);
    let etag = by_wildcard.headers()["etag"].to_str().unwrap().to_owned();
    let again = app
        .get_if_none_match(&format!("/jobs/{done}/report"), &etag)
        .await;
    assert_eq!(again.status(), StatusCode::NOT_MODIFIED);
    let as_json = app.get(&format!("/jobs/{done}/report?format=json")).await;
    let problem = assert_problem(as_json, StatusCode::BAD_REQUEST, "/invalid-query").await;
    assert!(
        problem["detail"].as_str().unwrap().contains("`html`"),
        "{problem}"
    );
    let json_only = app
        .client
        .get(app.url(&format!("/jobs/{done}/report")))
        .header("accept", "application/json")
        .send()
        .await
        .unwrap();
    assert_problem(json_only, StatusCode::NOT_ACCEPTABLE, "/not-acceptable").await;
}

/// A PDF's link annotations: (page number from 1, URI, rectangle [x1 y1 x2 y2] in pt).
fn link_annotations(pdf: &[u8]) -> (usize, Vec<(usize, String, [f64; 4])>) {
    let text = String::from_utf8_lossy(pdf);
    let mut objects: BTreeMap<u64, &str> = BTreeMap::new();
    let mut pages: Vec<Vec<u64>> = Vec::new();
    for chunk in text.split("endobj") {
        let Some(at) = chunk.find(" 0 obj") else { continue };
        let head = &chunk[..at];
        let number: u64 = head
            .rsplit(|c: char| !c.is_ascii_digit())
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or(u64::MAX);
        let body = &chunk[at..];
        objects.insert(number, body);
        let is_page = body
            .match_indices("/Type /Page")
            .any(|(i, m)| !body[i + m.len()..].starts_with('s'));
        if is_page {
            let annots = body
                .find("/Annots [")
                .map(|i| {
                    let list = &body[i + 9..];
                    let list = &list[..list.find(']').unwrap()];
                    let refs: Vec<&str> = list.split_whitespace().collect();
                    refs.chunks(3).filter_map(|r| r[0].parse().ok()).collect()
                })
                .unwrap_or_default();
            pages.push(annots);
        }
    }
    let mut links = Vec::new();
    for (page, annots) in pages.iter().enumerate() {
        for number in annots {
            let body = objects[number];
            let Some(uri) = body.find("/URI (").map(|i| {
                let rest = &body[i + 6..];
                rest[..rest.find(')').unwrap()].replace("\\", "")
            }) else {
                continue;
            };
            let rect = body.find("/Rect [").map(|i| {
                let rest = &body[i + 7..];
                let values: Vec<f64> = rest[..rest.find(']').unwrap()]
                    .split_whitespace()
                    .map(|v| v.parse().unwrap())
                    .collect();
                [values[0], values[1], values[2], values[3]]
            });
            links.push((page + 1, uri, rect.expect("a link annotation has a rectangle")));
        }
    }
    (pages.len(), links)
}

#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn in_chromium_every_section_shows_and_the_printed_pdf_keeps_each_plot_whole_on_one_page() {
    let chromium = chromium(concat!(
        module_path!(),
        "::in_chromium_every_section_shows_and_the_printed_pdf_keeps_each_plot_whole_on_one_page"
    ));
    let app = spawn().await;
    let job = run(&app, "bundle-dynamics", row()).await;
    let mut browser = Browser::launch(&chromium, 1000, 1400).await;
    browser.goto(&app.url(&format!("/jobs/{job}/report"))).await;
    let visible = "[...document.querySelectorAll('[data-section]')].map((s) => { const r = s.getBoundingClientRect(); \
                   const style = getComputedStyle(s); return [s.dataset.section, r.width > 0 && r.height > 0 \
                   && style.display !== 'none' && style.visibility !== 'hidden' && Number(style.opacity) > 0]; })";
    for media in ["screen", "print"] {
        browser
            .call("Emulation.setEmulatedMedia", json!({"media": media}))
            .await;
        let shown: Vec<(String, bool)> = serde_json::from_value(browser.eval(visible).await).unwrap();
        for section in SECTIONS.iter().chain(&["pins"]) {
            assert!(
                shown.iter().any(|(s, v)| s == section && *v),
                "{media}: section {section} not visible: {shown:?}"
            );
        }
    }
    browser
        .call("Emulation.setEmulatedMedia", json!({"media": ""}))
        .await;
    browser.screenshot(&screenshot_dir().join("report-row.png")).await;
    browser.assert_no_exceptions();

    // Each plot's link, as Chromium resolved it (absolute), and its aspect ratio.
    let plots: Vec<(String, f64)> = serde_json::from_value(
        browser
            .eval(
                "[...document.querySelectorAll('figure.plot a.data')].map((a) => { \
                 const box = a.querySelector('svg').viewBox.baseVal; return [a.href, box.height / box.width]; })",
            )
            .await,
    )
    .unwrap();
    assert_eq!(plots.len(), 3, "the envelope and two histories: {plots:?}");
    let printed = browser
        .call(
            "Page.printToPDF",
            json!({"printBackground": true, "preferCSSPageSize": true, "displayHeaderFooter": false}),
        )
        .await;
    let pdf = base64_decode(printed["data"].as_str().unwrap());
    std::fs::write(screenshot_dir().join("report-row.pdf"), &pdf).unwrap();
    let (pages, links) = link_annotations(&pdf);
    assert!(
        pages >= 2,
        "the note of a row takes more than one A4 page, printed {pages}"
    );
    for (href, aspect) in &plots {
        let fragments: Vec<&(usize, String, [f64; 4])> =
            links.iter().filter(|(_, uri, _)| uri == href).collect();
        assert!(!fragments.is_empty(), "no link to {href} in the PDF: {links:?}");
        let on: Vec<usize> = fragments.iter().map(|(page, _, _)| *page).collect();
        assert!(
            on.iter().all(|&p| p == on[0]),
            "the plot linking to {href} is split across pages {on:?}"
        );
        // One whole plot: as tall as its width and aspect ratio say (a plot cut at the
        // page's foot would be shorter).
        let [x1, y1, x2, y2] = fragments[0].2;
        let (width, height) = (x2 - x1, y2 - y1);
        assert!(
            fragments.len() == 1 && (height - width * aspect).abs() < 2.0,
            "the plot linking to {href} printed {width} × {height} pt in {} piece(s), expected {:.1} pt tall",
            fragments.len(),
            width * aspect
        );
        assert!(
            width > 400.0,
            "the plot linking to {href} printed {width} pt wide, not the page's width"
        );
    }

    // The job's dashboard page links to its note.
    browser.goto(&app.url(&format!("/jobs/{job}"))).await;
    let link = browser
        .wait_for(
            "document.querySelector('[data-report-link]')?.getAttribute('href')",
            Duration::from_secs(30),
        )
        .await;
    assert_eq!(
        link,
        json!(format!("/jobs/{job}/report")),
        "the job page's link to its note"
    );
    browser.assert_no_exceptions();
}
