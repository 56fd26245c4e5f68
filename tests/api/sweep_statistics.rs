//! A sweep's statistics for design through real HTTP: the run-wide table at a requested
//! coverage and confidence, the convergence track of one figure, and the per-contact and
//! per-pin tables of bundle sweeps (the row and the hexagonal bundle). Every expected
//! number is computed here from the member jobs' own results (each job's contact table,
//! its results document's pins, the sweep's rows) and from the binomial law of Wilks'
//! order statistics, summed term by term.

use std::sync::Arc;
use std::time::Duration;

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::hex_bundle_dynamics::HexBundleDynamics;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::counting;
use crate::helpers::{
    Backend, TestApp, assert_problem, on_both_backends, spawn_app, spawn_app_with_processes,
    spawn_app_with_processes_on,
};

on_both_backends!(per_contact_and_per_pin_statistics_of_a_row_are_those_of_its_jobs);

/// γ(n, r, p) = 1 − Σ_{j<r} C(n, j) (1 − p)^j p^(n−j): the probability that the r-th
/// largest of n draws is at or above the p-quantile, the binomial summed plainly.
fn confidence(runs: usize, rank: usize, coverage: f64) -> f64 {
    let below: f64 = (0..rank.min(runs + 1))
        .map(|j| {
            let choose: f64 = (0..j).map(|i| (runs - i) as f64 / (i + 1) as f64).product();
            choose * (1.0 - coverage).powi(j as i32) * coverage.powi((runs - j) as i32)
        })
        .sum();
    1.0 - below
}

/// The tightest rank from the top whose value is a p/γ upper bound of n runs.
fn rank(runs: usize, coverage: f64, level: f64) -> Option<usize> {
    (1..=runs)
        .take_while(|&r| confidence(runs, r, coverage) >= level)
        .last()
}

/// The fewest runs for a bound at `rank`, counted up.
fn runs_needed(rank: usize, coverage: f64, level: f64) -> usize {
    (rank..)
        .find(|&n| confidence(n, rank, coverage) >= level)
        .unwrap()
}

/// The p-quantile of sorted values, linear between order statistics at p·(n − 1).
fn quantile(sorted: &[f64], p: f64) -> f64 {
    let position = p * (sorted.len() - 1) as f64;
    let below = position.floor() as usize;
    let above = (below + 1).min(sorted.len() - 1);
    sorted[below] + (sorted[above] - sorted[below]) * (position - below as f64)
}

fn close(measured: f64, expected: f64, what: &str) {
    assert!(
        (measured - expected).abs() <= 1e-12 * expected.abs().max(1e-300),
        "{what}: measured {measured}, expected {expected}"
    );
}

/// A statistics row against `values` (in any order) at coverage p and confidence γ.
fn assert_statistics(row: &Value, values: &[f64], coverage: f64, level: f64, what: &str) {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    assert_eq!(row["count"], n, "{what}: {row}");
    let mean = sorted.iter().sum::<f64>() / n as f64;
    close(row["mean"].as_f64().unwrap(), mean, &format!("{what} mean"));
    assert_eq!(row["min"].as_f64(), Some(sorted[0]), "{what}: {row}");
    assert_eq!(row["max"].as_f64(), Some(sorted[n - 1]), "{what}: {row}");
    close(
        row["q50"].as_f64().unwrap(),
        quantile(&sorted, 0.5),
        &format!("{what} q50"),
    );
    close(
        row["quantile"].as_f64().unwrap(),
        quantile(&sorted, coverage),
        &format!("{what} quantile"),
    );
    let expected_rank = rank(n, coverage, level);
    assert_eq!(
        row["bound_rank"].as_u64().map(|r| r as usize),
        expected_rank,
        "{what}: {row}"
    );
    assert_eq!(
        row["bound"].as_f64(),
        expected_rank.map(|r| sorted[n - r]),
        "{what}: {row}"
    );
    assert_eq!(
        row["runs_needed"].as_u64().map(|r| r as usize),
        Some(runs_needed(expected_rank.unwrap_or(1), coverage, level)),
        "{what}: {row}"
    );
}

