//! The dashboard in a real browser: headless Chromium loads each page from a real
//! server (real processes, fresh database), runs its scripts against the JSON API, and
//! the DOM it ends with must hold what the page promises: the running job's progress
//! bar, the finished cantilever's numerical and reference curves (the very extremes of
//! the served histories) and their spectra with the f_err of the results, the bundle's
//! peak-force grid, the calibration map with its f_err = 0.2 contour, the Monte Carlo
//! histogram, and refused inputs marked next to their field. Every job shows its quality
//! verdict as a badge with its reasons (a poor one too), and the force plots draw the
//! peak-per-interval envelope whose maximum is the reported peak force.
//!
//! Screenshots go to `target/dashboard-screenshots/<page>.png`. Without Chromium, or with
//! `CHOCMODAL_SKIP_BROWSER_TESTS=1`, these tests are ignored (`build.rs` looks when the
//! package is built); under `CI=true` they are not: they fail, saying how to install
//! Chromium, and the skip variable fails them too (see `skip.rs`).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{TestApp, spawn_app_with_processes};

/// Headless Chromium for `test` (a skip asked for under CI fails it, see [`crate::skip`]).
pub(crate) fn chromium(test: &str) -> PathBuf {
    crate::skip::refuse_under_ci("CHOCMODAL_SKIP_BROWSER_TESTS", test, "needs headless Chromium");
    let candidates = std::env::var_os("CHOCMODAL_CHROMIUM")
        .map(PathBuf::from)
        .into_iter()
        .chain(
            [
                "/usr/bin/chromium",
                "/usr/bin/chromium-browser",
                "/usr/bin/google-chrome",
            ]
            .map(PathBuf::from),
        );
    let found = candidates.into_iter().find(|path| path.is_file());
    found.unwrap_or_else(|| {
        panic!(
            "the dashboard tests need headless Chromium: install Debian's `chromium` package \
             (`apt-get install chromium`; .ci/run does it), point CHOCMODAL_CHROMIUM at a \
             Chromium binary, or set CHOCMODAL_SKIP_BROWSER_TESTS=1 to ignore them (outside CI)"
        )
    })
}

pub(crate) fn screenshot_dir() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
    let dir = target.join("dashboard-screenshots");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Loads `url`, lets its scripts run for `budget_ms` of virtual time (the clock jumps
/// ahead while nothing is pending; network fetches are awaited), saves a screenshot and
/// returns the DOM.
async fn load(browser: &Path, url: &str, page: &str, height: u32, budget_ms: u32) -> String {
    let profile = tempfile::TempDir::new().unwrap();
    let screenshot = screenshot_dir().join(format!("{page}.png"));
    let run = tokio::process::Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--no-first-run",
            "--hide-scrollbars",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("--virtual-time-budget={budget_ms}"))
        .arg(format!("--window-size=1280,{height}"))
        .arg(format!("--screenshot={}", screenshot.display()))
        .arg("--dump-dom")
        .arg(url)
        .kill_on_drop(true)
        .output();
    let output = tokio::time::timeout(Duration::from_secs(90), run)
        .await
        .unwrap_or_else(|_| panic!("Chromium did not finish loading {url} within 90 s"))
        .expect("Chromium starts");
    let log = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "Chromium failed on {url}: {log}");
    // Uncaught exceptions in the page's scripts show up in the console log.
    let errors: Vec<&str> = log.lines().filter(|l| l.contains("Uncaught")).collect();
    assert!(errors.is_empty(), "script errors on {url}: {errors:#?}");
    let dom = String::from_utf8(output.stdout).unwrap();
    assert!(dom.contains("</html>"), "no DOM from {url}: {dom}");
    dom
}

/// The opening tags of the elements whose opening tag contains `marker`.
fn tags<'a>(dom: &'a str, marker: &str) -> Vec<&'a str> {
    dom.match_indices(marker)
        .map(|(at, _)| {
            let start = dom[..at].rfind('<').unwrap();
            let end = at + dom[at..].find('>').unwrap();
            &dom[start..=end]
        })
        .collect()
}

fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

fn number(tag: &str, name: &str) -> f64 {
    attribute(tag, name)
        .unwrap_or_else(|| panic!("no {name} in {tag}"))
        .parse()
        .unwrap_or_else(|e| panic!("{name} of {tag}: {e}"))
}

/// The markup of the element starting at the first tag containing `marker`, up to `</closing>`.
fn element<'a>(dom: &'a str, marker: &str, closing: &str) -> &'a str {
    let at = dom
        .find(marker)
        .unwrap_or_else(|| panic!("no {marker} on the page"));
    let start = dom[..at].rfind('<').unwrap();
    let end = at
        + dom[at..]
            .find(closing)
            .unwrap_or_else(|| panic!("{marker} is not closed"));
    &dom[start..end + closing.len()]
}

/// Equal up to the last bit or two: serde_json's default float parsing may be one ulp off.
pub(crate) fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-15 * b.abs()
}

pub(crate) fn values(document: &Value, name: &str) -> Vec<f64> {
    document["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap()["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

pub(crate) fn example(name: &str) -> Value {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

pub(crate) async fn execute(app: &TestApp, process: &str, body: &Value) -> String {
    let response = app.post_execution(process, body).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned()
}

#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn the_dashboard_draws_progress_curves_spectra_maps_and_field_errors_in_a_browser() {
    let browser = chromium(concat!(
        module_path!(),
        "::the_dashboard_draws_progress_curves_spectra_maps_and_field_errors_in_a_browser"
    ));
    let app =
        spawn_app_with_processes(vec![Arc::new(CantileverImpact), Arc::new(BundleDynamics)], |_| {}).await;
    let within = Duration::from_secs(60);

    // A slow job holds one worker (about 30 s, dismissed at the end); the other computes the rest.
    let slow = app.submit(json!({"steps": 600, "step_ms": 50.0})).await;
    let mut cantilever = example("cantilever-impact.json");
    cantilever["inputs"]["solver"]["duration"] = json!(0.1);
    let cantilever = execute(&app, "cantilever-impact", &cantilever).await;
    let mut bundle = example("bundle-random-gaps.json");
    bundle["inputs"]["pin"]["modes"] = json!(8);
    bundle["inputs"]["solver"]["duration"] = json!(0.03);
    let bundle = execute(&app, "bundle-dynamics", &bundle).await;
    let mut calibration = example("sweep-calibration.json");
    calibration["inputs"]["solver"]["duration"] = json!(0.05);
    calibration["inputs"]["beam"]["elements"] = json!(10);
    calibration["inputs"]["beam"]["modes"] = json!(6);
    calibration["inputs"]["reference"]["modes"] = json!(10);
    calibration["axes"] = json!([
        {"pointer": "/contact/rk", "logspace": [1.0, 1e6, 3]},
        {"pointer": "/solver/time_step", "values": [1e-5, 3e-5, 1e-4]}
    ]);
    let calibration = app.create_sweep(calibration).await;
    let mut gaps = example("sweep-gaps.json");
    gaps["samples"] = json!(8);
    gaps["inputs"]["solver"]["duration"] = json!(0.02);
    let gaps = app.create_sweep(gaps).await;
    for job in [&cantilever, &bundle] {
        assert_eq!(
            app.wait_for(job, &["successful"], within).await["status"],
            "successful"
        );
    }
    // A poor job, from the verdict's definition: fewer than 8 steps per period of the
    // fastest motion is poor, and steps per period go as 1/Δt, so the cantilever's step
    // times its steps per period / 5 gives 5 (central difference is stable up to π).
    let cantilever_results = app.get_json(&format!("/jobs/{cantilever}/results")).await;
    let mut poor = example("cantilever-impact.json");
    poor["inputs"]["solver"]["duration"] = json!(0.05);
    poor["inputs"]["solver"]["check"] = json!("none");
    poor["inputs"]["solver"]["time_step"] = json!(
        cantilever_results["numerical"]["time_step"].as_f64().unwrap()
            * cantilever_results["quality"]["steps_per_contact_period"]
                .as_f64()
                .unwrap()
            / 5.0
    );
    let poor = execute(&app, "cantilever-impact", &poor).await;
    // A job with a plausibility warning: a cantilever released from rest.
    let mut still = example("cantilever-impact.json");
    still["inputs"]["release"]["tip_displacement"] = json!(0.0);
    still["inputs"]["solver"]["duration"] = json!(0.02);
    still["inputs"]["solver"]["check"] = json!("none");
    let still = execute(&app, "cantilever-impact", &still).await;
    assert_eq!(
        app.wait_for(&poor, &["successful"], within).await["status"],
        "successful"
    );
    // The coarse steps of the stiffest contact are beyond the critical step: those runs
    // fail, so the calibration sweep is partial.
    app.wait_for_sweep(&calibration, &["partial"], within).await;
    app.wait_for_sweep(&gaps, &["successful"], within).await;
    let deadline = std::time::Instant::now() + within;
    let progress = loop {
        let progress = app.status(&slow).await["progress"].as_u64().unwrap();
        if progress >= 1 {
            break progress as f64 / 100.0;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "the slow job does not progress"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    };

    // The job list: the slow job's progress bar, between 0 and 1, as far as the job got.
    let dom = load(&browser, &app.url("/jobs?limit=30"), "jobs", 900, 3000).await;
    let row = element(&dom, &format!("data-job=\"{slow}\""), "</tr>");
    let bar = tags(row, "role=\"progressbar\"");
    assert_eq!(bar.len(), 1, "{row}");
    let fraction = number(bar[0], "data-value");
    assert!(
        fraction >= progress && fraction < 1.0,
        "progress {fraction} drawn, {progress} before loading"
    );
    // And the time left at its pace so far, from the status's estimated finish.
    assert!(
        row.contains("data-estimated-finish=\"") && row.contains(" left</span>"),
        "{row}"
    );
    let row = element(&dom, &format!("data-job=\"{cantilever}\""), "</tr>");
    assert!(row.contains("data-status=\"successful\""), "{row}");

    // The cantilever: both curves are the served histories, extremes included.
    let dom = load(
        &browser,
        &app.url(&format!("/jobs/{cantilever}")),
        "job-cantilever",
        2600,
        6000,
    )
    .await;
    let history = app
        .get_json(&format!("/jobs/{cantilever}/results/tip_displacement"))
        .await;
    let figure = element(&dom, "data-plot=\"tip_displacement\"", "</figure>");
    for name in ["numerical", "reference"] {
        let path = tags(figure, &format!("data-series=\"{name}\""));
        assert_eq!(path.len(), 1, "one {name} curve");
        let served = values(&history, name);
        let (min, max) = served
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        assert!(
            same(number(path[0], "data-min"), min),
            "{name} minimum drawn: {}, served {min}",
            path[0]
        );
        assert!(
            same(number(path[0], "data-max"), max),
            "{name} maximum drawn: {}, served {max}",
            path[0]
        );
        assert!(number(path[0], "data-points") > 500.0, "{}", path[0]);
    }
    // uPlot drew them: its canvas is in the figure.
    assert!(
        figure.contains("<canvas"),
        "no canvas in the tip_displacement figure"
    );
    let results = app.get_json(&format!("/jobs/{cantilever}/results")).await;
    let f_err = results["comparison"]["f_err"].as_f64().unwrap();
    let spectrum = element(&dom, "data-plot=\"tip_displacement-spectrum\"", "</figure>");
    assert!(
        spectrum.contains("data-log-y=\"true\""),
        "{}",
        &spectrum[..spectrum.len().min(600)]
    );
    for name in ["numerical", "reference"] {
        let path = tags(spectrum, &format!("data-series=\"{name}\""));
        assert_eq!(path.len(), 1, "one {name} spectrum");
        assert!(number(path[0], "data-points") >= 5.0, "{}", path[0]);
    }
    let shown = number(tags(spectrum, "data-spectrum-f-err")[0], "data-spectrum-f-err");
    assert!(same(shown, f_err), "f_err {shown} shown, {f_err} in the results");
    assert!(same(number(tags(&dom, "data-f-err")[0], "data-f-err"), f_err));
    assert!(dom.contains("tip_displacement.csv") && dom.contains("contact_force-spectrum.csv"));
    // Its verdict, as a badge in the quality card and next to f_err, with its reasons.
    let verdict = results["quality"]["verdict"].as_str().unwrap();
    assert_eq!(
        tags(&dom, &format!("data-quality=\"{verdict}\"")).len(),
        2,
        "the {verdict} badge in the quality card and next to f_err"
    );
    let reasons = results["quality"]["reasons"].as_array().unwrap();
    if !reasons.is_empty() {
        let list = element(&dom, "data-quality-reasons=", "</ul>");
        assert_eq!(list.matches("<li>").count(), reasons.len(), "{list}");
    }
    // The force plot: the envelope's maximum and the line drawn at the reported peak
    // are the reported maximum contact force; the samples never exceed it.
    let max_force = results["numerical"]["max_contact_force"].as_f64().unwrap();
    let figure = element(&dom, "data-plot=\"contact_force\"", "</figure>");
    let envelope = tags(figure, "data-series=\"numerical_peaks\"");
    assert_eq!(envelope.len(), 1, "one numerical envelope");
    assert!(
        same(number(envelope[0], "data-max"), max_force),
        "envelope maximum drawn: {}, reported {max_force}",
        envelope[0]
    );
    let sampled = tags(figure, "data-series=\"numerical\"");
    assert!(number(sampled[0], "data-max") <= max_force, "{}", sampled[0]);
    assert!(
        same(number(tags(figure, "data-hline=")[0], "data-hline"), max_force),
        "{figure}"
    );
    assert_eq!(tags(figure, "data-envelope=\"true\"").len(), 1);

    // The poor job: a poor badge, every reason listed, and the message saying so.
    let dom = load(
        &browser,
        &app.url(&format!("/jobs/{poor}")),
        "job-poor",
        2600,
        6000,
    )
    .await;
    let poor_results = app.get_json(&format!("/jobs/{poor}/results")).await;
    assert_eq!(poor_results["quality"]["verdict"], "poor");
    assert_eq!(tags(&dom, "data-quality=\"poor\"").len(), 2, "poor badges");
    let reasons = poor_results["quality"]["reasons"].as_array().unwrap();
    let list = element(&dom, "data-quality-reasons=", "</ul>");
    assert_eq!(list.matches("<li>").count(), reasons.len(), "{list}");
    let first = reasons[0].as_str().unwrap();
    assert!(list.contains(first), "{first} not in {list}");
    let status = element(&dom, "data-job-status=", "</table>");
    assert!(status.contains("quality poor"), "{status}");

    // Warnings: none for the example's cantilever; the one of a cantilever released from
    // rest under its status, at its pointer.
    let dom = load(
        &browser,
        &app.url(&format!("/jobs/{cantilever}")),
        "job-cantilever",
        900,
        3000,
    )
    .await;
    assert!(tags(&dom, "data-warnings=").is_empty(), "no warnings list");
    let status = app.wait_for(&still, &["successful"], within).await;
    assert_eq!(status["warnings"][0]["code"], "nothing_excites", "{status}");
    let dom = load(
        &browser,
        &app.url(&format!("/jobs/{still}")),
        "job-still",
        900,
        3000,
    )
    .await;
    let list = element(&dom, "data-warnings=\"1\"", "</ul>");
    assert!(
        list.contains("data-warning=\"nothing_excites\"")
            && list.contains("/inputs/release/tip_displacement"),
        "{list}"
    );

    // The bundle: one grid cell per contact, the strongest contact's history drawn.
    let dom = load(
        &browser,
        &app.url(&format!("/jobs/{bundle}")),
        "job-bundle",
        2000,
        6000,
    )
    .await;
    let results = app.get_json(&format!("/jobs/{bundle}/results")).await;
    let contacts = results["contacts"].as_array().unwrap();
    let grid = element(&dom, "data-plot=\"max-force-grid\"", "</figure>");
    assert_eq!(tags(grid, "data-contact=").len(), contacts.len());
    let strongest = results["max_contact_force"]["contact"].as_u64().unwrap();
    let cell = tags(grid, &format!("data-contact=\"{strongest}\""))[0];
    assert!(same(
        number(cell, "data-value"),
        contacts[strongest as usize]["max_force"].as_f64().unwrap()
    ));
    let figure = element(&dom, "data-plot=\"contact_forces\"", "</figure>");
    let path = tags(figure, &format!("data-series=\"c{strongest}\""));
    assert_eq!(path.len(), 1, "{figure}");
    assert!(number(path[0], "data-max") > 0.0);
    // The envelope of that contact peaks at its reported max_force, to the last bit.
    let envelope = tags(figure, &format!("data-series=\"c{strongest}_peaks\""));
    assert_eq!(envelope.len(), 1, "{figure}");
    let max_force = contacts[strongest as usize]["max_force"].as_f64().unwrap();
    assert!(
        same(number(envelope[0], "data-max"), max_force),
        "envelope maximum drawn: {}, reported {max_force}",
        envelope[0]
    );
    let verdict = results["quality"]["verdict"].as_str().unwrap();
    assert_eq!(
        tags(&dom, &format!("data-quality=\"{verdict}\"")).len(),
        2,
        "the {verdict} badge in the quality card and next to the peak force"
    );
    // Its impacts: one table row per impact of that contact (up to a page of 50), the
    // run's histogram with every impact, and a statistic picker for the grid.
    let impacts = contacts[strongest as usize]["impacts"].as_u64().unwrap();
    assert!(impacts > 0);
    let table = element(&dom, &format!("data-impacts-table=\"{strongest}\""), "</table>");
    assert_eq!(
        tags(table, "data-impact=").len() as u64,
        impacts.min(50),
        "{table}"
    );
    let histogram = element(&dom, "data-plot=\"impact-histogram\"", "</figure>");
    let counted: f64 = tags(histogram, "data-value=")
        .iter()
        .map(|bar| number(bar, "data-value"))
        .sum();
    assert_eq!(
        counted as u64,
        results["impact_summary"]["impacts"].as_u64().unwrap()
    );
    let picker = element(&dom, "data-picker=\"statistic\"", "</select>");
    assert!(picker.matches("<option").count() >= 10, "{picker}");

    // The calibration map: every run a cell, validity as aggregated, and the contour.
    let dom = load(
        &browser,
        &app.url(&format!("/sweeps/{calibration}")),
        "sweep-calibration",
        1700,
        4000,
    )
    .await;
    let aggregate = app.sweep_results(&calibration).await;
    let cells = aggregate["aggregates"]["calibration"]["cells"]
        .as_array()
        .unwrap();
    let map = element(&dom, "data-plot=\"calibration\"", "</figure>");
    assert_eq!(tags(map, "data-cell=").len(), 9);
    let valid = cells.iter().filter(|c| c["valid"] == true).count();
    assert!(
        valid > 0 && valid < 9,
        "the grid crosses the threshold: {valid} valid"
    );
    assert_eq!(tags(map, "data-valid=\"true\"").len(), valid);
    let contour = tags(map, "data-contour=\"0.2\"");
    assert_eq!(contour.len(), 1, "{map}");
    assert!(
        attribute(contour[0], "d").unwrap().starts_with('M'),
        "{}",
        contour[0]
    );
    assert!(dom.contains("data-results=\"9\""));
    // The badge says the sweep is partial and how many runs failed.
    let status = app.get_json(&format!("/sweeps/{calibration}")).await;
    let failed = status["counts"]["failed"].as_u64().unwrap();
    assert!(failed > 0, "{status}");
    let badge = tags(&dom, "data-failed=");
    assert_eq!(badge.len(), 1, "one sweep badge");
    assert!(
        badge[0].contains("data-status=\"partial\"") && number(badge[0], "data-failed") == failed as f64,
        "{}",
        badge[0]
    );
    assert!(
        dom.contains(&format!("partial: {failed} of 9 failed")),
        "the badge counts the failed runs"
    );
    // The verdict counts of its runs, as aggregated.
    let poor = aggregate["aggregates"]["quality"]["poor"].as_u64().unwrap();
    assert!(
        dom.contains(&format!("data-quality-counts=\"{poor}\"")),
        "{poor} poor runs not shown"
    );

    // The Monte Carlo campaign: a histogram of all eight runs.
    let dom = load(
        &browser,
        &app.url(&format!("/sweeps/{gaps}")),
        "sweep-gaps",
        1400,
        4000,
    )
    .await;
    let figure = element(&dom, "data-plot=\"histogram\"", "</figure>");
    assert!(figure.contains("data-values=\"8\""), "{figure}");
    let counted: f64 = tags(figure, "data-count=")
        .iter()
        .map(|t| number(t, "data-count"))
        .sum();
    assert_eq!(counted, 8.0);
    // Seeds are shown as the integers they are, in the results table.
    let rows = app.sweep_results(&gaps).await["rows"].clone();
    for row in rows.as_array().unwrap() {
        let seed = row["/bundle/gaps/seed"].as_u64().expect("an integer seed");
        assert!(
            dom.contains(&format!("<td>{seed}</td>")),
            "seed {seed} not shown as an integer"
        );
    }

    // A run refused for its time step: the submit form marks that very field.
    let refused = aggregate["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|row| row["status"] == "failed")
        .expect("a recorded invalid run")["job"]
        .as_str()
        .unwrap()
        .to_owned();
    let dom = load(
        &browser,
        &app.url(&format!("/ui/submit?from={refused}")),
        "submit",
        1400,
        3000,
    )
    .await;
    let field = element(&dom, "data-pointer=\"/inputs/solver/time_step\"", "</label>");
    assert!(field.contains("class=\"invalid\""), "{field}");
    let note = tags(field, "data-error-for=\"/inputs/solver/time_step\"");
    assert_eq!(note.len(), 1, "{field}");
    assert!(field.contains("critical"), "{field}");

    assert_eq!(
        app.delete(&format!("/jobs/{slow}")).await.status(),
        StatusCode::OK
    );
}

/// With an auth file the dashboard still loads (its static files are public, a page
/// asked for without a token is its shell with a 401), and the page's scripts, refused
/// by the API, ask for the team's token instead of showing empty tables.
#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn with_tokens_the_dashboard_asks_for_one() {
    let browser = chromium(concat!(
        module_path!(),
        "::with_tokens_the_dashboard_asks_for_one"
    ));
    let tokens = chocmodal::service::auth::TokenTable::parse("alpha alpha-token-0123456789\n").unwrap();
    let app = crate::helpers::spawn_app_with(|config| config.auth = Some(tokens)).await;

    let page = app
        .client
        .get(app.url("/jobs"))
        .header("accept", "text/html")
        .send()
        .await
        .unwrap();
    assert_eq!(page.status(), StatusCode::UNAUTHORIZED);
    assert!(page.text().await.unwrap().contains("data-page=\"jobs\""));
    assert_eq!(app.get("/ui/assets/app.js").await.status(), StatusCode::OK);
    assert_eq!(app.get("/jobs").await.status(), StatusCode::UNAUTHORIZED);

    let dom = load(&browser, &app.url("/jobs"), "token-prompt", 600, 3000).await;
    assert!(dom.contains("id=\"token-form\""), "no token form in {dom}");
    assert!(dom.contains("id=\"token-input\""), "{dom}");
}
