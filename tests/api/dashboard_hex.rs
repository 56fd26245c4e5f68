//! The `hex-bundle-dynamics` job page in headless Chromium, driven over the DevTools
//! protocol (`devtools.rs`), against the served results of a small 7-pin run that records
//! every contact:
//!
//! - the cross-section draws one circle per pin and, at the level shown (first the level
//!   of the run's strongest contact), one segment per contact of that level, each
//!   carrying the chosen statistic's value, the colour scale topped by its largest value
//!   over all levels;
//! - moving the level slider shows another level and its contacts;
//! - the statistic picker recolours the segments with another statistic;
//! - clicking a segment selects that contact and draws its force history, whose
//!   peak-per-interval envelope peaks at the served peaks column and at the contact's
//!   reported `max_force`.
//!
//! The expected numbers all come from `GET /jobs/{id}/results`, not from a past run.
//! Screenshot: `target/dashboard-screenshots/job-hex.png` (see `dashboard.rs`).

use std::sync::Arc;
use std::time::Duration;

use chocmodal::processes::hex_bundle_dynamics::HexBundleDynamics;
use serde::Deserialize;
use serde_json::{Value, json};

use crate::dashboard::{chromium, execute, same, screenshot_dir, values};
use crate::devtools::Browser;
use crate::helpers::spawn_app_with_processes;

const WITHIN: Duration = Duration::from_secs(30);

/// A 7-pin bundle of short tubes (24 levels), shaken hard enough to rattle, every contact
/// recorded (as `inputs()` of `src/processes/hex_bundle_dynamics_tests.rs`).
fn seven_pins() -> Value {
    json!({"inputs": {
        "pin": {"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "static_correction": "none"},
        "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                   "wrapper_flat_to_flat": 0.0305},
        "contact": {"stiffness": 2e6, "damping": 20.0},
        "gaps": {"type": "uniform", "pin_pin": 5e-5, "pin_wall": 1e-4},
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 50.0, "duration": 0.01},
                       "direction": 10.0},
        "solver": {"duration": 0.03, "check": "none"},
        "output": {"interval": 1e-3, "contacts": {"type": "all"}}
    }})
}

/// What the cross-section figure shows, read from its data-* attributes (`hex.js`).
#[derive(Debug, Deserialize)]
struct Section {
    level: usize,
    measure: String,
    shown: usize,
    selected: i64,
    pins: usize,
    /// (contact, value of the measure) per segment drawn.
    segments: Vec<(usize, f64)>,
    scale_max: f64,
    /// The text next to the slider.
    label: String,
}

async fn section(browser: &mut Browser) -> Section {
    let value = browser
        .eval(
            "(() => { const f = document.querySelector('[data-plot=\"cross-section\"]'); \
             return {level: Number(f.dataset.level), measure: f.dataset.measure, \
               shown: Number(f.dataset.contactsShown), selected: Number(f.dataset.selected), \
               pins: f.querySelectorAll('svg circle[data-pin]').length, \
               segments: [...f.querySelectorAll('svg line[data-contact]')] \
                 .map((l) => [Number(l.dataset.contact), Number(l.dataset.value)]), \
               scale_max: Number(f.querySelector('[data-scale-max]').dataset.scaleMax), \
               label: document.querySelector('[data-level-slider]').closest('p').textContent}; })()",
        )
        .await;
    serde_json::from_value(value.clone()).unwrap_or_else(|e| panic!("{value}: {e}"))
}

