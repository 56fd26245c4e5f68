//! The `chocmodal run` command through the real binary: results on stdout, histories
//! and the per-impact table as CSV with `--out`, invalid inputs as a problem document on stderr with exit 2.

use std::io::Write;
use std::process::{Command, Stdio};

fn chocmodal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_chocmodal"))
}

fn example() -> String {
    format!("{}/examples/cantilever-impact.json", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn run_prints_the_results_document_and_writes_csv_histories() {
    let out = std::env::temp_dir().join(format!("chocmodal-cli-{}", std::process::id()));
    let output = chocmodal()
        .args(["run", "cantilever-impact", &example(), "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let document: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON on stdout");
    for block in ["numerical", "reference", "comparison", "outputs"] {
        assert!(document.get(block).is_some(), "missing `{block}`");
    }
    assert_eq!(document["comparison"]["agrees"], true);
    for name in ["tip_displacement", "contact_force"] {
        let csv = std::fs::read_to_string(out.join(format!("{name}.csv"))).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some("time,numerical,reference"));
        assert_eq!(lines.count(), 50_001, "{name}: one row per step");
    }
    // The per-impact table in its own columns: one row per impact the results count.
    let csv = std::fs::read_to_string(out.join("impacts.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some(
            "contact,start,peak_time,peak_force,impulse,duration,approach_velocity,rebounds,dissipated,energy"
        )
    );
    assert_eq!(
        lines.count() as u64,
        document["numerical"]["impacts"].as_u64().unwrap()
    );
    for entry in std::fs::read_dir(&out).unwrap() {
        let path = entry.unwrap().path();
        assert_numbers_canonical(
            &std::fs::read_to_string(&path).unwrap(),
            &path.display().to_string(),
        );
    }
    std::fs::remove_dir_all(&out).ok();
}

/// Every number of a CSV below its header is written as the service writes them (and as
/// the JSON documents do): an integer, or the shortest text that reads back as the same
/// double.
fn assert_numbers_canonical(csv: &str, what: &str) {
    let canonical = |cell: &str| {
        let integer = cell.strip_prefix('-').unwrap_or(cell);
        (!integer.is_empty() && integer.bytes().all(|b| b.is_ascii_digit()))
            || cell
                .parse::<f64>()
                .ok()
                .and_then(serde_json::Number::from_f64)
                .is_some_and(|n| n.to_string() == cell)
    };
    let mut seen = 0;
    for cell in csv.lines().skip(1).flat_map(|line| line.split(',')) {
        if cell.parse::<f64>().is_ok() {
            seen += 1;
            assert!(
                canonical(cell),
                "{what}: `{cell}` is not the shortest text of its number"
            );
        }
    }
    assert!(seen > 0, "{what}: no number");
}

#[test]
fn a_bundle_run_writes_its_contact_statistics_as_csv() {
    let out = std::env::temp_dir().join(format!("chocmodal-cli-contacts-{}", std::process::id()));
    let mut body: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(format!(
            "{}/examples/bundle-row17.json",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap(),
    )
    .unwrap();
    body["inputs"]["solver"]["duration"] = serde_json::json!(0.02);
    let output = run_piped(
        &["run", "bundle-dynamics", "-", "--out", out.to_str().unwrap()],
        &body,
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let document: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    // `run` stamps the document as the service does: solver, build, inputs hash.
    let inputs = body["inputs"].clone();
    assert_eq!(
        document["provenance"]["solver_version"],
        env!("CARGO_PKG_VERSION")
    );
    assert_eq!(
        document["provenance"]["inputs_sha256"],
        chocmodal::provenance::inputs_sha256(&inputs)
    );
    let csv = std::fs::read_to_string(out.join("contacts.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let contacts = document["contacts"].as_array().unwrap();
    assert_eq!(rows.len(), contacts.len());
    let impacts = header
        .iter()
        .position(|h| *h == "impact_statistics.impacts")
        .unwrap();
    let force = header.iter().position(|h| *h == "max_force").unwrap();
    for (row, contact) in rows.iter().zip(contacts) {
        assert_eq!(row[impacts].parse::<u64>().ok(), contact["impacts"].as_u64());
        // serde_json's default float parsing may be one ulp off.
        let (written, reported) = (
            row[force].parse::<f64>().unwrap(),
            contact["max_force"].as_f64().unwrap(),
        );
        assert!(
            (written - reported).abs() <= 1e-15 * reported.abs(),
            "{written} vs {reported}"
        );
    }
    assert_numbers_canonical(&csv, "contacts.csv");
    // The per-pin table and the resultants, one row per pin and per pin and height.
    let pins = std::fs::read_to_string(out.join("pins.csv")).unwrap();
    let pin_rows = document["pins"].as_array().unwrap();
    assert_eq!(pins.lines().count(), 1 + pin_rows.len());
    assert!(
        pins.lines()
            .next()
            .unwrap()
            .contains("max_resultant_force.max_force")
    );
    let resultants = std::fs::read_to_string(out.join("resultants.csv")).unwrap();
    let per_height: usize = (pin_rows.iter())
        .map(|p| p["resultant_forces"].as_array().unwrap().len())
        .sum();
    assert_eq!(
        resultants.lines().next(),
        Some("pin,contacts,height,max_force,time")
    );
    assert_eq!(resultants.lines().count(), 1 + per_height);
    assert_numbers_canonical(&resultants, "resultants.csv");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn invalid_inputs_give_a_problem_document_and_exit_status_2() {
    let mut child = chocmodal()
        .args(["run", "cantilever-impact", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let body = r#"{"inputs": {"beam": {"length": -1, "young_modulus": 2.1e11, "density": 7800,
        "section": {"type": "tube", "outer_diameter": 0.01, "inner_diameter": 0.009}}}}"#;
    child.stdin.take().unwrap().write_all(body.as_bytes()).unwrap();
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(2));
    let problem: serde_json::Value = serde_json::from_slice(&output.stderr).expect("problem JSON on stderr");
    assert_eq!(problem["status"], 422);
    assert_eq!(problem["errors"][0]["pointer"], "/inputs/beam/length");
}

#[test]
fn malformed_json_and_unknown_process_exit_with_status_2() {
    let mut child = chocmodal()
        .args(["run", "cantilever-impact", "-"])
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(b"{not json").unwrap();
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(2));
    let output = chocmodal()
        .args(["run", "no-such-process", &example()])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("no-such-process"));
}

#[test]
fn an_unknown_database_url_is_refused_before_anything_starts() {
    for role in ["serve", "worker"] {
        let output = chocmodal()
            .args([role, "--database", "mysql://chocmodal@db/queue"])
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(2), "{role}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("sqlite://") && stderr.contains("postgres://"),
            "{role}: {stderr}"
        );
    }
}

#[test]
fn a_database_password_in_the_environment_stays_out_of_the_help() {
    let output = chocmodal()
        .args(["worker", "--help"])
        .env("CHOCMODAL_DATABASE_URL", "postgres://chocmodal:s3cret@db/queue")
        .output()
        .unwrap();
    assert!(output.status.success());
    let help = String::from_utf8_lossy(&output.stdout);
    assert!(
        help.contains("--health-bind") && !help.contains("s3cret"),
        "{help}"
    );
}

/// Runs `chocmodal run <process> -` with `body` on stdin.
fn run_with_stdin(process: &str, body: &serde_json::Value) -> std::process::Output {
    run_piped(&["run", process, "-"], body)
}

/// Runs `chocmodal <args>` with `body` on stdin.
fn run_piped(args: &[&str], body: &serde_json::Value) -> std::process::Output {
    let mut child = chocmodal()
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(body.to_string().as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

/// A result the verdict calls `poor` is still a result (exit 0, the document on stdout),
/// but the CLI says so on stderr with the reasons. The poor run is made from the
/// verdict's definition: fewer than 8 steps per period of the fastest motion is poor,
/// and steps per period are 2π / (ω_max Δt), so the step of a first run times its
/// `steps_per_contact_period` / 5 gives 5 steps per period (still stable: central
/// difference holds up to π).
#[test]
fn a_poor_result_warns_on_stderr_and_keeps_its_document_on_stdout() {
    let mut body: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example()).unwrap()).unwrap();
    body["inputs"]["solver"]["duration"] = serde_json::json!(0.05);
    body["inputs"]["solver"]["check"] = serde_json::json!("none");
    let first = run_with_stdin("cantilever-impact", &body);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let document: serde_json::Value = serde_json::from_slice(&first.stdout).expect("JSON on stdout");
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert_eq!(
        stderr.contains("warning: quality"),
        document["quality"]["verdict"] != "good",
        "a warning exactly when the verdict is not good: {stderr}"
    );

    let time_step = document["numerical"]["time_step"].as_f64().unwrap();
    let steps_per_period = document["quality"]["steps_per_contact_period"].as_f64().unwrap();
    body["inputs"]["solver"]["time_step"] = serde_json::json!(time_step * steps_per_period / 5.0);
    let coarse = run_with_stdin("cantilever-impact", &body);
    let stderr = String::from_utf8_lossy(&coarse.stderr);
    assert_eq!(coarse.status.code(), Some(0), "{stderr}");
    let document: serde_json::Value = serde_json::from_slice(&coarse.stdout).expect("only JSON on stdout");
    assert_eq!(document["quality"]["verdict"], "poor", "{}", document["quality"]);
    let reasons: Vec<&str> = document["quality"]["reasons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_str().unwrap())
        .collect();
    assert!(!reasons.is_empty());
    let expected = format!("warning: quality poor: {}", reasons.join("; "));
    assert!(
        stderr.lines().any(|line| line == expected),
        "expected the line `{expected}` on stderr, got: {stderr}"
    );
}

/// Two pins between the walls, tip contacts with 0.1 mm gaps, shaken by
/// `base_acceleration` for 0.03 s at a fixed 10 µs step.
fn bundle_body(base_acceleration: serde_json::Value) -> serde_json::Value {
    let contact = |left: serde_json::Value, right: serde_json::Value| serde_json::json!({"left": left, "right": right, "height": 1.8, "gap": 1e-4, "stiffness": 2e6, "damping": 20.0});
    serde_json::json!({"inputs": {
        "pin": {"length": 1.8, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "added_mass_per_length": 0.6, "elements": 20, "modes": 6, "damping_ratio": 0.01},
        "pins": 2,
        "contacts": [contact("wall".into(), 0.into()), contact(0.into(), 1.into()), contact(1.into(), "wall".into())],
        "excitation": {"base_acceleration": base_acceleration},
        "solver": {"time_step": 1e-5, "duration": 0.03, "check": "none"},
        "output": {"interval": 1e-4}
    }})
}

/// A job file naming a record file (`path`, or a path as its `id`, relative to the job
/// file) computes what the same record inline as a `table` does; a record file with a
/// bad line is refused at the reference's pointer, naming the line.
#[test]
fn run_reads_a_record_file_named_by_a_signal_reference() {
    let dir = tempfile::TempDir::new().unwrap();
    let time: Vec<f64> = (0..301).map(|k| k as f64 * 1e-4).collect();
    let acceleration: Vec<f64> = time
        .iter()
        .map(|t| 20.0 * (std::f64::consts::TAU * 10.0 * t).sin())
        .collect();
    let mut csv = String::from("time,acceleration\n");
    for (t, a) in time.iter().zip(&acceleration) {
        csv.push_str(&format!("{t:e},{a:e}\n"));
    }
    std::fs::write(dir.path().join("record.csv"), &csv).unwrap();
    let run_file = |name: &str, body: serde_json::Value| {
        let path = dir.path().join(name);
        std::fs::write(&path, body.to_string()).unwrap();
        chocmodal()
            .args(["run", "bundle-dynamics"])
            .arg(&path)
            .output()
            .unwrap()
    };
    let documents: Vec<serde_json::Value> = [
        serde_json::json!({"type": "signal", "path": "record.csv"}),
        serde_json::json!({"type": "signal", "id": "record.csv", "scale": 1.0}),
        serde_json::json!({"type": "table", "time": time, "acceleration": acceleration}),
    ]
    .into_iter()
    .enumerate()
    .map(|(k, signal)| {
        let output = run_file(&format!("job{k}.json"), bundle_body(signal));
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let mut document: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON on stdout");
        // The inputs differ (a path, an id, a table inline), hence their hash.
        document.as_object_mut().expect("an object").remove("provenance");
        document
    })
    .collect();
    assert!(
        documents[2]["impacts"].as_u64().unwrap_or(0) > 0,
        "{}",
        documents[2]
    );
    assert_eq!(documents[0], documents[2], "path reference vs inline table");
    assert_eq!(documents[1], documents[2], "path as id vs inline table");

    std::fs::write(dir.path().join("bad.csv"), "time,acceleration\n0,1\n0.1,oops\n").unwrap();
    let output = run_file(
        "bad.json",
        bundle_body(serde_json::json!({"type": "signal", "path": "bad.csv"})),
    );
    assert_eq!(output.status.code(), Some(2));
    let problem: serde_json::Value = serde_json::from_slice(&output.stderr).expect("problem JSON on stderr");
    assert_eq!(
        problem["errors"][0]["pointer"],
        "/inputs/excitation/base_acceleration/path"
    );
    let detail = problem["errors"][0]["detail"].as_str().unwrap();
    assert!(detail.contains("line 3") && detail.contains("oops"), "{detail}");
}

/// Plausibility warnings go to stderr, one line each, and the run goes on: a cantilever
/// released from rest has nothing to move it. The example itself has none.
#[test]
fn warnings_are_printed_on_stderr_and_the_run_succeeds() {
    let mut body: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example()).unwrap()).unwrap();
    body["inputs"]["solver"]["duration"] = serde_json::json!(0.01);
    body["inputs"]["solver"]["check"] = serde_json::json!("none");
    let run = |body: &serde_json::Value| run_with_stdin("cantilever-impact", body);
    let quiet = run(&body);
    assert!(quiet.status.success());
    assert!(
        !String::from_utf8_lossy(&quiet.stderr).contains("warning: /inputs"),
        "{}",
        String::from_utf8_lossy(&quiet.stderr)
    );

    body["inputs"]["release"]["tip_displacement"] = serde_json::json!(0.0);
    let output = run(&body);
    assert!(output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr
            .lines()
            .any(|line| line.starts_with("warning: /inputs/release/tip_displacement: nothing excites")),
        "{stderr}"
    );
    let document: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON on stdout");
    assert_eq!(document["warnings"][0]["code"], "nothing_excites");
}

/// The shipped record example (`examples/records/`) runs from any working directory: its
/// record file is found next to the job file, read whole (2001 samples at 200 per
/// second, PGA 3 m/s²), and shakes the row into its walls.
#[test]
fn the_shipped_record_example_runs() {
    let job = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/records/bundle-record.json");
    let output = chocmodal()
        .args(["run", "bundle-dynamics", job])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let document: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON on stdout");
    assert_eq!(
        document["warnings"],
        serde_json::json!([]),
        "{}",
        document["warnings"]
    );
    assert!(
        document["impacts"].as_u64().unwrap() > 0,
        "the record must close the gaps"
    );
    let record = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/records/synthetic-10s.csv"
    ))
    .unwrap();
    let peak = record
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max);
    assert!((peak - 3.0).abs() < 1e-5, "PGA {peak}");
}

