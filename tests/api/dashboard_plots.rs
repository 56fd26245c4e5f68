//! The dashboard used as a person uses it, in headless Chromium driven over the DevTools
//! protocol (`devtools.rs`): real mouse drags and moves, clicks, downloads.
//!
//! - A history plot zooms on the x range dragged across, the legend reads the served
//!   value under the cursor, the CSV export holds exactly the plotted samples of the
//!   shown range, and "reset zoom" brings the whole run back.
//! - Response spectra are drawn on log–log axes with the API's values: a job's
//!   displacement history (column and damping picked on the page) and a stored signal's,
//!   with the record's peak acceleration as a line; the signal list links to it.
//! - The job list at 1280 px: a failed job's bar stops where the run stopped, sweep runs
//!   can be hidden, and the table needs no horizontal scroll. The submit form gives
//!   every number its unit and every enumeration a select.
//!
//! Screenshots go to `target/dashboard-screenshots/` (see `dashboard.rs`).

use std::sync::Arc;
use std::time::Duration;

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;
use serde_json::{Value, json};

use crate::counting;
use crate::dashboard::{chromium, example, execute, same, screenshot_dir};
use crate::devtools::Browser;
use crate::helpers::spawn_app_with_processes;

const WITHIN: Duration = Duration::from_secs(30);

/// A number the page put in an attribute or returned (JavaScript's shortest round trip).
fn parsed(value: &Value) -> f64 {
    match value {
        Value::Number(n) => n.as_f64().unwrap(),
        Value::String(text) => text.parse().unwrap_or_else(|e| panic!("{text:?}: {e}")),
        other => panic!("not a number: {other}"),
    }
}

/// The plot area of figure `plot` (scrolled into view): left, top, width, height in CSS px.
async fn plot_area(browser: &mut Browser, plot: &str) -> [f64; 4] {
    let rect = browser
        .eval(&format!(
            "(() => {{ const over = document.querySelector('[data-plot=\"{plot}\"] .u-over'); \
             over.scrollIntoView({{block: 'center'}}); const r = over.getBoundingClientRect(); \
             return [r.left, r.top, r.width, r.height]; }})()"
        ))
        .await;
    [0, 1, 2, 3].map(|k| rect[k].as_f64().unwrap())
}

async fn attribute(browser: &mut Browser, selector: &str, name: &str) -> Value {
    browser
        .eval(&format!(
            "document.querySelector({selector:?}).getAttribute({name:?})"
        ))
        .await
}