/// The cross-section shows `level` coloured by `measure`: every pin, and exactly the
/// contacts of that level in the results, each with its served value.
fn check_section(section: &Section, results: &Value, level: usize, measure: &str) {
    let contacts = results["contacts"].as_array().unwrap();
    let pins = results["pins"].as_array().unwrap().len();
    assert_eq!(results["geometry"]["pins"], pins);
    assert_eq!(section.pins, pins, "pin circles drawn, pins in the results");
    assert_eq!(section.level, level, "level shown: {section:?}");
    assert!(
        section.label.contains(&format!("level {level}:")),
        "the slider's label: {:?}",
        section.label
    );
    assert_eq!(section.measure, measure);
    let expected: Vec<usize> = (0..contacts.len())
        .filter(|&k| contacts[k]["level"] == level)
        .collect();
    let mut drawn: Vec<usize> = section.segments.iter().map(|&(k, _)| k).collect();
    drawn.sort_unstable();
    assert!(!expected.is_empty(), "no contact at level {level}");
    assert_eq!(
        drawn, expected,
        "segments drawn at level {level}, contacts there in the results"
    );
    assert_eq!(section.shown, expected.len());
    let of = |k: usize| {
        contacts[k][measure]
            .as_f64()
            .unwrap_or_else(|| panic!("{measure} of c{k}"))
    };
    for &(k, value) in &section.segments {
        assert!(
            same(value, of(k)),
            "c{k} drawn with {measure} {value}, served {}",
            of(k)
        );
    }
    // The scale runs up to the largest value over every level (1 when all are 0).
    let largest = (0..contacts.len()).map(of).fold(0.0, f64::max);
    let top = if largest > 0.0 { largest } else { 1.0 };
    assert!(
        same(section.scale_max, top),
        "colour scale up to {}, largest {measure} served {largest}",
        section.scale_max
    );
}

