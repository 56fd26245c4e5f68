//! Robustness of input parsing and validation, on the shipped examples.
//!
//! - Strictness: an unknown member added to any object of any example's inputs is
//!   refused, with a pointer at that very member (no typo silently falls back to a
//!   default), and likewise in the sweep examples' own members.
//! - Property tests (proptest): arbitrary mutations of the examples (values replaced by
//!   arbitrary JSON, numbers scaled by extreme factors, members removed or added) never
//!   panic validation, and are either accepted with a finite cost estimate or refused
//!   with errors that each point into the request body.

use proptest::prelude::*;
use serde_json::Value;

use std::sync::Arc;

use super::Process;

/// The shipped execution examples of every process of the registry, with their process.
fn examples() -> Vec<(&'static str, Arc<dyn Process>, Value)> {
    let parse =
        |text: &str| serde_json::from_str::<Value>(text).expect("examples are JSON")["inputs"].clone();
    let registry = super::Registry::builtin();
    let all: Vec<_> = (registry.all().iter())
        .flat_map(|process| {
            process
                .examples()
                .iter()
                .map(move |e| (e.file, process.clone(), parse(e.body)))
        })
        .collect();
    assert!(all.len() >= 3, "too few examples: {}", all.len());
    all
}

/// Pointers of every value in `value` (the root is `""`), objects only if `objects_only`.
fn pointers(value: &Value, at: &str, objects_only: bool, out: &mut Vec<String>) {
    if !objects_only || value.is_object() {
        out.push(at.to_owned());
    }
    match value {
        Value::Object(map) => {
            for (key, child) in map {
                let escaped = key.replace('~', "~0").replace('/', "~1");
                pointers(child, &format!("{at}/{escaped}"), objects_only, out);
            }
        }
        Value::Array(items) => {
            for (index, child) in items.iter().enumerate() {
                pointers(child, &format!("{at}/{index}"), objects_only, out);
            }
        }
        _ => {}
    }
}

const TYPO: &str = "zz_typo";

#[test]
fn an_unknown_member_of_any_object_of_the_inputs_is_refused_at_its_pointer() {
    for (name, process, inputs) in examples() {
        let mut objects = Vec::new();
        pointers(&inputs, "", true, &mut objects);
        assert!(objects.len() > 3, "{name}: {objects:?}");
        for object in objects {
            let mut mutated = inputs.clone();
            mutated
                .pointer_mut(&object)
                .and_then(Value::as_object_mut)
                .expect("an object")
                .insert(TYPO.into(), Value::from(1));
            let errors = process
                .validate(&mutated)
                .expect_err(&format!("{name}: a typo in `{object}` was accepted"))
                .0;
            let expected = format!("/inputs{object}/{TYPO}");
            assert!(
                errors.iter().any(|e| e.pointer == expected),
                "{name}: a typo in `{object}` gave {errors:?}, not an error at {expected}"
            );
        }
    }
}

#[test]
fn an_unknown_member_of_a_sweep_is_refused_at_its_pointer() {
    for text in [
        include_str!("../../examples/sweep-calibration.json"),
        include_str!("../../examples/sweep-gaps.json"),
    ] {
        let body: Value = serde_json::from_str(text).unwrap();
        let mut objects = Vec::new();
        pointers(&body, "", true, &mut objects);
        // The base inputs are the process's (checked above, and run by run).
        objects.retain(|p| !p.starts_with("/inputs"));
        assert!(objects.len() >= 2, "{objects:?}");
        for object in objects {
            let mut mutated = body.clone();
            mutated
                .pointer_mut(&object)
                .and_then(Value::as_object_mut)
                .unwrap()
                .insert(TYPO.into(), Value::from(1));
            let expected = format!("{object}/{TYPO}");
            match crate::sweep::spec::parse(&mutated, 10_000) {
                Err(crate::sweep::SweepError::Invalid(errors)) => assert!(
                    errors.iter().any(|e| e.pointer == expected),
                    "a typo in `{object}` gave {errors:?}, not an error at {expected}"
                ),
                other => panic!("a typo in `{object}` gave {other:?}"),
            }
        }
    }
}

/// Arbitrary JSON: scalars that matter to these inputs (keywords, extreme numbers) and
/// small nested arrays and objects.
fn any_json() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
        (-3i64..500).prop_map(Value::from),
        any::<f64>().prop_filter_map("finite", |x| serde_json::Number::from_f64(x).map(Value::Number)),
        prop::sample::select(vec![
            0.0,
            -0.0,
            -1.0,
            5e-324,
            1e-300,
            1e-9,
            0.5,
            1.5,
            1e6,
            1e300,
            f64::MAX,
        ])
        .prop_map(Value::from),
        "[a-z_]{0,10}".prop_map(Value::from),
        prop::sample::select(vec![
            "auto",
            "wall",
            "tube",
            "explicit",
            "uniform",
            "normal",
            "per_contact",
            "random",
            "half_sine",
            "sine",
            "table",
            "tchamwa",
            "central_difference",
            "clamped",
            "pinned",
            "free",
        ])
        .prop_map(Value::from),
    ];
    leaf.prop_recursive(3, 24, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::btree_map("[a-z_]{1,10}", inner, 0..4)
                .prop_map(|map| Value::Object(map.into_iter().collect())),
        ]
    })
}

