//! Stored signals through real HTTP: a 200 000-sample record uploads past the general
//! body limit, streams back bit for bit and drives a sweep over its scale; its metadata
//! are the analytic figures of a sine (PGA = A, Arias intensity π A² T/(4g)); the
//! response spectrum of a long sine peaks at its frequency with the resonant
//! amplification 1/(2ξ); a job given a signal reference computes exactly what the same
//! record given inline as a `table` does; bad records and bad references are 4xx at
//! their pointer (or CSV line), and another tenant's signal does not exist.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;
use std::time::Duration;

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::service::auth::TokenTable;
use reqwest::{Response, StatusCode};
use serde_json::{Value, json};

use crate::helpers::{
    Backend, TestApp, assert_problem, on_both_backends, spawn_app_with_processes, spawn_app_with_processes_on,
};

on_both_backends!(
    signals_are_stored_listed_streamed_and_deleted,
    another_tenants_signal_is_not_found_nor_usable
);

/// Standard gravity, the g of the Arias intensity (m/s²).
const G: f64 = 9.80665;

impl TestApp {
    /// POSTs a record to `/signals` with this content type and query (`""` for none).
    pub async fn post_signal(
        &self,
        body: impl Into<reqwest::Body>,
        content_type: &str,
        query: &str,
    ) -> Response {
        self.client
            .post(self.url(&format!("/signals{query}")))
            .header("content-type", content_type)
            .body(body)
            .send()
            .await
            .unwrap()
    }

    /// Uploads a record; returns its metadata (checking `201` and `Location`).
    pub async fn upload_signal(
        &self,
        body: impl Into<reqwest::Body>,
        content_type: &str,
        query: &str,
    ) -> Value {
        let response = self.post_signal(body, content_type, query).await;
        let status = response.status();
        let location = response
            .headers()
            .get("location")
            .map(|l| l.to_str().unwrap().to_owned());
        let metadata: Value = response.json().await.unwrap();
        assert_eq!(status, StatusCode::CREATED, "{metadata}");
        assert_eq!(
            location,
            Some(format!("/signals/{}", metadata["id"].as_str().unwrap()))
        );
        metadata
    }
}

/// `amplitude` · sin(2π `frequency` t) sampled every `interval` s, `samples` samples.
fn sine(amplitude: f64, frequency: f64, interval: f64, samples: usize) -> (Vec<f64>, Vec<f64>) {
    let time: Vec<f64> = (0..samples).map(|k| k as f64 * interval).collect();
    let values = time
        .iter()
        .map(|t| amplitude * (TAU * frequency * t).sin())
        .collect();
    (time, values)
}

fn csv(time: &[f64], values: &[f64]) -> String {
    let mut text = String::from("time,acceleration\n");
    for (t, a) in time.iter().zip(values) {
        text.push_str(&format!("{t:e},{a:e}\n"));
    }
    text
}

fn parse_csv(text: &str) -> (Vec<f64>, Vec<f64>) {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("time,acceleration"));
    lines
        .map(|line| {
            let (t, a) = line.split_once(',').unwrap();
            (t.parse::<f64>().unwrap(), a.parse::<f64>().unwrap())
        })
        .unzip()
}

/// Two pins between the walls, contacts at the tips with `gap` (m), shaken by
/// `base_acceleration`, 0.05 s at a fixed 10 µs step.
fn bundle(base_acceleration: Value, gap: f64) -> Value {
    let contact = |left: Value, right: Value| json!({"left": left, "right": right, "height": 1.8, "gap": gap, "stiffness": 2e6, "damping": 20.0});
    json!({
        "pin": {"length": 1.8, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "added_mass_per_length": 0.6, "elements": 20, "modes": 6, "damping_ratio": 0.01},
        "pins": 2,
        "contacts": [contact(json!("wall"), json!(0)), contact(json!(0), json!(1)), contact(json!(1), json!("wall"))],
        "excitation": {"base_acceleration": base_acceleration},
        "solver": {"time_step": 1e-5, "duration": 0.05, "check": "none"},
        "output": {"interval": 1e-4}
    })
}

async fn spawn_with_bundle() -> TestApp {
    spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |_| {}).await
}

