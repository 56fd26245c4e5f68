//! Benchmarks of the numerical core (run with `cargo bench`): the row17 bundle case of
//! issue 5 (17 pins × 20 modes, 180 contacts, 200 000 steps) through the whole
//! `bundle-dynamics` process, modal analysis included, without and with the static
//! correction (issue 16: one pseudo-mode per contact height), and the semi-analytic reference
//! of the default cantilever case. Prints wall times and steps per second; targets are
//! ratios read in one run, not asserted (machines are shared and noisy).

use std::ops::ControlFlow;
use std::time::Instant;

use chocmodal::processes::Process;
use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;

fn example(name: &str) -> serde_json::Value {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    let body: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("JSON");
    body["inputs"].clone()
}

fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs {
        let start = Instant::now();
        let value = f();
        best = best.min(start.elapsed().as_secs_f64());
        last = Some(value);
    }
    (best, last.expect("at least one run"))
}

fn main() {
    // `cargo test --all-targets` also runs this binary (without `--bench`): skip there.
    if !std::env::args().any(|a| a == "--bench") {
        println!("benchmarks run with `cargo bench`");
        return;
    }
    let mut row17 = example("bundle-row17.json");
    // The speed target is for the run alone; the check's cost is measured below.
    row17["solver"]["check"] = serde_json::json!("none");
    let mut row17_plain = row17.clone();
    row17_plain["pin"]["static_correction"] = serde_json::json!("none");
    let mut row17_corrected = row17.clone();
    row17_corrected["pin"]["static_correction"] = serde_json::json!("contacts");
    let mut seconds_by_correction = Vec::new();
    for (label, inputs) in [("none", &row17_plain), ("contacts", &row17_corrected)] {
        let (seconds, output) = best_of(3, || {
            BundleDynamics
                .run(inputs, &mut |_| ControlFlow::Continue(()))
                .expect("row17 runs")
        });
        let steps = output.document["steps"].as_f64().unwrap_or(0.0);
        let dofs = &output.document["basis"]["cost"]["modal_dofs_per_pin"];
        println!(
            "row17 bundle-dynamics, static_correction {label} ({dofs} modal DOFs per pin): {seconds:.3} s for \
             {steps} steps = {:.3e} steps/s ({:.2} µs/step), target 0.3 s",
            steps / seconds,
            1e6 * seconds / steps
        );
        seconds_by_correction.push(seconds);
    }
    println!(
        "row17 cost ratio, static correction at the contact heights vs none (same step): {:.2}",
        seconds_by_correction[1] / seconds_by_correction[0]
    );

    accuracy_costs("row17", &BundleDynamics, &row17, 3);

    let cantilever = example("cantilever-impact.json");
    let (seconds, _) = best_of(3, || {
        CantileverImpact
            .run(&cantilever, &mut |_| ControlFlow::Continue(()))
            .expect("cantilever runs")
    });
    println!("cantilever-impact default case (numerical + reference + f_err): {seconds:.3} s");
    let mut cantilever_fixed = cantilever.clone();
    cantilever_fixed["solver"]["check"] = serde_json::json!("none");
    accuracy_costs("cantilever", &CantileverImpact, &cantilever_fixed, 5);

    let reference = chocmodal::physics::reference::CantileverReference {
        length: 1.0,
        young_modulus: 2.1e11,
        density: 7800.0,
        area: std::f64::consts::PI / 4.0 * (0.01f64.powi(2) - 0.009f64.powi(2)),
        inertia: std::f64::consts::PI / 64.0 * (0.01f64.powi(4) - 0.009f64.powi(4)),
        added_mass_per_length: 0.0,
        contact_stiffness: 3.0 * 2.1e11 * std::f64::consts::PI / 64.0 * (0.01f64.powi(4) - 0.009f64.powi(4)),
        gap: 0.0,
        damping_ratios: vec![0.01],
        tip_displacement: 1e-3,
        tip_velocity: 0.0,
        duration: 0.5,
        modes: 30,
        max_events: 100_000,
    };
    let (seconds, _) = best_of(5, || {
        reference
            .solve(&mut |_| ControlFlow::Continue(()))
            .expect("reference solves")
    });
    println!(
        "semi-analytic reference, default case, 30 modes: {:.1} ms",
        1e3 * seconds
    );
}

/// Prints the cost of `time_step: auto` and of the step check (`auto`, the default: at
/// 2Δt where that proves the run, else Δt/2; and `step_halving`) on `inputs` (a
/// fixed-step run with `check: none`) as ratios to that run, each variant timed as the
/// best of `runs`, the variants interleaved run by run.
fn accuracy_costs(name: &str, process: &dyn Process, inputs: &serde_json::Value, runs: usize) {
    let variant = |time_step: Option<&str>, check: &str| {
        let mut body = inputs.clone();
        if let Some(step) = time_step {
            body["solver"]["time_step"] = serde_json::json!(step);
        }
        body["solver"]["check"] = serde_json::json!(check);
        body
    };
    let variants = [
        ("fixed step", variant(None, "none")),
        ("fixed step + step-halving check", variant(None, "step_halving")),
        ("fixed step + auto check", variant(None, "auto")),
        ("auto", variant(Some("auto"), "none")),
        ("auto + step-halving check", variant(Some("auto"), "step_halving")),
        ("auto + auto check (the default)", variant(Some("auto"), "auto")),
    ];
    let mut best = [f64::INFINITY; 6];
    let mut steps = [0.0; 6];
    for _ in 0..runs {
        for (k, (_, body)) in variants.iter().enumerate() {
            let start = Instant::now();
            let output = process
                .run(body, &mut |_| ControlFlow::Continue(()))
                .expect("the variant runs");
            best[k] = best[k].min(start.elapsed().as_secs_f64());
            let document = &output.document;
            steps[k] = document["steps"]
                .as_f64()
                .or_else(|| document["numerical"]["steps"].as_f64())
                .unwrap_or(0.0);
        }
    }
    for (k, (label, _)) in variants.iter().enumerate() {
        println!(
            "{name} {label}: {:.3} s, {} steps, {:.2} × the fixed-step run",
            best[k],
            steps[k],
            best[k] / best[0]
        );
    }
}