/// One change to an example.
#[derive(Debug, Clone)]
enum Mutation {
    /// Replace the value at the chosen pointer.
    Replace(prop::sample::Index, Value),
    /// Multiply the number at the chosen pointer (if it is one) by a factor.
    Scale(prop::sample::Index, f64),
    /// Remove the chosen member or element.
    Remove(prop::sample::Index),
    /// Add a member to the chosen object (or an element to the chosen array).
    Add(prop::sample::Index, String, Value),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let known_keys = prop::sample::select(vec![
        "modes",
        "elements",
        "pins",
        "contacts",
        "bundle",
        "levels",
        "gaps",
        "closures",
        "duration",
        "time_step",
        "interval",
        "heights",
        "phi",
        "rk",
        "stiffness",
        "values",
        "seed",
        "count",
    ])
    .prop_map(str::to_owned);
    prop_oneof![
        (any::<prop::sample::Index>(), any_json()).prop_map(|(i, v)| Mutation::Replace(i, v)),
        (
            any::<prop::sample::Index>(),
            prop::sample::select(vec![-1.0, 0.0, 1e-9, 1e-3, 0.5, 2.0, 10.0, 1e3, 1e9, 1e300])
        )
            .prop_map(|(i, f)| Mutation::Scale(i, f)),
        any::<prop::sample::Index>().prop_map(Mutation::Remove),
        (any::<prop::sample::Index>(), known_keys, any_json()).prop_map(|(i, k, v)| Mutation::Add(i, k, v)),
    ]
}

fn apply(inputs: &mut Value, mutation: &Mutation) {
    let mut all = Vec::new();
    pointers(inputs, "", false, &mut all);
    let pick = |index: &prop::sample::Index| all[index.index(all.len())].clone();
    match mutation {
        Mutation::Replace(index, value) => {
            if let Some(target) = inputs.pointer_mut(&pick(index)) {
                *target = value.clone();
            }
        }
        Mutation::Scale(index, factor) => {
            if let Some(target) = inputs.pointer_mut(&pick(index))
                && let Some(x) = target.as_f64()
                && let Some(scaled) = serde_json::Number::from_f64(x * factor)
            {
                *target = Value::Number(scaled);
            }
        }
        Mutation::Remove(index) => {
            let pointer = pick(index);
            if let Some((parent, last)) = pointer.rsplit_once('/') {
                match inputs.pointer_mut(parent) {
                    Some(Value::Object(map)) => {
                        map.remove(&last.replace("~1", "/").replace("~0", "~"));
                    }
                    Some(Value::Array(items)) => {
                        if let Ok(i) = last.parse::<usize>()
                            && i < items.len()
                        {
                            items.remove(i);
                        }
                    }
                    _ => {}
                }
            }
        }
        Mutation::Add(index, key, value) => match inputs.pointer_mut(&pick(index)) {
            Some(Value::Object(map)) => {
                map.insert(key.clone(), value.clone());
            }
            Some(Value::Array(items)) => items.push(value.clone()),
            _ => {}
        },
    }
}

/// A pointer into the request body: under `/inputs`, no empty segment, and where it
/// leaves the body, only through members (a missing or defaulted member, e.g.
/// `/inputs/solver/time_step` when `solver` is not given), never through an element
/// of a list that is not there.
fn points_into(body: &Value, pointer: &str) -> bool {
    if !(pointer == "/inputs" || pointer.starts_with("/inputs/")) || pointer.contains("//") {
        return false;
    }
    let mut at = String::new();
    let mut inside = true;
    for segment in pointer.split('/').skip(1) {
        at.push('/');
        at.push_str(segment);
        if inside && body.pointer(&at).is_none() {
            inside = false;
            if let Some((parent, _)) = at.rsplit_once('/')
                && body.pointer(parent).is_some_and(Value::is_array)
            {
                return false;
            }
        }
    }
    true
}

proptest! {
    // 160 cases by default (a second); `PROPTEST_CASES=5000` for a longer hunt.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|n| n.parse().ok()).unwrap_or(160),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_examples_are_accepted_or_refused_with_pointers_never_panic(
        example in any::<prop::sample::Index>(),
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let mut all = examples();
        let (name, process, mut inputs) = all.swap_remove(example.index(all.len()));
        for m in &mutations {
            apply(&mut inputs, m);
        }
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| process.validate(&inputs)));
        let Ok(outcome) = outcome else {
            return Err(TestCaseError::fail(format!("{name}: validation panicked on {inputs}")));
        };
        let body = serde_json::json!({ "inputs": inputs });
        match outcome {
            Ok(super::Validated { estimate, .. }) => {
                prop_assert!(
                    estimate.work().is_finite() && estimate.work() >= 0.0
                        && estimate.history_values.is_finite() && estimate.history_values >= 0.0,
                    "{}: estimate {:?} for {}", name, estimate, inputs
                );
            }
            Err(invalid) => {
                prop_assert!(!invalid.0.is_empty());
                for error in &invalid.0 {
                    prop_assert!(
                        points_into(&body, &error.pointer),
                        "{}: error {:?} does not point into {}", name, error, body
                    );
                    prop_assert!(!error.detail.is_empty());
                }
            }
        }
    }

    #[test]
    fn any_text_parses_as_a_body_or_gives_a_problem(text in ".{0,200}") {
        if let Err(problem) = crate::json_body::parse(&text) {
            prop_assert!(problem.status == 400 || problem.status == 422, "{:?}", problem);
        }
    }
}