async fn submit(app: &TestApp, inputs: Value) -> String {
    let response = app
        .post_execution("bundle-dynamics", &json!({"inputs": inputs}))
        .await;
    let status = response.status();
    let body: Value = response.json().await.unwrap();
    assert_eq!(status, StatusCode::CREATED, "{body}");
    body["jobID"].as_str().unwrap().to_owned()
}

async fn results_of(app: &TestApp, job: &str) -> Value {
    let status = app
        .wait_for(
            job,
            &["successful", "failed", "dismissed"],
            Duration::from_secs(120),
        )
        .await;
    assert_eq!(status["status"], "successful", "{status}");
    let mut results = app.get_json(&format!("/jobs/{job}/results")).await;
    results.as_object_mut().unwrap().remove("outputs");
    // The inputs differ (a reference, a record inline), hence their hash.
    results.as_object_mut().unwrap().remove("provenance");
    results
}

/// The acceptance case of issue 21: 200 000 samples (8 MB of CSV, eight times the
/// general body limit) upload, stream back bit for bit as CSV and JSON, and drive a
/// sweep over `scale`. The contacts never close (1 m gaps), so the pins respond
/// linearly, and scaling by a power of two scales every float exactly: the peak
/// deflection of the run at scale 2 is exactly twice that at scale 1, and half at 0.5.
#[tokio::test]
async fn a_200_000_sample_record_uploads_streams_back_and_drives_a_sweep_over_its_scale() {
    let app = spawn_with_bundle().await;
    let (time, values) = sine(20.0, 10.0, 1e-5, 200_000);
    let text = csv(&time, &values);
    assert!(text.len() > 4 << 20, "the record is {} bytes", text.len());
    let metadata = app.upload_signal(text, "text/csv", "").await;
    let id = metadata["id"].as_str().unwrap().to_owned();
    assert_eq!(metadata["samples"], 200_000, "{metadata}");
    assert_eq!(metadata["uniform"], true, "{metadata}");

    let response = app
        .client
        .get(app.url(&format!("/signals/{id}/samples")))
        .header("accept", "text/csv")
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), StatusCode::OK);
    let (back_time, back_values) = parse_csv(&response.text().await.unwrap());
    assert_eq!(
        (back_time == time, back_values == values),
        (true, true),
        "CSV round trip"
    );
    // Read with Rust's own correctly rounded parser: the served text must name the
    // stored doubles exactly.
    let text = app
        .get(&format!("/signals/{id}/samples?format=json"))
        .await
        .text()
        .await
        .unwrap();
    let numbers = |member: &str| -> Vec<f64> {
        let start = text.find(&format!("\"{member}\":[")).unwrap() + member.len() + 4;
        let end = start + text[start..].find(']').unwrap();
        text[start..end].split(',').map(|n| n.parse().unwrap()).collect()
    };
    assert!(
        numbers("time") == time && numbers("acceleration") == values,
        "JSON round trip"
    );

    let reference = json!({"type": "signal", "id": id, "scale": 1.0});
    let sweep = app
        .create_sweep(
            json!({"process": "bundle-dynamics", "inputs": bundle(reference, 1.0),
            "axes": [{"pointer": "/excitation/base_acceleration/scale", "values": [0.5, 1.0, 2.0]}]}),
        )
        .await;
    app.wait_for_sweep(&sweep, &["successful"], Duration::from_secs(300))
        .await;
    let results = app.sweep_results(&sweep).await;
    let rows = results["rows"].as_array().cloned().unwrap_or_default();
    assert_eq!(rows.len(), 3, "{results}");
    let peak = |row: &Value| row["pins.0.max_abs_deflection"].as_f64().unwrap_or(f64::NAN);
    let (half, one, two) = (peak(&rows[0]), peak(&rows[1]), peak(&rows[2]));
    assert!(one > 1e-4, "the record moves the pins: peak {one} m");
    assert_eq!(
        two,
        2.0 * one,
        "scale 2: measured {two} vs expected {}",
        2.0 * one
    );
    assert_eq!(
        half,
        0.5 * one,
        "scale 0.5: measured {half} vs expected {}",
        0.5 * one
    );
}