/// The times and one column of a history as the job page asks for it (2400 points).
async fn served(app: &crate::helpers::TestApp, path: &str, column: &str) -> (Vec<f64>, Vec<f64>) {
    let document = app.get_json(path).await;
    let time = document["time"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    (time, crate::dashboard::values(&document, column))
}

#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn a_history_zooms_hovers_and_exports_and_spectra_are_drawn_on_log_axes() {
    let chromium = chromium(concat!(
        module_path!(),
        "::a_history_zooms_hovers_and_exports_and_spectra_are_drawn_on_log_axes"
    ));
    let app = spawn_app_with_processes(vec![Arc::new(CantileverImpact)], |_| {}).await;
    let mut cantilever = example("cantilever-impact.json");
    cantilever["inputs"]["solver"]["duration"] = json!(0.1);
    let job = execute(&app, "cantilever-impact", &cantilever).await;
    assert_eq!(
        app.wait_for(&job, &["successful"], Duration::from_secs(60)).await["status"],
        "successful"
    );
    // A stored signal: 4 s of a 5 Hz sine of 3 m/s², 200 samples per second.
    let time: Vec<f64> = (0..800).map(|k| k as f64 / 200.0).collect();
    let mut record = String::from("time,acceleration\n");
    for t in &time {
        record.push_str(&format!(
            "{t},{}\n",
            3.0 * (2.0 * std::f64::consts::PI * 5.0 * t).sin()
        ));
    }
    let signal = app.upload_signal(record, "text/csv", "").await;
    let signal_id = signal["id"].as_str().unwrap().to_owned();

    let mut browser = Browser::launch(&chromium, 1280, 1000).await;
    browser.goto(&app.url(&format!("/jobs/{job}"))).await;
    let figure = "[data-plot=\"tip_displacement\"]";
    browser
        .wait_for(
            &format!("document.querySelector('{figure} canvas') !== null"),
            WITHIN,
        )
        .await;

    // Zoom: drag across the second quarter of the plot.
    let full = [
        parsed(&attribute(&mut browser, figure, "data-x-min").await),
        parsed(&attribute(&mut browser, figure, "data-x-max").await),
    ];
    let [left, top, width, height] = plot_area(&mut browser, "tip_displacement").await;
    let middle = top + height / 2.0;
    browser
        .drag((left + 0.25 * width, middle), (left + 0.5 * width, middle))
        .await;
    browser
        .wait_for(
            &format!(
                "Number(document.querySelector('{figure}').getAttribute('data-x-max')) < {}",
                full[1]
            ),
            WITHIN,
        )
        .await;
    let zoomed = [
        parsed(&attribute(&mut browser, figure, "data-x-min").await),
        parsed(&attribute(&mut browser, figure, "data-x-max").await),
    ];
    let span = full[1] - full[0];
    let pixel = span / width;
    for (shown, expected) in zoomed.iter().zip([full[0] + 0.25 * span, full[0] + 0.5 * span]) {
        assert!(
            (shown - expected).abs() <= 2.0 * pixel,
            "zoomed to {zoomed:?}, dragged across {expected} (a pixel is {pixel} s; whole run {full:?})"
        );
    }
    let reset = format!("{figure} [data-action=\"reset-zoom\"]");
    assert_eq!(
        browser
            .eval(&format!("document.querySelector('{reset}').disabled"))
            .await,
        false,
        "reset zoom is offered once zoomed"
    );

    // Hover: the legend reads the served sample under the cursor.
    let [left, top, width, height] = plot_area(&mut browser, "tip_displacement").await;
    browser
        .mouse("mouseMoved", left + 0.4 * width, top + height / 2.0, false)
        .await;
    let hovered_time = parsed(
        &browser
            .wait_for(
                &format!("document.querySelector('{figure} [data-cursor-x]').getAttribute('data-cursor-x')"),
                WITHIN,
            )
            .await,
    );
    let hovered_value = parsed(
        &attribute(
            &mut browser,
            &format!("{figure} [data-series=\"numerical\"] .value"),
            "data-value",
        )
        .await,
    );
    let expected_time = zoomed[0] + 0.4 * (zoomed[1] - zoomed[0]);
    assert!(
        hovered_time >= zoomed[0]
            && hovered_time <= zoomed[1]
            && (hovered_time - expected_time).abs() < 0.02 * span,
        "hovered t = {hovered_time}, the cursor at about {expected_time} in {zoomed:?}"
    );
    let (times, numerical) = served(
        &app,
        &format!("/jobs/{job}/results/tip_displacement?max_points=2400"),
        "numerical",
    )
    .await;
    let row = times
        .iter()
        .position(|&t| t == hovered_time)
        .unwrap_or_else(|| panic!("hovered t = {hovered_time} is no served sample time"));
    assert_eq!(
        hovered_value, numerical[row],
        "the legend shows {hovered_value} at t = {hovered_time}, the history {}",
        numerical[row]
    );
    browser
        .screenshot(&screenshot_dir().join("plot-zoomed-hover.png"))
        .await;

    // Export: the plotted samples of the shown range, as CSV, the hovered one included.
    browser.click(&format!("{figure} [data-export=\"csv\"]")).await;
    let (name, bytes) = browser.downloaded().await;
    assert_eq!(name, "tip_displacement.csv");
    let text = String::from_utf8(bytes).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("time,numerical_peaks,reference_peaks,numerical,reference"),
        "{}",
        &text[..text.len().min(300)]
    );
    let rows: Vec<Vec<&str>> = lines.map(|line| line.split(',').collect()).collect();
    let (peak_times, _) = served(
        &app,
        &format!("/jobs/{job}/results/tip_displacement_peaks?max_points=2400"),
        "numerical",
    )
    .await;
    let mut plotted: Vec<f64> = times
        .iter()
        .chain(&peak_times)
        .copied()
        .filter(|t| (zoomed[0]..=zoomed[1]).contains(t))
        .collect();
    plotted.sort_by(f64::total_cmp);
    plotted.dedup();
    let exported: Vec<f64> = rows.iter().map(|row| row[0].parse().unwrap()).collect();
    assert_eq!(
        exported, plotted,
        "the exported times are the plotted ones in the shown range"
    );
    let at_hover = rows
        .iter()
        .find(|row| row[0].parse::<f64>().unwrap() == hovered_time)
        .expect("the hovered sample is exported");
    assert_eq!(at_hover[3].parse::<f64>().unwrap(), hovered_value);

    // Reset: the whole run again.
    browser.click(&reset).await;
    browser
        .wait_for(
            &format!(
                "Number(document.querySelector('{figure}').getAttribute('data-x-max')) === {}",
                full[1]
            ),
            WITHIN,
        )
        .await;

    // The job's response spectrum, log–log: the API's values, column and damping picked.
    let spectrum = "[data-plot=\"response-spectrum\"]";
    browser
        .wait_for(
            &format!("document.querySelector('{spectrum} canvas') !== null"),
            WITHIN,
        )
        .await;
    assert_eq!(attribute(&mut browser, spectrum, "data-log-x").await, "true");
    assert_eq!(attribute(&mut browser, spectrum, "data-log-y").await, "true");
    let api = app
        .get_json(&format!(
            "/jobs/{job}/results/tip_displacement/response_spectrum?series=numerical&damping=0.02&damping=0.05&f_min=1&f_max=1000&points=200"
        ))
        .await;
    check_spectrum(&mut browser, spectrum, &api, "peak_acceleration").await;
    browser
        .eval(
            "(() => { const card = document.querySelector('[data-card=\"response-spectrum\"]'); \
             card.querySelector('[data-control=\"series\"]').value = 'reference'; \
             card.querySelector('[data-control=\"damping\"]').value = '10 %'; })()",
        )
        .await;
    browser
        .click("[data-card=\"response-spectrum\"] [data-action=\"draw-spectrum\"]")
        .await;
    browser
        .wait_for(
            &format!("document.querySelector('{spectrum} [data-series=\"psa_0.1\"]') !== null"),
            WITHIN,
        )
        .await;
    let api = app
        .get_json(&format!(
            "/jobs/{job}/results/tip_displacement/response_spectrum?series=reference&damping=0.1&f_min=1&f_max=1000&points=200"
        ))
        .await;
    check_spectrum(&mut browser, spectrum, &api, "peak_acceleration").await;
    browser
        .screenshot(&screenshot_dir().join("job-response-spectrum.png"))
        .await;

    // The signal list links to the signal; its page draws its spectrum with the PGA.
    browser.goto(&app.url("/signals")).await;
    let link = browser
        .wait_for(
            &format!("document.querySelector('tr[data-signal=\"{signal_id}\"] a')?.getAttribute('href')"),
            WITHIN,
        )
        .await;
    assert_eq!(link, format!("/signals/{signal_id}").as_str());
    browser.goto(&app.url(&format!("/signals/{signal_id}"))).await;
    let spectrum = "[data-plot=\"signal-spectrum\"]";
    browser
        .wait_for(
            &format!("document.querySelector('{spectrum} canvas') !== null"),
            WITHIN,
        )
        .await;
    assert_eq!(attribute(&mut browser, spectrum, "data-log-x").await, "true");
    let api = app
        .get_json(&format!(
            "/signals/{signal_id}/spectrum?damping=0.02&damping=0.05&damping=0.1&f_min=0.1&f_max=50&points=200"
        ))
        .await;
    check_spectrum(&mut browser, spectrum, &api, "pga").await;
    let record = browser
        .wait_for(
            "document.querySelector('[data-plot=\"signal-record\"] [data-series=\"acceleration\"]')?.getAttribute('data-points')",
            WITHIN,
        )
        .await;
    assert_eq!(parsed(&record), 800.0);
    browser.screenshot(&screenshot_dir().join("signal.png")).await;
    browser.assert_no_exceptions();
}