/// Issue 33: the cantilever bounces a few times in 0.3 s; with fewer rows than impacts,
/// `impacts.csv` holds the largest ones and says `truncated` with the counts on every
/// row, as the results do.
#[test]
fn a_capped_impacts_csv_keeps_the_largest_and_says_truncated() {
    let out = std::env::temp_dir().join(format!("chocmodal-cli-capped-{}", std::process::id()));
    let mut body: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example()).unwrap()).unwrap();
    body["inputs"]["solver"]["duration"] = serde_json::json!(0.3);
    body["inputs"]["output"] = serde_json::json!({"impacts": {"max_rows": 2}});
    let output = run_piped(
        &["run", "cantilever-impact", "-", "--out", out.to_str().unwrap()],
        &body,
    );
    assert!(
        output.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let document: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let summary = &document["numerical"]["impact_summary"];
    let impacts = summary["impacts"].as_u64().unwrap();
    assert!(impacts > 2, "the case must bounce more than twice: {summary}");
    assert_eq!(
        (summary["truncated"].as_bool(), summary["tabulated"].as_u64()),
        (Some(true), Some(2))
    );
    let csv = std::fs::read_to_string(out.join("impacts.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .ends_with(",energy,truncated,impacts,tabulated,contact_impacts,contact_tabulated")
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 2);
    for row in &rows {
        assert!(row.ends_with(&format!(",true,{impacts},2,{impacts},2")), "{row}");
    }
    // The run's largest force is in the table.
    let peak = document["numerical"]["max_contact_force"].as_f64().unwrap();
    let forces: Vec<f64> = rows
        .iter()
        .map(|r| r.split(',').nth(3).unwrap().parse().unwrap())
        .collect();
    assert!(forces.contains(&peak), "{peak} N not in {forces:?}");
    assert!(
        forces
            .iter()
            .all(|&f| f >= summary["untabulated_max_peak"].as_f64().unwrap())
    );
    std::fs::remove_dir_all(&out).ok();
}
