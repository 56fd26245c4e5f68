//! Expansion of sweep requests: grid order, random draws within their laws, integer
//! targets, and the errors of malformed requests.

use serde_json::{Value, json};

use super::spec::parse;
use super::*;

fn spec(body: Value) -> SweepSpec {
    parse(&body, 10_000).unwrap_or_else(|e| panic!("{e:?}"))
}

#[test]
fn a_grid_is_the_cartesian_product_with_the_last_axis_fastest() {
    let sweep = spec(json!({"process": "p", "inputs": {"a": 1.0, "b": {"c": 0}},
        "axes": [{"pointer": "/a", "values": [1.0, 2.0]}, {"pointer": "/b/c", "linspace": [0, 20, 3]}]}));
    let runs = sweep.expand();
    let pairs: Vec<(Value, Value)> = runs
        .iter()
        .map(|r| (r.inputs["a"].clone(), r.inputs["b"]["c"].clone()))
        .collect();
    assert_eq!(
        pairs,
        vec![
            (json!(1.0), json!(0)),
            (json!(1.0), json!(10)),
            (json!(1.0), json!(20)),
            (json!(2.0), json!(0)),
            (json!(2.0), json!(10)),
            (json!(2.0), json!(20)),
        ]
    );
}

#[test]
fn logspace_spaces_values_geometrically_with_exact_ends() {
    let sweep = spec(
        json!({"process": "p", "inputs": {"rk": 1.0}, "axes": [{"pointer": "/rk", "logspace": [0.1, 100, 4]}]}),
    );
    let values: Vec<f64> = sweep
        .expand()
        .iter()
        .map(|r| r.inputs["rk"].as_f64().unwrap())
        .collect();
    assert_eq!(values[0], 0.1);
    assert_eq!(values[3], 100.0);
    assert_eq!(
        values,
        [0.1, 1.0, 10.0, 100.0],
        "inner values rounded to 15 significant digits"
    );
}

#[test]
fn random_draws_stay_within_their_laws_and_integer_targets_get_integers() {
    let sweep = spec(json!({"process": "p", "inputs": {"x": 0.0, "modes": 10},
        "axes": [{"pointer": "/x", "uniform": [2.0, 3.0]}, {"pointer": "/modes", "uniform": [5, 15]},
                 {"pointer": "/new", "lognormal": {"mean": 0.0, "std": 0.5}}],
        "samples": 200, "seed": 3}));
    let runs = sweep.expand();
    assert_eq!(runs.len(), 200);
    for run in &runs {
        let x = run.inputs["x"].as_f64().unwrap();
        assert!((2.0..3.0).contains(&x), "{x}");
        let modes = run.inputs["modes"].as_i64().expect("an integer");
        assert!((5..=15).contains(&modes), "{modes}");
        assert!(run.inputs["new"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn list_axes_with_random_axes_repeat_the_same_draws_in_every_cell() {
    let sweep = spec(json!({"process": "p", "inputs": {}, "design": "latin_hypercube",
        "axes": [{"pointer": "/a", "values": ["x", "y"]}, {"pointer": "/g", "normal": {"mean": 1.0, "std": 0.1}}],
        "samples": 3, "seed": 9}));
    let runs = sweep.expand();
    assert_eq!(runs.len(), 6);
    for sample in 0..3 {
        assert_eq!(runs[sample].inputs["a"], json!("x"));
        assert_eq!(runs[3 + sample].inputs["a"], json!("y"));
        assert_eq!(runs[sample].inputs["g"], runs[3 + sample].inputs["g"]);
    }
}

#[test]
fn malformed_requests_name_the_member_at_fault() {
    let errors = match parse(
        &json!({"process": "p", "inputs": {"a": 1.0, "s": "text"},
            "axes": [{"pointer": "/a", "linspace": [0, 1]}, {"pointer": "/s/x", "values": [1]},
                     {"pointer": "/b", "values": [1], "uniform": [0, 1]}],
            "samples": 4, "colour": "red"}),
        100,
    ) {
        Err(SweepError::Invalid(errors)) => errors,
        other => panic!("{other:?}"),
    };
    let pointers: Vec<&str> = errors.iter().map(|e| e.pointer.as_str()).collect();
    for expected in [
        "/colour",
        "/axes/0/linspace",
        "/axes/1/pointer",
        "/axes/2",
        "/samples",
    ] {
        assert!(
            pointers.contains(&expected),
            "{expected} missing from {pointers:?}"
        );
    }
}

#[test]
fn sweeps_over_the_run_limit_are_refused_before_expansion() {
    let result = parse(
        &json!({"process": "p", "inputs": {}, "axes": [
            {"pointer": "/a", "linspace": [0, 1, 1000]}, {"pointer": "/b", "linspace": [0, 1, 1000]},
            {"pointer": "/c", "linspace": [0, 1, 1000]}]}),
        10_000,
    );
    assert_eq!(
        result,
        Err(SweepError::TooLarge {
            runs: 1_000_000_000,
            limit: 10_000
        })
    );
}

#[test]
fn members_of_the_wrong_type_are_all_named_at_once() {
    let errors = match parse(
        &json!({"process": 3, "inputs": [], "design": {"grid": null}, "seed": -1,
            "policy": "sometimes", "invalid_runs": null,
            "axes": [{"pointer": 1, "values": [1]}, 5, {"pointer": "/a", "linspace": ["0", 1, 3]},
                     {"pointer": "/b", "normal": {"mean": 0, "sd": 1}}]}),
        100,
    ) {
        Err(SweepError::Invalid(errors)) => errors,
        other => panic!("{other:?}"),
    };
    let pointers: Vec<&str> = errors.iter().map(|e| e.pointer.as_str()).collect();
    assert_eq!(
        pointers,
        [
            "/process",
            "/inputs",
            "/axes/0/pointer",
            "/axes/1",
            "/axes/2/linspace",
            "/axes/3/normal/sd",
            "/design",
            "/seed",
            "/policy",
            "/invalid_runs",
        ]
    );
    assert_eq!(errors[4].detail, "start and stop must be numbers");
}

#[test]
fn a_body_that_is_no_object_is_refused_whole() {
    assert_eq!(
        parse(&json!([{"process": "p"}]), 100),
        Err(SweepError::Invalid(vec![crate::processes::FieldError::new(
            "",
            "the body must be a JSON object"
        )]))
    );
}

/// A seed names a draw: it is generated as an integer even where the base holds a float
/// and the bounds are floats, and for a new member.
#[test]
fn seeds_are_generated_as_integers() {
    let sweep = spec(json!({"process": "p", "inputs": {"gaps": {"seed": 1.0}},
        "axes": [{"pointer": "/gaps/seed", "uniform": [0.5, 1e9]},
                 {"pointer": "/signal/seed", "linspace": [0.0, 1e9, 3]}],
        "samples": 50, "seed": 9}));
    for run in sweep.expand() {
        for pointer in ["/gaps/seed", "/signal/seed"] {
            let seed = &run.inputs.pointer(pointer).unwrap();
            assert!(seed.is_u64(), "{pointer} of run {}: {seed}", run.index);
        }
    }
}