/// The spectrum plot `figure` draws the spectrum document `api`: one curve per damping
/// ratio with the same number of points and extremes, and a line at `api[peak]`.
async fn check_spectrum(browser: &mut Browser, figure: &str, api: &Value, peak: &str) {
    let curves = api["pseudo_acceleration"].as_array().unwrap();
    let drawn = browser
        .eval(&format!(
            "document.querySelectorAll('{figure} [data-series]').length"
        ))
        .await;
    assert_eq!(drawn, curves.len(), "one curve per damping ratio");
    for curve in curves {
        let name = format!("psa_{}", curve["damping"]);
        let key = format!("{figure} [data-series=\"{name}\"]");
        let values: Vec<f64> = curve["values"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        assert_eq!(
            parsed(&attribute(browser, &key, "data-points").await),
            values.len() as f64
        );
        assert!(
            same(parsed(&attribute(browser, &key, "data-max").await), max),
            "{name}: max {max}"
        );
        assert!(
            same(parsed(&attribute(browser, &key, "data-min").await), min),
            "{name}: min {min}"
        );
    }
    let line = parsed(&attribute(browser, &format!("{figure} [data-hline]"), "data-hline").await);
    assert!(
        same(line, api[peak].as_f64().unwrap()),
        "line at {line}, {peak} {}",
        api[peak]
    );
}

/// A synthetic earthquake's record, picked in the job's spectrum card, is drawn at its
/// target's damping and over its band, with the target dashed beside it and the largest
/// deviation in the caption: the API's numbers.
#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn a_synthetic_earthquake_is_drawn_against_its_target() {
    let chromium = chromium(concat!(
        module_path!(),
        "::a_synthetic_earthquake_is_drawn_against_its_target"
    ));
    let app = spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |_| {}).await;
    let mut earthquake = example("bundle-earthquake.json");
    earthquake["inputs"]["bundle"]["pins"] = json!(2);
    earthquake["inputs"]["solver"]["duration"] = json!(0.5);
    let job = execute(&app, "bundle-dynamics", &earthquake).await;
    assert_eq!(
        app.wait_for(&job, &["successful"], Duration::from_secs(120))
            .await["status"],
        "successful"
    );
    let target = &earthquake["inputs"]["excitation"]["base_acceleration"]["target"];
    let band = target["frequencies"].as_array().cloned().unwrap_or_default();

    let mut browser = Browser::launch(&chromium, 1280, 1000).await;
    browser.goto(&app.url(&format!("/jobs/{job}"))).await;
    let card = "[data-card=\"response-spectrum\"]";
    browser
        .wait_for(
            &format!("document.querySelector('{card} [data-control=\"output\"]') !== null"),
            WITHIN,
        )
        .await;
    browser
        .eval(&format!(
            "(() => {{ const output = document.querySelector('{card} [data-control=\"output\"]'); \
             output.value = 'excitation'; output.dispatchEvent(new Event('change')); }})()"
        ))
        .await;
    browser
        .wait_for(
            &format!(
                "document.querySelector('{card} [data-control=\"series\"]').value === 'base_acceleration' \
                 && Number(document.querySelector('{card} [data-control=\"f_min\"]').value) === {}",
                band[0]
            ),
            WITHIN,
        )
        .await;
    browser
        .click(&format!("{card} [data-action=\"draw-spectrum\"]"))
        .await;
    let spectrum = "[data-plot=\"response-spectrum\"]";
    browser
        .wait_for(
            &format!("document.querySelector('{spectrum} [data-series=\"target\"]') !== null"),
            WITHIN,
        )
        .await;
    let api = app
        .get_json(&format!(
            "/jobs/{job}/results/excitation/response_spectrum?series=base_acceleration&damping={}&f_min={}&f_max={}&points=200",
            target["damping"],
            band[0],
            band[band.len() - 1]
        ))
        .await;
    let wanted: Vec<f64> = api["target"]["pseudo_acceleration"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .iter()
        .map(|v| v.as_f64().unwrap_or(f64::NAN))
        .collect();
    let key = format!("{spectrum} [data-series=\"target\"]");
    assert_eq!(
        parsed(&attribute(&mut browser, &key, "data-points").await),
        wanted.len() as f64
    );
    let max = wanted.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(same(
        parsed(&attribute(&mut browser, &key, "data-max").await),
        max
    ));
    let key = format!("{spectrum} [data-series=\"psa_{}\"]", target["damping"]);
    assert_eq!(parsed(&attribute(&mut browser, &key, "data-points").await), 200.0);
    let deviation = api["target"]["max_deviation"].as_f64().unwrap_or(f64::NAN);
    assert!(deviation <= 0.1, "{}", api["target"]);
    let shown = attribute(
        &mut browser,
        &format!("{card} [data-target-deviation]"),
        "data-target-deviation",
    )
    .await;
    assert!(same(parsed(&shown), deviation), "{shown} against {deviation}");
    browser
        .screenshot(&screenshot_dir().join("job-earthquake-spectrum.png"))
        .await;
    browser.assert_no_exceptions();
}