/// A sine of amplitude A = 2.5 m/s² at 5 Hz over 10 whole periods (T = 2 s), uploaded
/// as accelerations alone at 2000 samples per second: PGA = A (a sample sits on every
/// crest), Arias intensity π/(2g) · A² T/2, within (ωh)²/6 of the record linear between
/// samples.
#[tokio::test]
async fn the_metadata_of_a_sine_are_its_amplitude_and_its_analytic_arias_intensity() {
    let app = spawn_with_bundle().await;
    let (amplitude, frequency, rate) = (2.5, 5.0, 2000.0);
    let samples = 4001;
    let mut text = String::from("acceleration\n");
    for k in 0..samples {
        let a = amplitude * (TAU * frequency * k as f64 / rate).sin();
        text.push_str(&format!("{a:e}\n"));
    }
    let metadata = app.upload_signal(text, "text/csv", "?sampling_rate=2000").await;
    let id = metadata["id"].as_str().unwrap();
    let fetched = app.get_json(&format!("/signals/{id}")).await;
    assert_eq!(fetched["id"], metadata["id"]);
    let number = |name: &str| fetched[name].as_f64().unwrap_or(f64::NAN);
    assert_eq!(fetched["samples"], 4001);
    assert!((number("duration") - 2.0).abs() < 1e-12, "{fetched}");
    assert!((number("sampling_interval") - 5e-4).abs() < 1e-15, "{fetched}");
    assert!((number("sampling_rate") - rate).abs() < 1e-9, "{fetched}");
    assert_eq!(fetched["uniform"], true);
    assert!(
        (number("pga") - amplitude).abs() < 1e-12,
        "PGA measured {} vs expected {amplitude}",
        number("pga")
    );
    let expected = PI / (2.0 * G) * amplitude * amplitude * 2.0 / 2.0;
    let omega_h = TAU * frequency / rate;
    let relative = (number("arias_intensity") - expected).abs() / expected;
    assert!(
        relative < omega_h * omega_h / 6.0,
        "Arias intensity measured {} vs expected {expected} (relative {relative:e})",
        number("arias_intensity")
    );
    assert!(
        fetched["created"].as_str().unwrap_or_default().ends_with('Z'),
        "{fetched}"
    );
}

/// A long sine (60 periods at f₀ = 5 Hz, amplitude 1 m/s²) brings each oscillator to
/// its steady state; at resonance the displacement amplitude is A/(2ξω²), so PSA peaks
/// near f₀ (at f₀/√(1 − 2ξ²)) at A/(2ξ√(1 − ξ²)) ≈ A/(2ξ): 10 at ξ = 0.05, 25 at 0.02.
#[tokio::test]
async fn the_spectrum_of_a_long_sine_peaks_at_its_frequency_with_amplification_one_over_two_xi() {
    let app = spawn_with_bundle().await;
    let (frequency, rate) = (5.0, 1000.0);
    let (time, values) = sine(1.0, frequency, 1.0 / rate, 12_001);
    let metadata = app
        .upload_signal(
            json!({"time": time, "acceleration": values}).to_string(),
            "application/json",
            "",
        )
        .await;
    let id = metadata["id"].as_str().unwrap();
    let spectrum = app
        .get_json(&format!(
            "/signals/{id}/spectrum?damping=0.05,0.02&f_min=4&f_max=6.25&points=201"
        ))
        .await;
    let frequencies: Vec<f64> = serde_json::from_value(spectrum["frequencies"].clone()).unwrap();
    assert_eq!(frequencies.len(), 201);
    assert!((frequencies[0] - 4.0).abs() < 1e-12 && (frequencies[200] - 6.25).abs() < 1e-12);
    for (index, xi) in [0.05, 0.02].into_iter().enumerate() {
        let entry = &spectrum["pseudo_acceleration"][index];
        assert_eq!(entry["damping"], xi);
        let values: Vec<f64> = serde_json::from_value(entry["values"].clone()).unwrap();
        let (peak_at, peak) =
            values.iter().enumerate().fold(
                (0, 0.0f64),
                |best, (k, &v)| if v > best.1 { (k, v) } else { best },
            );
        let expected = 1.0 / (2.0 * xi);
        assert!(
            (frequencies[peak_at] - frequency).abs() < 0.01 * frequency,
            "ξ {xi}: peak at {} Hz vs expected {frequency} Hz",
            frequencies[peak_at]
        );
        assert!(
            (peak - expected).abs() < 0.02 * expected,
            "ξ {xi}: peak PSA measured {peak} vs expected 1/(2ξ) = {expected}"
        );
    }
    let response = app
        .client
        .get(app.url(&format!("/signals/{id}/spectrum?points=50")))
        .header("accept", "text/csv")
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), StatusCode::OK);
    let text = response.text().await.unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("frequency,psa_0.05"));
    assert_eq!(lines.count(), 50);
}