#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn a_hex_job_page_draws_its_cross_section_levels_statistics_and_a_clicked_contacts_history() {
    let chromium = chromium(concat!(
        module_path!(),
        "::a_hex_job_page_draws_its_cross_section_levels_statistics_and_a_clicked_contacts_history"
    ));
    let app = spawn_app_with_processes(vec![Arc::new(HexBundleDynamics)], |_| {}).await;
    let job = execute(&app, "hex-bundle-dynamics", &seven_pins()).await;
    assert_eq!(
        app.wait_for(&job, &["successful"], Duration::from_secs(120))
            .await["status"],
        "successful"
    );
    let results = app.get_json(&format!("/jobs/{job}/results")).await;
    let contacts = results["contacts"].as_array().unwrap();
    let force = |k: usize| contacts[k]["max_force"].as_f64().unwrap();
    let level_of = |k: usize| contacts[k]["level"].as_u64().unwrap() as usize;
    let strongest = results["max_contact_force"]["contact"].as_u64().unwrap() as usize;
    assert_eq!(
        results["recorded_contacts"].as_array().unwrap().len(),
        contacts.len(),
        "every contact recorded"
    );

    let mut browser = Browser::launch(&chromium, 1280, 1400).await;
    browser.goto(&app.url(&format!("/jobs/{job}"))).await;
    browser
        .wait_for(
            "document.querySelector('[data-plot=\"cross-section\"]') !== null",
            WITHIN,
        )
        .await;

    // First the level of the strongest contact, by peak force, that contact selected.
    let first = section(&mut browser).await;
    check_section(&first, &results, level_of(strongest), "max_force");
    assert_eq!(first.selected, strongest as i64);
    // Its history is drawn before anything else is clicked (a later answer would
    // replace the clicked contact's).
    browser
        .wait_for(
            &format!(
                "document.querySelector('[data-plot=\"contact_forces\"] [data-series=\"c{strongest}_peaks\"]') !== null"
            ),
            WITHIN,
        )
        .await;

    // The slider: the level holding the strongest contact of the other levels.
    let other = (0..contacts.len())
        .filter(|&k| level_of(k) != level_of(strongest))
        .max_by(|&a, &b| force(a).total_cmp(&force(b)))
        .unwrap();
    assert!(
        force(other) > 0.0,
        "the run should load more than one level: {}",
        results["contacts"]
    );
    let level = level_of(other);
    browser
        .eval(&format!(
            "(() => {{ const slider = document.querySelector('[data-level-slider]'); slider.value = '{level}'; \
             slider.dispatchEvent(new Event('input', {{bubbles: true}})); }})()"
        ))
        .await;
    browser
        .wait_for(
            &format!("document.querySelector('[data-plot=\"cross-section\"]').dataset.level === '{level}'"),
            WITHIN,
        )
        .await;
    check_section(&section(&mut browser).await, &results, level, "max_force");

    // The statistic picker recolours the level's segments: impacts, then wear work rate.
    for measure in ["impacts", "wear_work_rate", "max_force"] {
        browser
            .eval(&format!(
                "(() => {{ const picker = document.querySelector('[data-picker=\"statistic\"]'); \
                 picker.value = '{measure}'; picker.dispatchEvent(new Event('change', {{bubbles: true}})); }})()"
            ))
            .await;
        browser
            .wait_for(
                &format!(
                    "document.querySelector('[data-plot=\"cross-section\"]').dataset.measure === '{measure}'"
                ),
                WITHIN,
            )
            .await;
        check_section(&section(&mut browser).await, &results, level, measure);
    }

    // A click on that contact's segment selects it and draws its force history.
    browser
        .click(&format!(
            "[data-plot=\"cross-section\"] line[data-contact=\"{other}\"]"
        ))
        .await;
    let envelope = format!("[data-plot=\"contact_forces\"] [data-series=\"c{other}_peaks\"]");
    browser
        .wait_for(&format!("document.querySelector('{envelope}') !== null"), WITHIN)
        .await;
    let clicked = section(&mut browser).await;
    assert_eq!(clicked.selected, other as i64, "the clicked contact is selected");
    check_section(&clicked, &results, level, "max_force");
    let drawn = browser
        .eval(&format!(
            "(() => {{ const figure = document.querySelector('[data-plot=\"contact_forces\"]'); \
             const of = (name) => figure.querySelector(`[data-series=\"${{name}}\"]`); \
             return {{peaks: Number(of('c{other}_peaks').dataset.max), samples: Number(of('c{other}').dataset.max), \
               line: Number(figure.querySelector('[data-hline]').dataset.hline)}}; }})()"
        ))
        .await;
    let peaks = values(
        &app.get_json(&format!(
            "/jobs/{job}/results/contact_forces_peaks?series=c{other}&max_points=2400"
        ))
        .await,
        &format!("c{other}"),
    );
    let served_peak = peaks.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let max_force = force(other);
    let drawn_peak = drawn["peaks"].as_f64().unwrap();
    assert!(
        same(drawn_peak, served_peak),
        "c{other}: envelope drawn up to {drawn_peak}, the served peaks column up to {served_peak}"
    );
    assert!(
        same(served_peak, max_force),
        "c{other}: peaks column up to {served_peak}, max_force {max_force}"
    );
    assert!(
        same(drawn["line"].as_f64().unwrap(), max_force),
        "reported peak line at {}, max_force {max_force}",
        drawn["line"]
    );
    assert!(
        drawn["samples"].as_f64().unwrap() <= max_force,
        "c{other}: samples drawn up to {}, above max_force {max_force}",
        drawn["samples"]
    );

    browser
        .eval(
            "document.querySelector('[data-level-slider]').closest('section').scrollIntoView({block: 'start'})",
        )
        .await;
    browser.screenshot(&screenshot_dir().join("job-hex.png")).await;
    browser.assert_no_exceptions();
}

/// The results of `job` once successful.
async fn finished(app: &crate::helpers::TestApp, job: &str) -> Value {
    let status = app.wait_for(job, &["successful"], Duration::from_secs(120)).await;
    assert_eq!(status["status"], "successful", "{status}");
    app.get_json(&format!("/jobs/{job}/results")).await
}

/// The band the dashboard colours a utilisation by (docs/margins.md): green below 0.8,
/// amber from 0.8 to 1, red from 1.
fn band(utilisation: &Value) -> Option<&'static str> {
    let u = utilisation.as_f64()?;
    Some(if u >= 1.0 {
        "over"
    } else if u >= 0.8 {
        "near"
    } else {
        "ok"
    })
}

