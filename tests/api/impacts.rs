//! Impact statistics over HTTP (issue 19): the per-impact table of a job as CSV and JSON
//! pages, filtered by contact, adding up to the results document's totals; counting
//! settings that merge rebounds; bad counting settings refused at their pointers; a table
//! capped below the run's impacts keeping each contact's largest and saying so in the
//! results, the header, the JSON pages and the CSV.

use std::sync::Arc;

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;

use crate::helpers::{TestApp, assert_problem, spawn_app_with_processes};

async fn spawn() -> TestApp {
    spawn_app_with_processes(vec![Arc::new(CantileverImpact), Arc::new(BundleDynamics)], |_| {}).await
}

fn example(name: &str) -> Value {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

async fn run(app: &TestApp, process: &str, body: &Value) -> (String, Value) {
    let response = app.post_execution(process, body).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let id = response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    let status = app.wait_until_finished(&id).await;
    assert_eq!(status["status"], "successful", "{status}");
    let results = app.get_json(&format!("/jobs/{id}/results")).await;
    (id, results)
}

fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// The public cantilever case: the reference counts its impacts exactly (closures of the
/// semi-analytic solution); with the default counting the numerical table has as many
/// rows, they add up to the contact's impulse and their largest peak is its largest
/// force.
#[tokio::test]
async fn the_impact_table_serves_every_impact_and_adds_up_to_the_results() {
    let app = spawn().await;
    let mut body = example("cantilever-impact.json");
    body["inputs"]["solver"]["duration"] = json!(0.2);
    let (id, results) = run(&app, "cantilever-impact", &body).await;
    let numerical = &results["numerical"];
    let impacts = numerical["impacts"].as_u64().unwrap();
    assert!(impacts >= 2, "{numerical}");
    assert_eq!(impacts, results["reference"]["impacts"].as_u64().unwrap());
    assert_eq!(
        results["outputs"]["impacts"]["href"],
        format!("/jobs/{id}/results/impacts")
    );

    let csv = app
        .get(&format!("/jobs/{id}/results/impacts?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    assert_eq!(
        csv.lines().next(),
        Some(
            "contact,start,peak_time,peak_force,impulse,duration,approach_velocity,rebounds,dissipated,energy"
        )
    );
    assert_eq!(csv.lines().count() as u64, impacts + 1);
    let impulse: f64 = column(&csv, "impulse").iter().sum();
    let total = numerical["impulse"].as_f64().unwrap();
    assert!((impulse - total).abs() <= 1e-9 * total, "{impulse} vs {total}");
    let peak = column(&csv, "peak_force").into_iter().fold(0.0, f64::max);
    assert_eq!(peak, numerical["max_contact_force"].as_f64().unwrap());
    let statistics = &numerical["impact_statistics"];
    assert_eq!(statistics["impacts"].as_u64(), Some(impacts));
    assert_eq!(
        statistics["histogram"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap())
            .sum::<u64>(),
        impacts
    );
    // The approach energy ½ m v² never exceeds the energy the release put in (no
    // excitation; damping only removes energy).
    let initial = numerical["energy"]["initial"].as_f64().unwrap();
    assert!(statistics["max_impact_energy"].as_f64().unwrap() <= initial);

    // JSON pages: one row at a time, the next page named, the filter kept.
    let page = app
        .get_json(&format!("/jobs/{id}/results/impacts?limit=1&contact=0"))
        .await;
    assert_eq!(page["total_rows"].as_u64(), Some(impacts));
    assert_eq!(page["rows"].as_array().unwrap().len(), 1);
    assert_eq!(page["next"], "offset=1&limit=1&contact=0");
    let second = app
        .get_json(&format!("/jobs/{id}/results/impacts?offset=1&limit=1&contact=0"))
        .await;
    assert!(second["rows"][0]["start"].as_f64() >= page["rows"][0]["start"].as_f64());
    // Accept: text/csv gives the CSV; a contact the model lacks has no rows.
    let by_accept = app
        .client
        .get(app.url(&format!("/jobs/{id}/results/impacts?contact=7")))
        .header("accept", "text/csv")
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert_eq!(by_accept.lines().count(), 1);
    for query in ["contact=x", "limit=0", "offset=-1", "colour=red"] {
        let response = app.get(&format!("/jobs/{id}/results/impacts?{query}")).await;
        assert_eq!(response.status(), StatusCode::BAD_REQUEST, "{query}");
    }
}

/// A rest time longer than the flights between the cantilever's impacts merges them
/// into one impact whose rebounds are the others; the loaded time and impulse do not
/// change.
#[tokio::test]
async fn a_rest_time_merges_rebounds_into_one_impact() {
    let app = spawn().await;
    let mut body = example("cantilever-impact.json");
    body["inputs"]["solver"]["duration"] = json!(0.2);
    let (_, plain) = run(&app, "cantilever-impact", &body).await;
    body["inputs"]["output"] = json!({"impacts": {"rest_time": 0.2}, "blocks": 4});
    let (id, merged) = run(&app, "cantilever-impact", &body).await;
    let (a, b) = (&plain["numerical"], &merged["numerical"]);
    assert_eq!(b["impacts"], 1);
    let rows = app.get_json(&format!("/jobs/{id}/results/impacts")).await;
    assert_eq!(
        rows["rows"][0]["rebounds"].as_u64(),
        Some(a["impacts"].as_u64().unwrap() - 1)
    );
    let (x, y) = (&a["impact_statistics"], &b["impact_statistics"]);
    for field in ["loaded_time", "impulse"] {
        let (x, y) = (x[field].as_f64().unwrap(), y[field].as_f64().unwrap());
        // Summed by block in one run, at once in the other.
        assert!((x - y).abs() <= 1e-12 * x, "{field}: {x} vs {y}");
    }
    assert_eq!(y["blocks"]["blocks"], 4);
    assert_eq!(b["impact_summary"]["rest_time"], 0.2);
}

#[tokio::test]
async fn bad_counting_settings_are_refused_at_their_pointers() {
    let app = spawn().await;
    for process in ["cantilever-impact", "bundle-dynamics"] {
        let mut body = example(if process == "cantilever-impact" {
            "cantilever-impact.json"
        } else {
            "bundle-row17.json"
        });
        body["inputs"]["output"] = json!({
            "impacts": {"force_threshold": -1.0, "rest_time": -0.1, "classes": 10001},
            "blocks": 0
        });
        let response = app.post_execution(process, &body).await;
        let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
        let pointers: Vec<&str> = problem["errors"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["pointer"].as_str().unwrap())
            .collect();
        for pointer in [
            "/inputs/output/impacts/force_threshold",
            "/inputs/output/impacts/rest_time",
            "/inputs/output/impacts/classes",
            "/inputs/output/blocks",
        ] {
            assert!(pointers.contains(&pointer), "{process}: {pointer} in {problem}");
        }
        body["inputs"]["output"] = json!({"impacts": {"classes": 0}});
        let response = app.post_execution(process, &body).await;
        let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
        assert_eq!(problem["errors"][0]["pointer"], "/inputs/output/impacts/classes");
        // A table of no row could not hold the run's largest impact.
        body["inputs"]["output"] = json!({"impacts": {"max_rows": 0}});
        let response = app.post_execution(process, &body).await;
        let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
        assert_eq!(
            problem["errors"][0]["pointer"], "/inputs/output/impacts/max_rows",
            "{process}: {problem}"
        );
        assert!(
            problem["errors"][0]["detail"]
                .as_str()
                .is_some_and(|r| r.contains("at least 1")),
            "{problem}"
        );
    }
}

/// Issue 30: `/jobs/{id}/results/impacts` also matches the generic
/// `/jobs/{jobId}/results/{output}` template. Whichever template a client matches the
/// URL to, the served JSON follows that template's 200 schema; and a history served
/// through the generic template follows it too.
#[tokio::test]
async fn the_impact_table_and_a_history_follow_every_openapi_path_their_url_matches() {
    let app = spawn().await;
    let mut body = example("cantilever-impact.json");
    body["inputs"]["solver"]["duration"] = json!(0.05);
    let (id, results) = run(&app, "cantilever-impact", &body).await;
    let openapi = app.get_json("/openapi.json").await;
    let history = results["outputs"]
        .as_object()
        .expect("outputs")
        .keys()
        .find(|name| *name != "impacts")
        .expect("a history")
        .clone();
    for (output, templates) in [
        (
            "impacts",
            vec!["/jobs/{jobId}/results/impacts", "/jobs/{jobId}/results/{output}"],
        ),
        (history.as_str(), vec!["/jobs/{jobId}/results/{output}"]),
    ] {
        let path = format!("/jobs/{id}/results/{output}");
        let mut matching = crate::schema_check::matching_templates(&openapi, &path);
        matching.sort_unstable();
        let mut expected = templates.clone();
        expected.sort_unstable();
        assert_eq!(matching, expected, "templates matching {path}");
        let served = app.get_json(&path).await;
        for template in matching {
            let schema = &openapi["paths"][template]["get"]["responses"]["200"]["content"]["application/json"]
                ["schema"];
            assert!(!schema.is_null(), "{template} declares no JSON schema");
            let violations = crate::schema_check::violations(&openapi, schema, &served);
            assert!(
                violations.is_empty(),
                "GET {path} does not follow the schema of {template}: {violations:#?}"
            );
        }
    }
}

async fn get_text(app: &TestApp, path: &str) -> (String, String) {
    let response = app.get(path).await;
    assert_eq!(response.status(), StatusCode::OK, "{path}");
    let header = response
        .headers()
        .get("impact-table")
        .unwrap_or_else(|| panic!("{path}: no Impact-Table header"))
        .to_str()
        .unwrap()
        .to_owned();
    (header, response.text().await.unwrap())
}

/// The CSV's rows as their cells, by column name.
fn records(csv: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = csv.lines();
    let header = lines.next().unwrap().split(',').map(str::to_owned).collect();
    let rows = lines.map(|l| l.split(',').map(str::to_owned).collect()).collect();
    (header, rows)
}

/// Issue 33: a bundle shaken into many impacts, run with the default table (complete)
/// and capped at a third of its impacts. The capped run's statistics are the complete
/// run's; its table holds exactly `max_rows` of the complete table's rows, each
/// contact's largest, the run's peak among them; and the results, the `Impact-Table`
/// header, the JSON pages and the CSV say `truncated` with counts that add up.
#[tokio::test]
async fn a_capped_table_keeps_each_contacts_largest_impacts_and_says_truncated() {
    let app = spawn().await;
    let mut body = example("bundle-minimal-sine.json");
    body["inputs"]["solver"]["duration"] = json!(0.6);
    let (complete_id, complete) = run(&app, "bundle-dynamics", &body).await;
    let summary = &complete["impact_summary"];
    let impacts = summary["impacts"].as_u64().unwrap();
    let contacts = complete["contacts"].as_array().unwrap().len() as u64;
    assert_eq!(summary["truncated"], false, "{summary}");
    assert_eq!(summary["untabulated_max_peak"], Value::Null);
    let (header, every) = get_text(&app, &format!("/jobs/{complete_id}/results/impacts?format=csv")).await;
    assert_eq!(
        header,
        format!("complete, impacts={impacts}, tabulated={impacts}")
    );
    let (columns, every) = records(&every);
    assert_eq!(
        columns.len(),
        10,
        "a complete table has its ten columns: {columns:?}"
    );
    assert_eq!(every.len() as u64, impacts);

    let max_rows = impacts / 3;
    assert!(
        max_rows >= 2 * contacts,
        "the case must impact often: {impacts} impacts"
    );
    body["inputs"]["output"] = json!({"impacts": {"max_rows": max_rows}});
    let (id, capped) = run(&app, "bundle-dynamics", &body).await;
    let summary = &capped["impact_summary"];
    assert_eq!(summary["truncated"], true, "{summary}");
    assert_eq!(summary["impacts"].as_u64(), Some(impacts));
    assert_eq!(summary["tabulated"].as_u64(), Some(max_rows));
    assert_eq!(summary["untabulated"].as_u64(), Some(impacts - max_rows));
    assert_eq!(summary["max_rows"].as_u64(), Some(max_rows));
    assert_eq!(summary["fair_share"].as_u64(), Some(max_rows / contacts));

    let (header, csv) = get_text(&app, &format!("/jobs/{id}/results/impacts?format=csv")).await;
    assert_eq!(
        header,
        format!("truncated, impacts={impacts}, tabulated={max_rows}")
    );
    let (columns, kept) = records(&csv);
    assert_eq!(
        columns[10..],
        [
            "truncated",
            "impacts",
            "tabulated",
            "contact_impacts",
            "contact_tabulated"
        ]
    );
    assert_eq!(kept.len() as u64, max_rows);
    let cell = |row: &Vec<String>, name: &str| row[columns.iter().position(|c| c == name).unwrap()].clone();
    let force = |row: &Vec<String>| cell(row, "peak_force").parse::<f64>().unwrap();
    // Every kept row is a row of the complete table, sorted by start.
    let starts: Vec<f64> = kept.iter().map(|r| cell(r, "start").parse().unwrap()).collect();
    assert!(starts.windows(2).all(|w| w[0] <= w[1]));
    for row in &kept {
        assert!(
            every.contains(&row[..10].to_vec()),
            "{row:?} is not a row of the complete table"
        );
    }
    let mut left_out_peak = f64::NEG_INFINITY;
    let stated: u64 = capped["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["impact_statistics"]["tabulated"].as_u64().unwrap())
        .sum();
    assert_eq!(stated, max_rows);
    for (k, contact) in capped["contacts"].as_array().unwrap().iter().enumerate() {
        let mine: Vec<&Vec<String>> = kept
            .iter()
            .filter(|r| cell(r, "contact") == k.to_string())
            .collect();
        let all: Vec<&Vec<String>> = every.iter().filter(|r| r[0] == k.to_string()).collect();
        let counted = contact["impacts"].as_u64().unwrap();
        assert_eq!(all.len() as u64, counted, "contact {k}");
        assert_eq!(
            contact["impact_statistics"]["tabulated"].as_u64(),
            Some(mine.len() as u64)
        );
        assert!(
            mine.len() as u64 >= counted.min(max_rows / contacts),
            "contact {k}: its fair share"
        );
        for row in &mine {
            assert_eq!(cell(row, "truncated"), "true");
            assert_eq!(cell(row, "impacts"), impacts.to_string());
            assert_eq!(cell(row, "tabulated"), max_rows.to_string());
            assert_eq!(cell(row, "contact_impacts"), counted.to_string());
            assert_eq!(cell(row, "contact_tabulated"), mine.len().to_string());
        }
        // Its rows are its largest impacts, and its largest force is among them.
        let smallest_kept = mine.iter().map(|r| force(r)).fold(f64::INFINITY, f64::min);
        let dropped: Vec<f64> = all
            .iter()
            .filter(|r| !mine.iter().any(|m| m[..10] == r[..]))
            .map(|r| force(r))
            .collect();
        let largest_dropped = dropped.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!(
            largest_dropped <= smallest_kept,
            "contact {k}: dropped {largest_dropped} N, kept {smallest_kept} N"
        );
        left_out_peak = left_out_peak.max(largest_dropped);
        if counted > 0 {
            let max_force = contact["max_force"].as_f64().unwrap();
            assert!(
                mine.iter().any(|r| force(r) == max_force),
                "contact {k}: {max_force} N not kept"
            );
        }
    }
    assert_eq!(summary["untabulated_max_peak"].as_f64(), Some(left_out_peak));
    // Largest peaks first: no row is smaller than an impact left out of another contact
    // unless it is within its own contact's fair share (checked above per contact); the
    // largest peak of the run is kept.
    let run_peak = every.iter().map(force).fold(0.0, f64::max);
    assert_eq!(kept.iter().map(force).fold(0.0, f64::max), run_peak);

    // JSON pages and a filter give the whole table's counts, in the header too.
    let page = app
        .get(&format!("/jobs/{id}/results/impacts?contact=0&limit=2"))
        .await;
    assert_eq!(
        page.headers()["impact-table"],
        format!("truncated, impacts={impacts}, tabulated={max_rows}").as_str()
    );
    let page: Value = page.json().await.unwrap();
    assert_eq!(page["truncated"], true);
    assert_eq!(page["impacts"].as_u64(), Some(impacts));
    assert_eq!(page["tabulated"].as_u64(), Some(max_rows));
    let complete_page = app
        .get_json(&format!("/jobs/{complete_id}/results/impacts?limit=1"))
        .await;
    assert_eq!(complete_page["truncated"], false);
    assert_eq!(complete_page["impacts"].as_u64(), Some(impacts));
}