/// The same record as a stored signal and inline as a `table`: the integrator sees the
/// same table, so the two jobs' results are identical, impacts included. The job keeps
/// the reference, not the samples.
#[tokio::test]
async fn a_job_with_a_signal_reference_computes_what_the_same_record_inline_does() {
    let app = spawn_with_bundle().await;
    // Short decimals, which the JSON parser of the execution request and the CSV parser
    // of the upload read as the same doubles.
    let time: Vec<f64> = (0..1001).map(|k| k as f64 / 1e4).collect();
    let values: Vec<f64> = time
        .iter()
        .map(|t| (20.0 * (TAU * 10.0 * t).sin() * 1e6).round() / 1e6)
        .collect();
    let metadata = app.upload_signal(csv(&time, &values), "text/csv", "").await;
    let id = metadata["id"].as_str().unwrap();
    let by_reference = submit(
        &app,
        bundle(json!({"type": "signal", "id": id, "scale": 1.0}), 1e-4),
    )
    .await;
    let inline = submit(
        &app,
        bundle(
            json!({"type": "table", "time": time, "acceleration": values}),
            1e-4,
        ),
    )
    .await;
    let (by_reference_results, inline_results) = (
        results_of(&app, &by_reference).await,
        results_of(&app, &inline).await,
    );
    assert!(
        by_reference_results["impacts"].as_u64().unwrap_or(0) > 0,
        "the case has impacts: {by_reference_results}"
    );
    assert_eq!(by_reference_results, inline_results);
    let inputs = app.get_json(&format!("/jobs/{by_reference}/inputs")).await;
    assert_eq!(
        inputs["inputs"]["excitation"]["base_acceleration"],
        json!({"type": "signal", "id": id, "scale": 1.0})
    );
}