/// The rows of a statistics table with `key` (`contact`, `pin`) = `item` and `figure`.
fn find<'a>(
    table: &'a Value,
    item: Option<(&str, usize)>,
    figure: &str,
    cell: &[(&str, &Value)],
) -> &'a Value {
    table["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|row| {
            row["figure"] == figure
                && item.is_none_or(|(key, k)| row[key] == k)
                && cell.iter().all(|(axis, value)| row[*axis] == **value)
        })
        .unwrap_or_else(|| panic!("no row {item:?} {figure} {cell:?} in {}", table["rows"]))
}

/// The CSV has the JSON's columns as header and one line per row.
async fn assert_csv_matches(app: &TestApp, path: &str, document: &Value) {
    let separator = if path.contains('?') { '&' } else { '?' };
    let response = app.get(&format!("{path}{separator}format=csv")).await;
    assert_eq!(response.status(), StatusCode::OK, "{path}");
    let csv = response.text().await.unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let columns: Vec<&str> = document["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(header, columns, "{path}");
    assert_eq!(
        lines.count(),
        document["rows"].as_array().unwrap().len(),
        "{path}"
    );
}

/// The jobs of a sweep's successful runs, in run order, with their axis values.
async fn successful_runs(app: &TestApp, id: &str) -> Vec<Value> {
    let results = app.sweep_results(id).await;
    results["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|row| row["status"] == "successful")
        .cloned()
        .collect()
}

/// 120 draws of `count-steps`: the run-wide table at 90 %/90 % and the convergence
/// track of the drawn `/step_ms` are the order statistics of the sweep's rows.
#[tokio::test]
async fn run_wide_statistics_and_convergence_follow_the_rows_order_statistics() {
    let app = spawn_app().await;
    let id = app
        .create_sweep(
            json!({"process": counting::ID, "inputs": {"steps": 1}, "samples": 120, "seed": 33,
            "axes": [{"pointer": "/step_ms", "uniform": [0.0, 1.0]}]}),
        )
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(120))
        .await;
    let rows = successful_runs(&app, &id).await;
    let drawn: Vec<f64> = rows.iter().map(|r| r["/step_ms"].as_f64().unwrap()).collect();

    let path = format!("/sweeps/{id}/statistics?coverage=0.9&confidence=0.9");
    let table = app.get_json(&path).await;
    assert_eq!(
        (table["coverage"].as_f64(), table["confidence"].as_f64()),
        (Some(0.9), Some(0.9))
    );
    assert_eq!(
        table["runs_needed"],
        runs_needed(1, 0.9, 0.9),
        "{}",
        table["runs_needed"]
    );
    assert_statistics(
        find(&table, None, "/step_ms", &[]),
        &drawn,
        0.9,
        0.9,
        "/step_ms at 90/90",
    );
    assert_csv_matches(&app, &path, &table).await;
    // The default is 95 %/95 %: the aggregates' bound.
    let default = app.get_json(&format!("/sweeps/{id}/statistics")).await;
    let row = find(&default, None, "/step_ms", &[]);
    assert_statistics(row, &drawn, 0.95, 0.95, "/step_ms at 95/95");
    let aggregates = &app.sweep_results(&id).await["aggregates"]["statistics"][0]["metrics"]["/step_ms"];
    assert_eq!(row["bound"], aggregates["bound_95_95"]);
    // 99 %/95 % from 120 runs: no bound yet, and the runs a bound needs.
    let strict = app
        .get_json(&format!("/sweeps/{id}/statistics?coverage=0.99"))
        .await;
    let row = find(&strict, None, "/step_ms", &[]);
    assert_eq!(row["bound"], Value::Null, "{row}");
    assert_eq!(row["runs_needed"], runs_needed(1, 0.99, 0.95), "{row}");

    let path = format!("/sweeps/{id}/statistics/convergence?figure=/step_ms&coverage=0.95&confidence=0.95");
    let track = app.get_json(&path).await;
    let steps = track["rows"].as_array().unwrap();
    assert_eq!(steps.len(), drawn.len());
    for (n, step) in steps.iter().enumerate() {
        let mut prefix = drawn[..=n].to_vec();
        prefix.sort_by(f64::total_cmp);
        assert_eq!(step["sample"], n);
        assert_eq!(step["runs"], n + 1);
        assert_eq!(step["run"], rows[n]["run"]);
        assert_eq!(step["value"].as_f64(), Some(drawn[n]));
        close(
            step["quantile"].as_f64().unwrap(),
            quantile(&prefix, 0.95),
            &format!("quantile at {}", n + 1),
        );
        let expected = rank(n + 1, 0.95, 0.95);
        assert_eq!(
            step["bound_rank"].as_u64().map(|r| r as usize),
            expected,
            "at {}",
            n + 1
        );
        assert_eq!(
            step["bound"].as_f64(),
            expected.map(|r| prefix[n + 1 - r]),
            "at {}",
            n + 1
        );
    }
    // 59 runs: the largest; 93: the second largest (Wilks).
    assert_eq!(
        (steps[57]["bound_rank"].clone(), steps[58]["bound_rank"].clone()),
        (Value::Null, json!(1))
    );
    assert_eq!(
        (steps[91]["bound_rank"].clone(), steps[92]["bound_rank"].clone()),
        (json!(1), json!(2))
    );
    assert_csv_matches(&app, &path, &track).await;

    // Bad parameters: refused, named.
    for (query, named) in [
        ("statistics?coverage=1", "`coverage`"),
        ("statistics?coverage=0", "`coverage`"),
        ("statistics?confidence=abc", "`confidence`"),
        ("statistics?confidence=1.5", "`confidence`"),
        ("statistics?quantile=0.9", "`quantile`"),
        ("statistics/convergence", "`figure`"),
        ("statistics/convergence?figure=nothing", "`figure`"),
        ("statistics/contacts?coverage=-1", "`coverage`"),
        (
            "statistics/pins?confidence=0.9999999999999999&coverage=0.9999999999999999",
            "`coverage`",
        ),
    ] {
        let response = app.get(&format!("/sweeps/{id}/{query}")).await;
        let problem = assert_problem(response, StatusCode::BAD_REQUEST, "invalid-query").await;
        let detail = problem["detail"].as_str().unwrap();
        assert!(detail.contains(named), "{query}: {detail}");
    }
    let response = app.get("/sweeps/no-such-sweep/statistics/contacts").await;
    assert_problem(response, StatusCode::NOT_FOUND, "no-such-sweep").await;
}

/// Planning without a sweep: the runs each rank of a bound needs, counted up from the
/// binomial here; 59, 93, 124 at 95 %/95 %.
#[tokio::test]
async fn the_runs_a_bound_needs_are_given_before_any_sweep() {
    let app = spawn_app().await;
    for (coverage, level) in [(0.95, 0.95), (0.99, 0.95), (0.95, 0.99), (0.9, 0.5)] {
        let plan = app
            .get_json(&format!(
                "/sweeps/runs-needed?coverage={coverage}&confidence={level}&ranks=4"
            ))
            .await;
        let listed = plan["runs_needed"].as_array().unwrap();
        assert_eq!(listed.len(), 4, "{plan}");
        for (k, entry) in listed.iter().enumerate() {
            assert_eq!(entry["rank"], k + 1);
            assert_eq!(
                entry["runs"],
                runs_needed(k + 1, coverage, level),
                "{coverage}/{level}: {entry}"
            );
        }
    }
    let plan = app.get_json("/sweeps/runs-needed").await;
    let counts: Vec<&Value> = plan["runs_needed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| &e["runs"])
        .collect();
    assert_eq!(counts, [&json!(59), &json!(93), &json!(124)]);
    for (query, named) in [
        ("ranks=0", "`ranks`"),
        ("ranks=101", "`ranks`"),
        ("coverage=2", "`coverage`"),
        ("confidence=", "`confidence`"),
        ("samples=3", "`samples`"),
    ] {
        let response = app.get(&format!("/sweeps/runs-needed?{query}")).await;
        let problem = assert_problem(response, StatusCode::BAD_REQUEST, "invalid-query").await;
        assert!(
            problem["detail"].as_str().unwrap().contains(named),
            "{query}: {problem}"
        );
    }
}

/// Random gap states of a row of three pins: each contact's and each pin's statistics
/// over the runs are those of the member jobs' own contact tables and pin entries, and
/// the bound (60 %/50 % from 10 runs: the rank the binomial gives) is their order
/// statistic. Both backends: the runs' documents are read a page at a time.
async fn per_contact_and_per_pin_statistics_of_a_row_are_those_of_its_jobs(backend: Backend) {
    let app = spawn_app_with_processes_on(backend, vec![Arc::new(BundleDynamics)], |_| {}).await;
    let mut body: Value = serde_json::from_str(include_str!("../../examples/sweep-gaps.json")).unwrap();
    // 10 runs: more than one page of documents (8).
    body["samples"] = json!(10);
    body["inputs"]["solver"]["duration"] = json!(0.02);
    let id = app.create_sweep(body).await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(180))
        .await;
    let runs = successful_runs(&app, &id).await;
    assert_eq!(runs.len(), 10);
    let (coverage, level) = (0.6, 0.5);
    let expected_rank = rank(10, coverage, level).unwrap();
    assert!(
        expected_rank >= 2,
        "a bound below the largest value: rank {expected_rank}"
    );

    let mut tables = Vec::new();
    let mut documents = Vec::new();
    for run in &runs {
        let job = run["job"].as_str().unwrap();
        tables.push(app.get_json(&format!("/jobs/{job}/results/contacts")).await);
        documents.push(app.get_json(&format!("/jobs/{job}/results")).await);
    }
    let path = format!("/sweeps/{id}/statistics/contacts?coverage={coverage}&confidence={level}");
    let contacts = app.get_json(&path).await;
    assert_eq!(contacts["kind"], "contacts");
    let count = tables[0]["contacts"].as_array().unwrap().len();
    assert_eq!(count, 8, "3 pins, 4 gaps, 2 levels");
    let figures = [
        "max_force",
        "impacts",
        "contact_time",
        "impulse",
        "gap",
        "impact_statistics.impacts",
    ];
    for k in 0..count {
        for figure in figures {
            let values: Vec<f64> = tables
                .iter()
                .map(|t| {
                    t["contacts"][k][figure]
                        .as_f64()
                        .unwrap_or_else(|| panic!("{figure} of {k}"))
                })
                .collect();
            let row = find(&contacts, Some(("contact", k)), figure, &[]);
            assert_statistics(row, &values, coverage, level, &format!("contact {k} {figure}"));
            assert_eq!(row["runs"], 10);
        }
    }
    // Bodies are not figures.
    for row in contacts["rows"].as_array().unwrap() {
        assert!(
            !["left", "right"].contains(&row["figure"].as_str().unwrap()),
            "{row}"
        );
    }
    assert_csv_matches(&app, &path, &contacts).await;
    // One figure only.
    let peaks = app
        .get_json(&format!("/sweeps/{id}/statistics/contacts?figure=max_force"))
        .await;
    assert_eq!(peaks["rows"].as_array().unwrap().len(), count);
    assert!(
        peaks["rows"]
            .as_array()
            .unwrap()
            .iter()
            .all(|r| r["figure"] == "max_force")
    );

    let path = format!("/sweeps/{id}/statistics/pins?coverage={coverage}&confidence={level}");
    let pins = app.get_json(&path).await;
    for p in 0..3 {
        for figure in [
            ("max_abs_deflection", "/max_abs_deflection"),
            ("bending.stress", "/bending/stress"),
        ] {
            let values: Vec<f64> = documents
                .iter()
                .map(|d| d["pins"][p].pointer(figure.1).and_then(Value::as_f64).unwrap())
                .collect();
            let row = find(&pins, Some(("pin", p)), figure.0, &[]);
            assert_statistics(row, &values, coverage, level, &format!("pin {p} {}", figure.0));
        }
    }
    assert_csv_matches(&app, &path, &pins).await;
    let response = app
        .get(&format!("/sweeps/{id}/statistics/pins?figure=no_such_figure"))
        .await;
    let problem = assert_problem(response, StatusCode::BAD_REQUEST, "invalid-query").await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(
        detail.contains("`figure`")
            && detail.contains("no_such_figure")
            && detail.contains("max_abs_deflection"),
        "{detail}"
    );
}

/// Seven wire-wrapped pins under a random shake amplitude, at two contact stiffnesses
/// (a list axis: two cells): each contact's and pin's statistics per cell are those of
/// the cell's jobs.
#[tokio::test]
async fn per_contact_and_per_pin_statistics_of_a_hexagonal_sweep_are_per_cell() {
    let app = spawn_app_with_processes(vec![Arc::new(HexBundleDynamics)], |_| {}).await;
    let pin = json!({"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
        "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
        "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "damping_ratio": 0.01});
    let inputs = json!({"pin": pin,
        "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                   "wrapper_flat_to_flat": 0.0305},
        "contact": {"stiffness": 2e5, "damping": 2.0},
        "gaps": {"type": "uniform", "pin_pin": 0.0, "pin_wall": 0.0},
        "excitation": {"base_acceleration": {"type": "sine", "amplitude": 20.0, "frequency": 30.0, "cycles": 2},
                       "direction": 30.0},
        "solver": {"duration": 0.03, "check": "none"}});
    let id = app
        .create_sweep(
            json!({"process": "hex-bundle-dynamics", "inputs": inputs, "samples": 3, "seed": 7,
            "axes": [{"pointer": "/contact/stiffness", "values": [2e5, 4e5]},
                     {"pointer": "/excitation/base_acceleration/amplitude", "uniform": [10.0, 30.0]}]}),
        )
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(240))
        .await;
    let runs = successful_runs(&app, &id).await;
    assert_eq!(runs.len(), 6);
    let contacts = app.get_json(&format!("/sweeps/{id}/statistics/contacts")).await;
    let pins = app.get_json(&format!("/sweeps/{id}/statistics/pins")).await;
    assert_eq!(
        contacts["columns"].as_array().unwrap()[..3],
        [json!("/contact/stiffness"), json!("contact"), json!("figure")]
    );
    for stiffness in [json!(2e5), json!(4e5)] {
        let mut tables = Vec::new();
        let mut documents = Vec::new();
        for run in runs.iter().filter(|r| r["/contact/stiffness"] == stiffness) {
            let job = run["job"].as_str().unwrap();
            tables.push(app.get_json(&format!("/jobs/{job}/results/contacts")).await);
            documents.push(app.get_json(&format!("/jobs/{job}/results")).await);
        }
        assert_eq!(tables.len(), 3);
        let cell = [("/contact/stiffness", &stiffness)];
        let count = tables[0]["contacts"].as_array().unwrap().len();
        assert!(count > 6, "{count} contacts");
        for k in 0..count {
            for figure in ["max_force", "impacts", "impulse"] {
                let values: Vec<f64> = tables
                    .iter()
                    .map(|t| t["contacts"][k][figure].as_f64().unwrap())
                    .collect();
                let row = find(&contacts, Some(("contact", k)), figure, &cell);
                assert_statistics(
                    row,
                    &values,
                    0.95,
                    0.95,
                    &format!("k = {stiffness}: contact {k} {figure}"),
                );
                assert_eq!(row["runs"], 3);
            }
        }
        for p in 0..7 {
            for (figure, pointer) in [
                ("deflection.max_deflection", "/deflection/max_deflection"),
                ("bending.stress", "/bending/stress"),
            ] {
                let values: Vec<f64> = documents
                    .iter()
                    .map(|d| d["pins"][p].pointer(pointer).and_then(Value::as_f64).unwrap())
                    .collect();
                let row = find(&pins, Some(("pin", p)), figure, &cell);
                assert_statistics(
                    row,
                    &values,
                    0.95,
                    0.95,
                    &format!("k = {stiffness}: pin {p} {figure}"),
                );
            }
        }
    }
}

/// The sweep page's Monte Carlo card plots, against the number of runs in draw order,
/// each run's value, the q95 of the runs so far and the 95 %/95 % Wilks bound (from the
/// 59th run), drawn by uPlot in Chromium from the served convergence table.
#[tokio::test]
#[cfg_attr(
    chocmodal_skip_browser_tests,
    ignore = "needs headless Chromium: none found at build time, or CHOCMODAL_SKIP_BROWSER_TESTS=1 (build.rs)"
)]
async fn the_sweep_page_plots_the_quantile_and_the_bound_against_the_runs() {
    let chromium = crate::dashboard::chromium(concat!(
        module_path!(),
        "::the_sweep_page_plots_the_quantile_and_the_bound_against_the_runs"
    ));
    let app = spawn_app().await;
    let runs = 70;
    let id = app
        .create_sweep(
            json!({"process": counting::ID, "inputs": {"steps": 1}, "samples": runs, "seed": 5,
            "axes": [{"pointer": "/step_ms", "uniform": [0.0, 1.0]}]}),
        )
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(60))
        .await;
    let rows = successful_runs(&app, &id).await;
    let drawn: Vec<f64> = rows.iter().map(|r| r["/step_ms"].as_f64().unwrap()).collect();
    // What the plot must show, from the rows: per n the q95 and the bound of the first n.
    let mut quantiles = Vec::new();
    let mut bounds = Vec::new();
    for n in 1..=runs {
        let mut prefix = drawn[..n].to_vec();
        prefix.sort_by(f64::total_cmp);
        quantiles.push(quantile(&prefix, 0.95));
        bounds.extend(rank(n, 0.95, 0.95).map(|r| prefix[n - r]));
    }
    let extent = |values: &[f64]| {
        values
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)))
    };

    let mut browser = crate::devtools::Browser::launch(&chromium, 1280, 2400).await;
    browser.goto(&app.url(&format!("/sweeps/{id}"))).await;
    let key = |series: &str| {
        format!(
            "(() => {{ const k = document.querySelector('[data-plot=\"convergence\"] [data-series=\"{series}\"]'); \
             return k && [Number(k.getAttribute('data-points')), Number(k.getAttribute('data-min')), \
             Number(k.getAttribute('data-max'))]; }})()"
        )
    };
    let drawn_plot = browser
        .wait_for(
            "document.querySelector('[data-plot=\"convergence\"] canvas') !== null",
            Duration::from_secs(30),
        )
        .await;
    assert_eq!(drawn_plot, json!(true));
    let screenshot = crate::dashboard::screenshot_dir().join("sweep-convergence.png");
    browser.screenshot(&screenshot).await;
    for (series, values) in [
        ("value", drawn.clone()),
        ("quantile", quantiles),
        ("bound", bounds),
    ] {
        let shown = browser.eval(&key(series)).await;
        let (lo, hi) = extent(&values);
        assert_eq!(
            shown[0].as_f64(),
            Some(values.len() as f64),
            "{series}: points {shown}"
        );
        assert_eq!(shown[1].as_f64(), Some(lo), "{series}: least {shown}");
        assert_eq!(shown[2].as_f64(), Some(hi), "{series}: greatest {shown}");
    }
    assert_eq!(
        browser.eval(&key("bound")).await[0].as_f64(),
        Some((runs - 58) as f64),
        "the bound from the 59th run on"
    );
    browser.assert_no_exceptions();
}