#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn the_job_list_fits_1280_px_shows_where_a_failed_run_stopped_and_hides_sweep_runs() {
    let chromium = chromium(concat!(
        module_path!(),
        "::the_job_list_fits_1280_px_shows_where_a_failed_run_stopped_and_hides_sweep_runs"
    ));
    let app =
        spawn_app_with_processes(vec![Arc::new(CantileverImpact), Arc::new(BundleDynamics)], |_| {}).await;
    let failed = app.submit(json!({"steps": 100, "fail_at": 61})).await;
    assert_eq!(app.wait_until_finished(&failed).await["progress"], 60);
    let sweep = app
        .create_sweep(json!({"process": counting::ID, "inputs": {"steps": 1},
                             "axes": [{"pointer": "/steps", "values": [1, 2]}]}))
        .await;
    app.wait_for_sweep(&sweep, &["successful"], WITHIN).await;
    let mut cantilever = example("cantilever-impact.json");
    cantilever["inputs"]["solver"]["duration"] = json!(0.02);
    let first = execute(&app, "cantilever-impact", &cantilever).await;
    app.wait_for(&first, &["successful"], WITHIN).await;
    // A poor run, whose long status message sits in the table too: 5 steps per contact
    // period (see dashboard.rs).
    let results = app.get_json(&format!("/jobs/{first}/results")).await;
    cantilever["inputs"]["solver"]["check"] = json!("none");
    cantilever["inputs"]["solver"]["time_step"] = json!(
        results["numerical"]["time_step"].as_f64().unwrap()
            * results["quality"]["steps_per_contact_period"].as_f64().unwrap()
            / 5.0
    );
    let alone = execute(&app, "cantilever-impact", &cantilever).await;
    let status = app.wait_for(&alone, &["successful"], WITHIN).await;
    assert!(status["message"].as_str().unwrap().len() > 100, "{status}");

    let mut browser = Browser::launch(&chromium, 1280, 800).await;
    browser.goto(&app.url("/jobs?limit=30")).await;
    browser
        .wait_for(
            &format!("document.querySelector('tr[data-job=\"{alone}\"]') !== null"),
            WITHIN,
        )
        .await;
    // Nothing wider than its card.
    let overflow = browser
        .eval(
            "(() => { const table = document.querySelector('table[data-list=\"jobs\"]'); \
             return [table.scrollWidth, table.parentElement.clientWidth, document.documentElement.scrollWidth, \
             document.documentElement.clientWidth]; })()",
        )
        .await;
    assert!(
        overflow[0].as_f64() <= overflow[1].as_f64() && overflow[2].as_f64() <= overflow[3].as_f64(),
        "the table is [width, room, page width, window] = {overflow} px"
    );
    browser.screenshot(&screenshot_dir().join("jobs-1280.png")).await;
    // The verdict column: the poor run says so, as its status does.
    let verdict = browser
        .eval(&format!(
            "document.querySelector('tr[data-job=\"{alone}\"] [data-verdict]')?.getAttribute('data-verdict')"
        ))
        .await;
    assert_eq!(verdict, status["verdict"], "{status}");
    assert!(status["verdict"].is_string(), "{status}");
    // The failed run's bar stops at 60 %.
    let bar = browser
        .eval(&format!(
            "(() => {{ const row = document.querySelector('tr[data-job=\"{failed}\"]'); \
             const bar = row.querySelector('[role=progressbar]'); \
             return [bar.getAttribute('data-value'), row.querySelector('.percent').textContent]; }})()"
        ))
        .await;
    assert_eq!(parsed(&bar[0]), 0.6, "{bar}");
    assert_eq!(bar[1], "stopped at 60 %");
    // Without sweep runs: the three jobs submitted on their own.
    browser.click("[data-in-sweep=\"false\"]").await;
    browser
        .wait_for(
            "location.search.includes('inSweep=false') && document.querySelector('tr[data-job]') !== null",
            WITHIN,
        )
        .await;
    let listed = browser
        .eval("[...document.querySelectorAll('tr[data-job]')].map((row) => row.getAttribute('data-job'))")
        .await;
    assert_eq!(listed, json!([alone, first, failed]));
    // The failed job's own page says the same.
    browser.goto(&app.url(&format!("/jobs/{failed}"))).await;
    let progress = browser
        .wait_for(
            "document.querySelector('[data-job-status] .percent')?.textContent",
            WITHIN,
        )
        .await;
    assert_eq!(progress, "stopped at 60 %");

    // The submit form: every number with its unit, enumerations as selects.
    browser
        .goto(&app.url("/ui/submit?example=bundle-random-gaps.json"))
        .await;
    browser
        .wait_for(
            "document.querySelector('[data-pointer=\"/inputs/pin/length\"]') !== null",
            WITHIN,
        )
        .await;
    let form = browser
        .eval(
            "(() => { const unitOf = (p) => document.querySelector(`[data-pointer=\"${p}\"]`)\
               .closest('label').querySelector('[data-unit]')?.getAttribute('data-unit'); \
             const numbers = [...document.querySelectorAll('input[data-pointer]')].filter((input) => \
               /^-?[0-9.]/.test(input.value) || /^\\[\\s*-?[0-9.]/.test(input.value)); \
             return {numbers: numbers.length, \
               unitless: numbers.filter((input) => !input.closest('label').querySelector('[data-unit]')) \
                 .map((input) => input.dataset.pointer), \
               length: unitOf('/inputs/pin/length'), density: unitOf('/inputs/pin/density'), \
               stiffness: unitOf('/inputs/bundle/stiffness'), damping_ratio: unitOf('/inputs/pin/damping_ratio'), \
               scheme: document.querySelector('[data-pointer=\"/inputs/solver/scheme\"]').tagName, \
               schemes: [...document.querySelectorAll('[data-pointer=\"/inputs/solver/scheme\"] option')].map((o) => o.value), \
               section: document.querySelector('[data-pointer=\"/inputs/pin/section/type\"]').tagName}; })()",
        )
        .await;
    assert!(form["numbers"].as_u64().unwrap() > 10, "{form}");
    assert_eq!(
        form["unitless"],
        json!([]),
        "number fields without a unit: {form}"
    );
    assert_eq!(form["length"], "m");
    assert_eq!(form["density"], "kg/m³");
    assert_eq!(form["stiffness"], "N/m");
    assert_eq!(form["damping_ratio"], "dimensionless");
    assert_eq!(form["scheme"], "SELECT");
    assert_eq!(
        form["schemes"],
        json!(["central_difference", "tchamwa", "exact_modal"])
    );
    assert_eq!(form["section"], "SELECT");
    // Another section type offers its own members, empty, and keeps the form's JSON valid.
    browser
        .eval(
            "(() => { const select = document.querySelector('[data-pointer=\"/inputs/pin/section/type\"]'); \
             select.value = 'explicit'; select.dispatchEvent(new Event('change', {bubbles: true})); })()",
        )
        .await;
    let explicit = browser
        .wait_for(
            "document.querySelector('[data-pointer=\"/inputs/pin/section/area\"]') && \
             [document.querySelector('[data-pointer=\"/inputs/pin/section/area\"]').closest('label') \
               .querySelector('[data-unit]').getAttribute('data-unit'), \
              document.querySelector('[data-pointer=\"/inputs/pin/section/outer_diameter\"]') === null, \
              JSON.parse(document.querySelector('textarea.json').value).inputs.pin.section.type]",
            WITHIN,
        )
        .await;
    assert_eq!(explicit, json!(["m²", true, "explicit"]));
    browser
        .screenshot(&screenshot_dir().join("submit-units.png"))
        .await;
    browser.assert_no_exceptions();
}