async fn signals_are_stored_listed_streamed_and_deleted(backend: Backend) {
    let app = spawn_app_with_processes_on(backend, vec![Arc::new(BundleDynamics)], |config| {
        config.workers = 0
    })
    .await;
    let first = app
        .upload_signal(
            r#"{"sampling_rate": 100, "acceleration": [0, 1.5, -3, 0.5]}"#,
            "application/json",
            "",
        )
        .await;
    let second = app.upload_signal("0,1\n0.01,2\n0.03,-1\n", "text/csv", "").await;
    assert_eq!(second["uniform"], false, "{second}");
    assert_eq!(second["pga"], 2.0);
    let page = app.get_json("/signals?limit=1").await;
    assert_eq!(page["signals"][0]["id"], second["id"], "newest first: {page}");
    let next = page["links"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["rel"] == "next")
        .map(|l| l["href"].as_str().unwrap().to_owned())
        .expect("a next link");
    let older = app.get_json(&next).await;
    assert_eq!(older["signals"][0]["id"], first["id"], "{older}");
    assert_eq!(older["signals"].as_array().map(Vec::len), Some(1));

    let id = first["id"].as_str().unwrap();
    let text = app
        .get(&format!("/signals/{id}/samples?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    assert_eq!(
        parse_csv(&text),
        (vec![0.0, 0.01, 0.02, 0.03], vec![0.0, 1.5, -3.0, 0.5])
    );

    // A queued job refers to it (no workers): deleting is refused until the job is dismissed.
    let job = submit(&app, bundle(json!({"type": "signal", "id": id}), 1e-4)).await;
    let refused = app.delete(&format!("/signals/{id}")).await;
    let problem = assert_problem(refused, StatusCode::CONFLICT, "/signal-in-use").await;
    assert!(
        problem["detail"]
            .as_str()
            .unwrap()
            .contains("1 queued or running"),
        "{problem}"
    );
    app.delete(&format!("/jobs/{job}")).await;
    let deleted = app.delete(&format!("/signals/{id}")).await;
    assert_eq!(deleted.status(), StatusCode::NO_CONTENT);
    assert_problem(
        app.get(&format!("/signals/{id}")).await,
        StatusCode::NOT_FOUND,
        "/no-such-signal",
    )
    .await;
    assert_problem(
        app.delete(&format!("/signals/{id}")).await,
        StatusCode::NOT_FOUND,
        "/no-such-signal",
    )
    .await;
}

const ALPHA: &str = "alpha-token-0123456789";
const BETA: &str = "beta-token-9876543210";

async fn another_tenants_signal_is_not_found_nor_usable(backend: Backend) {
    let tokens = TokenTable::parse(&format!("alpha {ALPHA}\nbeta {BETA}\n")).unwrap();
    let app = spawn_app_with_processes_on(backend, vec![Arc::new(BundleDynamics)], move |config| {
        config.auth = Some(tokens);
        config.workers = 0;
    })
    .await;
    let upload = app
        .client
        .post(app.url("/signals"))
        .bearer_auth(ALPHA)
        .header("content-type", "text/csv")
        .body("time,acceleration\n0,1\n0.1,2\n")
        .send()
        .await
        .unwrap();
    assert_eq!(upload.status(), StatusCode::CREATED);
    let metadata: Value = upload.json().await.unwrap();
    let id = metadata["id"].as_str().unwrap();
    let as_beta = |path: String| app.client.get(app.url(&path)).bearer_auth(BETA).send();
    for path in [
        format!("/signals/{id}"),
        format!("/signals/{id}/samples"),
        format!("/signals/{id}/spectrum"),
    ] {
        assert_problem(
            as_beta(path).await.unwrap(),
            StatusCode::NOT_FOUND,
            "/no-such-signal",
        )
        .await;
    }
    let list: Value = as_beta("/signals".into()).await.unwrap().json().await.unwrap();
    assert_eq!(list["signals"], json!([]), "{list}");
    let deletion = app
        .client
        .delete(app.url(&format!("/signals/{id}")))
        .bearer_auth(BETA)
        .send()
        .await
        .unwrap();
    assert_problem(deletion, StatusCode::NOT_FOUND, "/no-such-signal").await;
    // Referring to it from beta's job: the same refusal as an id that does not exist.
    let inputs = bundle(json!({"type": "signal", "id": id}), 1e-4);
    let job = app
        .client
        .post(app.url("/processes/bundle-dynamics/execution"))
        .bearer_auth(BETA)
        .json(&json!({"inputs": inputs}))
        .send()
        .await
        .unwrap();
    let problem = assert_problem(job, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(
        problem["errors"][0]["pointer"], "/inputs/excitation/base_acceleration/id",
        "{problem}"
    );
    assert!(
        problem["errors"][0]["detail"]
            .as_str()
            .unwrap()
            .contains("no signal"),
        "{problem}"
    );
    // Alpha's own job is accepted.
    let job = app
        .client
        .post(app.url("/processes/bundle-dynamics/execution"))
        .bearer_auth(ALPHA)
        .json(&json!({"inputs": inputs}))
        .send()
        .await
        .unwrap();
    assert_eq!(job.status(), StatusCode::CREATED);
}

#[tokio::test]
async fn bad_records_are_refused_at_their_sample_and_line() {
    let app = spawn_with_bundle().await;
    let cases = [
        ("time,acceleration\n0,1\n0.1,2\n0.1,3\n", "/time/2", "line 4"),
        (
            "time,acceleration\n0,1\n\n0.1,abc\n0.2,3\n",
            "/acceleration/1",
            "line 4",
        ),
        ("time,acceleration\n0,1\n0.1,NaN\n", "/acceleration/1", "line 3"),
        (
            "time,acceleration\n0,1\n0.2,2\n0.1,3\n",
            "/time/2",
            "strictly increasing",
        ),
    ];
    for (text, pointer, said) in cases {
        let response = app.post_signal(text, "text/csv", "").await;
        let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-signal").await;
        assert_eq!(problem["errors"][0]["pointer"], pointer, "{text}: {problem}");
        let detail = problem["errors"][0]["detail"].as_str().unwrap();
        assert!(detail.contains(said), "{text}: {detail}");
    }
    let response = app
        .post_signal(
            r#"{"sampling_rate": -5, "acceleration": [1, 2]}"#,
            "application/json",
            "",
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-signal").await;
    assert_eq!(problem["errors"][0]["pointer"], "/sampling_rate");
    let response = app
        .post_signal(
            r#"{"time": [0, 1], "acceleration": [1, null]}"#,
            "application/json",
            "",
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-signal").await;
    assert_eq!(problem["errors"][0]["pointer"], "/acceleration/1");
    for query in ["?sampling_rate=0", "?sampling_rate=-200"] {
        let response = app.post_signal("acceleration\n1\n2\n", "text/csv", query).await;
        let problem = assert_problem(response, StatusCode::BAD_REQUEST, "/invalid-query").await;
        assert!(
            problem["detail"].as_str().unwrap().contains("sampling_rate"),
            "{problem}"
        );
    }
    let response = app.post_signal("acceleration\n1\n2\n", "text/csv", "").await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-signal").await;
    assert_eq!(problem["errors"][0]["pointer"], "/sampling_rate", "{problem}");
    let response = app.post_signal("<xml/>", "application/xml", "").await;
    assert_problem(
        response,
        StatusCode::UNSUPPORTED_MEDIA_TYPE,
        "/unsupported-media-type",
    )
    .await;
    let list = app.get_json("/signals").await;
    assert_eq!(list["signals"], json!([]), "nothing stored: {list}");
}

#[tokio::test]
async fn records_over_the_size_limits_are_refused_with_the_limit_stated() {
    let app = spawn_app_with_processes(vec![], |config| {
        config.max_signal_bytes = 10_000;
        config.max_signal_samples = 100;
    })
    .await;
    let (time, values) = sine(1.0, 1.0, 0.01, 1000);
    let response = app.post_signal(csv(&time, &values), "text/csv", "").await;
    let problem = assert_problem(response, StatusCode::PAYLOAD_TOO_LARGE, "/payload-too-large").await;
    assert!(
        problem["detail"].as_str().unwrap().contains("10000 bytes"),
        "{problem}"
    );
    let (time, values) = sine(1.0, 1.0, 0.01, 150);
    let response = app.post_signal(csv(&time, &values), "text/csv", "").await;
    let problem = assert_problem(response, StatusCode::PAYLOAD_TOO_LARGE, "/payload-too-large").await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(
        detail.contains("150 samples") && detail.contains("at most 100"),
        "{problem}"
    );
}

#[tokio::test]
async fn unknown_ids_and_file_paths_in_a_job_are_refused_at_their_pointer() {
    let app = spawn_with_bundle().await;
    let unknown = "00000000-0000-4000-8000-000000000000";
    let cases = [
        (
            json!({"type": "signal", "id": unknown}),
            "/inputs/excitation/base_acceleration/id",
        ),
        (
            json!({"type": "signal", "path": "record.csv"}),
            "/inputs/excitation/base_acceleration/path",
        ),
        (
            json!({"type": "signal", "scale": 2.0}),
            "/inputs/excitation/base_acceleration/id",
        ),
    ];
    for (signal, pointer) in cases {
        let response = app
            .post_execution(
                "bundle-dynamics",
                &json!({"inputs": bundle(signal.clone(), 1e-4)}),
            )
            .await;
        let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
        assert_eq!(problem["errors"][0]["pointer"], pointer, "{signal}: {problem}");
    }
    // In a sweep, the run's pointer.
    let response = app
        .post_sweep(&json!({"process": "bundle-dynamics",
            "inputs": bundle(json!({"type": "signal", "id": unknown}), 1e-4),
            "axes": [{"pointer": "/excitation/base_acceleration/scale", "values": [1.0, 2.0]}]}))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(
        problem["errors"][0]["pointer"], "/runs/0/inputs/excitation/base_acceleration/id",
        "{problem}"
    );
    let jobs = app.get_json("/jobs").await;
    assert_eq!(jobs["jobs"], json!([]), "nothing queued: {jobs}");
}

/// Accelerations of 1e154 m/s² square to 1e308, at the edge of `f64`: such a record
/// (a hostile or broken upload) is stored with its exact Arias intensity π/(2g)∫a²dt,
/// computed without overflow (here a constant A over T = 2 s: π A² T/(2g), about
/// 3.2e307 m/s), not a 500; one whose intensity is beyond the largest number is a 422 at
/// `/acceleration` stating the bound. Its metadata and spectrum read back.
#[tokio::test]
async fn huge_accelerations_get_their_exact_arias_intensity_or_a_422_stating_the_bound() {
    let app = spawn_with_bundle().await;
    let amplitude = 1e154;
    let metadata = app
        .upload_signal(
            format!("time,acceleration\n0,{amplitude:e}\n1,{amplitude:e}\n2,{amplitude:e}\n"),
            "text/csv",
            "",
        )
        .await;
    // In the order that stays finite: π/(2g)·T first.
    let expected = PI / (2.0 * G) * 2.0 * amplitude * amplitude;
    let measured = metadata["arias_intensity"]
        .as_f64()
        .expect("a finite Arias intensity");
    assert!(
        ((measured - expected) / expected).abs() < 1e-12,
        "Arias measured {measured:e} vs expected {expected:e}"
    );
    assert_eq!(metadata["pga"], amplitude);
    let id = metadata["id"].as_str().unwrap();
    let read = app.get_json(&format!("/signals/{id}")).await;
    assert_eq!(read["arias_intensity"], metadata["arias_intensity"]);

    let response = app
        .post_signal(
            r#"{"time": [0, 1000000], "acceleration": [1e300, 1e300]}"#,
            "application/json",
            "",
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-signal").await;
    assert_eq!(problem["errors"][0]["pointer"], "/acceleration", "{problem}");
    let detail = problem["errors"][0]["detail"].as_str().unwrap();
    assert!(
        detail.contains("Arias intensity") && detail.contains("1.7976931348623157e308"),
        "{detail}"
    );
}

/// A record in g, uploaded as a PEER AT2 file (as `text/plain`, NPTS and DT read from
/// it) and as one CSV column with `?unit=g` and a `dt=` header: both are stored in
/// m/s², with the PGA of the sine's amplitude × 9.80665 and its duration (NPTS − 1)·DT;
/// a unit that contradicts the file is a 422 at `/unit`, an unknown unit a 400.
#[tokio::test]
async fn a_record_in_g_as_an_at2_file_or_a_column_is_stored_in_metres_per_second_squared() {
    let app = spawn_with_bundle().await;
    let (amplitude_g, frequency, dt, samples) = (0.3, 2.0, 0.01, 401);
    let values: Vec<f64> = (0..samples)
        .map(|k| amplitude_g * (TAU * frequency * k as f64 * dt).sin())
        .collect();
    let mut at2 = format!(
        "PEER NGA STRONG MOTION DATABASE RECORD\nTest sine, 1/1/2000, Station, 000\n\
         ACCELERATION TIME SERIES IN UNITS OF G\nNPTS= {samples:5}, DT=   .0100 SEC\n"
    );
    for chunk in values.chunks(5) {
        let line: Vec<String> = chunk.iter().map(|a| format!("{a:15.7E}")).collect();
        at2.push_str(&line.join(""));
        at2.push('\n');
    }
    let mut column = String::from("dt=0.01\n");
    for a in &values {
        column.push_str(&format!("{a:e}\n"));
    }
    for (body, query) in [(at2.clone(), ""), (column, "?unit=g")] {
        let metadata = app.upload_signal(body, "text/plain", query).await;
        let number = |name: &str| metadata[name].as_f64().unwrap_or(f64::NAN);
        assert_eq!(metadata["samples"], samples, "{metadata}");
        assert!((number("duration") - 4.0).abs() < 1e-12, "{metadata}");
        // The largest sample, in m/s²; the file's 8 significant digits bound the agreement.
        let pga = values.iter().fold(0.0_f64, |m, a| m.max(a.abs())) * G;
        assert!(
            (number("pga") - pga).abs() < 1e-6 * pga,
            "{query}: PGA {} m/s², expected {pga}",
            number("pga")
        );
    }
    let response = app.post_signal(at2, "text/plain", "?unit=m/s2").await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-signal").await;
    assert_eq!(problem["errors"][0]["pointer"], "/unit", "{problem}");
    let response = app
        .post_signal("acceleration\n1\n2\n", "text/csv", "?sampling_rate=10&unit=ft/s2")
        .await;
    assert_eq!(response.status(), StatusCode::BAD_REQUEST);
}