/// With allowables set from a first run's own peaks (the worst contact at 0.9 of its
/// allowable, the worst stress at 1.2 of its), the page's margins card states the
/// served worst utilisation, and every pin of the cross-section and every bar of the
/// per-pin and per-contact utilisation charts carries the band of its served utilisation.
#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn a_hex_job_page_colours_its_pins_and_margins_by_utilisation() {
    let chromium = chromium(concat!(
        module_path!(),
        "::a_hex_job_page_colours_its_pins_and_margins_by_utilisation"
    ));
    let app = spawn_app_with_processes(vec![Arc::new(HexBundleDynamics)], |_| {}).await;
    let bare = finished(&app, &execute(&app, "hex-bundle-dynamics", &seven_pins()).await).await;
    let peak = bare["max_contact_force"]["force"].as_f64().unwrap();
    let stress = bare["max_bending"]["stress"].as_f64().unwrap();
    assert!(
        peak > 0.0 && stress > 0.0,
        "the bundle must rattle: {peak} N, {stress} Pa"
    );
    let mut inputs = seven_pins();
    inputs["inputs"]["output"]["allowables"] = json!({"contact_force": peak / 0.9, "stress": stress / 1.2});
    let job = execute(&app, "hex-bundle-dynamics", &inputs).await;
    let results = finished(&app, &job).await;
    let worst = results["worst_utilisation"].as_f64().unwrap();
    assert!(same(worst, 1.2), "the worst is the stress's 1.2: {worst}");

    let mut browser = Browser::launch(&chromium, 1280, 1400).await;
    browser.goto(&app.url(&format!("/jobs/{job}"))).await;
    browser
        .wait_for(
            "document.querySelector('[data-plot=\"cross-section\"]') !== null && \
             document.querySelector('[data-margins]') !== null",
            WITHIN,
        )
        .await;
    let page = browser
        .eval(
            "(() => { const bars = (id) => [...document.querySelectorAll(`[data-plot=\"${id}\"] rect[data-bar]`)] \
               .map((b) => [b.dataset.bar, Number(b.dataset.value), b.dataset.band || null]); \
             return {worst: Number(document.querySelector('[data-margins]').dataset.worst), \
               pins: [...document.querySelectorAll('[data-plot=\"cross-section\"] svg circle[data-pin]')] \
                 .map((c) => [Number(c.dataset.pin), c.dataset.band || null]), \
               pin_bars: bars('margin-pins'), contact_bars: bars('margin-contacts')}; })()",
        )
        .await;
    assert!(same(page["worst"].as_f64().unwrap(), worst), "{page}");
    let pins = results["pins"].as_array().unwrap();
    let drawn = page["pins"].as_array().unwrap();
    assert_eq!(drawn.len(), pins.len(), "{page}");
    for circle in drawn {
        let p = circle[0].as_u64().unwrap() as usize;
        assert_eq!(
            circle[1].as_str(),
            band(&pins[p]["utilisation"]),
            "pin {p}: drawn {circle}, served {}",
            pins[p]
        );
    }
    let pin_bars = page["pin_bars"].as_array().unwrap();
    assert_eq!(pin_bars.len(), pins.len(), "{page}");
    for (bar, pin) in pin_bars.iter().zip(pins) {
        assert!(
            same(bar[1].as_f64().unwrap(), pin["utilisation"].as_f64().unwrap()),
            "{bar} {pin}"
        );
        assert_eq!(bar[2].as_str(), band(&pin["utilisation"]), "{bar} {pin}");
    }
    let contacts = results["contacts"].as_array().unwrap();
    let contact_bars = page["contact_bars"].as_array().unwrap();
    assert_eq!(contact_bars.len(), contacts.len(), "{page}");
    for (bar, contact) in contact_bars.iter().zip(contacts) {
        assert_eq!(bar[2].as_str(), band(&contact["utilisation"]), "{bar}");
    }
    let bands: Vec<Option<&str>> = drawn.iter().map(|c| c[1].as_str()).collect();
    assert!(bands.contains(&Some("over")), "the worst pin is red: {bands:?}");
    browser
        .eval("document.querySelector('[data-margins]').scrollIntoView({block: 'start'})")
        .await;
    browser
        .screenshot(&screenshot_dir().join("job-hex-margins.png"))
        .await;
    browser.assert_no_exceptions();
}
