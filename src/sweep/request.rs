//! The sweep request as it travels: one serde type that reads the body and, through
//! utoipa, is the request's OpenAPI schema (`SweepRequest`, `SweepAxis`).
//!
//! Every member is a [`Member`], so that reading a JSON object never fails on a
//! member's type and [`super::spec`] can report every problem of the request at once;
//! members that are not part of a request are collected (`unknown`) and refused there,
//! each at its own pointer. The same types, once checked, are the axes stored in a
//! sweep's definition ([`super::definition`]) and read back to render its results.
//!
//! ```json
//! {"process": "cantilever-impact", "inputs": {...},
//!  "axes": [{"pointer": "/contact/rk", "logspace": [0.1, 100, 4]},
//!           {"pointer": "/solver/time_step", "values": [1e-5, 5e-5]}],
//!  "design": "grid", "samples": 100, "seed": 7, "policy": "continue"}
//! ```

use serde::{Deserialize, Serialize};
use serde_json::{Map, Number, Value};
use utoipa::ToSchema;

use super::member::Member;

// The schema descriptions are the doc comments of the types and fields below: they are
// what API users read.

/// A sweep request. Integer targets (an integer in the base inputs, or integer bounds)
/// receive generated numbers rounded to integers.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[schema(example = json!({
    "process": "cantilever-impact",
    "inputs": {"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                        "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009}},
               "release": {"tip_displacement": 0.001},
               "solver": {"time_step": 1e-5, "duration": 0.02}},
    "axes": [{"pointer": "/contact/rk", "values": [0.1, 10.0]}]}))]
pub struct SweepRequest {
    /// Process id, e.g. `cantilever-impact`.
    #[serde(default)]
    #[schema(value_type = String, required = true)]
    pub process: Member<String>,
    /// Base inputs of every run (see the process description).
    #[serde(default)]
    #[schema(value_type = Object, required = true)]
    pub inputs: Member<Map<String, Value>>,
    /// The inputs that vary from run to run, at least one.
    #[serde(default)]
    #[schema(value_type = Vec<SweepAxis>, required = true)]
    pub axes: Member<Vec<Member<SweepAxis>>>,
    /// `grid` (the default with list axes only), `monte_carlo` (the default with a
    /// random axis) or `latin_hypercube`.
    #[serde(default)]
    #[schema(value_type = Design, required = false)]
    pub design: Member<Design>,
    /// Draws per grid cell of the list axes; required with random axes (only with them).
    #[serde(default)]
    #[schema(value_type = u64, required = false, minimum = 1)]
    pub samples: Member<u64>,
    /// Seed of the random draws (an integer from 0 to 2⁶⁴ − 1): the same seed gives the
    /// same runs on every machine.
    #[serde(default)]
    #[schema(value_type = u64, required = false, default = 0)]
    pub seed: Member<u64>,
    /// `continue` or `fail_fast`: the first failed run dismisses the others.
    #[serde(default)]
    #[schema(value_type = Policy, required = false, default = "continue")]
    pub policy: Member<Policy>,
    /// `refuse`: any invalid generated run refuses the whole sweep (422); `record`:
    /// invalid runs are recorded as failed jobs with their `invalid-inputs` problem,
    /// never queued, and the valid ones run (maps across a stability limit).
    #[serde(default)]
    #[schema(value_type = InvalidRuns, required = false, default = "refuse")]
    pub invalid_runs: Member<InvalidRuns>,
    // Members that are not part of a request, refused each at its pointer.
    #[serde(flatten)]
    #[schema(ignore)]
    pub unknown: Map<String, Value>,
}

impl SweepRequest {
    /// The members of a request, in the order the refusal of an unknown one lists them.
    pub const MEMBERS: [&str; 8] = [
        "process",
        "inputs",
        "axes",
        "samples",
        "seed",
        "design",
        "policy",
        "invalid_runs",
    ];
}

/// One axis of a sweep: a JSON pointer into the inputs and exactly one of `values`,
/// `linspace`, `logspace` (list axes) or `uniform`, `normal`, `lognormal` (random axes).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, ToSchema)]
pub struct SweepAxis {
    /// JSON pointer into the process inputs, e.g. `/contact/rk`; it must exist in the
    /// base inputs or be creatable there (missing object members are created).
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    #[schema(value_type = String, required = true)]
    pub pointer: Member<String>,
    /// Explicit values, any JSON, at least one.
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    #[schema(value_type = Vec<Object>, required = false)]
    pub values: Member<Vec<Value>>,
    /// `[start, stop, count]`: count (1 to 1000000) evenly spaced values, both ends
    /// exact, the inner ones rounded to 15 significant digits.
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    #[schema(value_type = Vec<f64>, required = false)]
    pub linspace: Member<Spacing>,
    /// `[start, stop, count]`: count (1 to 1000000) geometrically spaced values (not
    /// exponents), start and stop > 0, both ends exact, the inner ones rounded to 15
    /// significant digits.
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    #[schema(value_type = Vec<f64>, required = false)]
    pub logspace: Member<Spacing>,
    /// `[low, high]`: uniform draws on [low, high), finite, low < high.
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    #[schema(value_type = Vec<f64>, required = false)]
    pub uniform: Member<Bounds>,
    /// `{"mean", "std"}`: normal draws (finite mean, std ≥ 0).
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    #[schema(value_type = Object, required = false)]
    pub normal: Member<LawParameters>,
    /// `{"mean", "std"}` of the natural logarithm of the value: lognormal draws (finite
    /// mean, std ≥ 0).
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    #[schema(value_type = Object, required = false)]
    pub lognormal: Member<LawParameters>,
    // Members that are not part of an axis, refused each at its pointer.
    #[serde(flatten)]
    #[schema(ignore)]
    pub unknown: Map<String, Value>,
}

impl SweepAxis {
    /// The kinds of values given (members present, whatever their type): an admitted
    /// axis has exactly one.
    pub fn kinds(&self) -> Vec<AxisKind> {
        AxisKind::ALL
            .into_iter()
            .filter(|kind| match kind {
                AxisKind::Values => !self.values.is_missing(),
                AxisKind::Linspace => !self.linspace.is_missing(),
                AxisKind::Logspace => !self.logspace.is_missing(),
                AxisKind::Uniform => !self.uniform.is_missing(),
                AxisKind::Normal => !self.normal.is_missing(),
                AxisKind::Lognormal => !self.lognormal.is_missing(),
            })
            .collect()
    }

    /// The kind of values of an axis with exactly one.
    pub fn kind(&self) -> Option<AxisKind> {
        match self.kinds().as_slice() {
            [kind] => Some(*kind),
            _ => None,
        }
    }
}

/// How an axis gives its values: the member that holds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisKind {
    /// `values`: explicit values.
    Values,
    /// `linspace`: evenly spaced values.
    Linspace,
    /// `logspace`: geometrically spaced values.
    Logspace,
    /// `uniform`: uniform draws.
    Uniform,
    /// `normal`: normal draws.
    Normal,
    /// `lognormal`: lognormal draws.
    Lognormal,
}

impl AxisKind {
    /// In the order the refusals list them.
    pub const ALL: [AxisKind; 6] = [
        AxisKind::Values,
        AxisKind::Linspace,
        AxisKind::Logspace,
        AxisKind::Uniform,
        AxisKind::Normal,
        AxisKind::Lognormal,
    ];

    /// The member's name.
    pub fn name(self) -> &'static str {
        match self {
            AxisKind::Values => "values",
            AxisKind::Linspace => "linspace",
            AxisKind::Logspace => "logspace",
            AxisKind::Uniform => "uniform",
            AxisKind::Normal => "normal",
            AxisKind::Lognormal => "lognormal",
        }
    }

    /// Random axes draw their values from a law (`samples` per grid cell); the others
    /// list them (one grid dimension each).
    pub fn is_random(self) -> bool {
        matches!(self, AxisKind::Uniform | AxisKind::Normal | AxisKind::Lognormal)
    }

    /// Every name, comma-separated (for refusals).
    pub fn names() -> String {
        Self::ALL.map(Self::name).join(", ")
    }
}

/// `[start, stop, count]` of `linspace` and `logspace`; start and stop as written
/// (an integer stays one), each member checked on its own.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct Spacing(pub Member<Number>, pub Member<Number>, pub Member<u64>);

/// `[low, high]` of `uniform`, as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct Bounds(pub Number, pub Number);

/// `{"mean", "std"}` of `normal` and `lognormal`, as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct LawParameters {
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    pub mean: Member<Number>,
    #[serde(default, skip_serializing_if = "Member::is_missing")]
    pub std: Member<Number>,
    // Members other than mean and std, refused each at its pointer.
    #[serde(flatten)]
    pub unknown: Map<String, Value>,
}

/// How the runs are chosen: `grid`, `monte_carlo` or `latin_hypercube`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(try_from = "String", into = "&'static str")]
#[schema(rename_all = "snake_case")]
pub enum Design {
    /// Cartesian product of list axes (no random axis).
    Grid,
    /// Independent draws of the random axes.
    MonteCarlo,
    /// Stratified draws: each random axis hits each of its `samples` equal-probability strata once.
    LatinHypercube,
}

impl Design {
    pub fn as_str(self) -> &'static str {
        match self {
            Design::Grid => "grid",
            Design::MonteCarlo => "monte_carlo",
            Design::LatinHypercube => "latin_hypercube",
        }
    }

    pub fn parse(text: &str) -> Option<Self> {
        [Design::Grid, Design::MonteCarlo, Design::LatinHypercube]
            .into_iter()
            .find(|d| d.as_str() == text)
    }
}

/// What a failed run does to the rest of the sweep: `continue` or `fail_fast`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(try_from = "String", into = "&'static str")]
#[schema(rename_all = "snake_case")]
pub enum Policy {
    /// The other runs go on; the sweep ends `successful` once every run ended.
    Continue,
    /// The first failed run dismisses the runs not finished; the sweep is `failed`.
    FailFast,
}

impl Policy {
    pub fn as_str(self) -> &'static str {
        match self {
            Policy::Continue => "continue",
            Policy::FailFast => "fail_fast",
        }
    }

    pub fn parse(text: &str) -> Option<Self> {
        [Policy::Continue, Policy::FailFast]
            .into_iter()
            .find(|p| p.as_str() == text)
    }
}

/// What happens to generated runs whose inputs the process refuses: `refuse` or
/// `record`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(try_from = "String", into = "&'static str")]
#[schema(rename_all = "snake_case")]
pub enum InvalidRuns {
    /// The whole sweep is refused (422), nothing is queued.
    Refuse,
    /// The sweep is queued; each invalid run is recorded as a `failed` job with its
    /// `invalid-inputs` problem and never reaches a worker (calibration maps that cross
    /// the stability limit: such cells are simply not valid).
    Record,
}

impl InvalidRuns {
    pub fn as_str(self) -> &'static str {
        match self {
            InvalidRuns::Refuse => "refuse",
            InvalidRuns::Record => "record",
        }
    }

    pub fn parse(text: &str) -> Option<Self> {
        [InvalidRuns::Refuse, InvalidRuns::Record]
            .into_iter()
            .find(|i| i.as_str() == text)
    }
}

// The choices are JSON strings (their `as_str`), never the `{"grid": null}` of serde's
// externally tagged enums.
macro_rules! string_choice {
    ($($choice:ident),+) => {$(
        impl From<$choice> for &'static str {
            fn from(choice: $choice) -> Self {
                choice.as_str()
            }
        }

        impl TryFrom<String> for $choice {
            type Error = String;

            fn try_from(text: String) -> Result<Self, String> {
                Self::parse(&text)
                    .ok_or_else(|| format!("`{text}` is no {}", stringify!($choice)))
            }
        }
    )+};
}
string_choice!(Design, Policy, InvalidRuns);

#[cfg(test)]
mod tests {
    use serde_json::json;
    use utoipa::PartialSchema;

    use super::*;

    #[test]
    fn the_members_listed_in_refusals_are_the_schemas_properties() {
        let schema = serde_json::to_value(SweepRequest::schema()).unwrap();
        let mut properties: Vec<&str> = schema["properties"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        let mut members = SweepRequest::MEMBERS.to_vec();
        properties.sort_unstable();
        members.sort_unstable();
        assert_eq!(properties, members);
        let axis = serde_json::to_value(SweepAxis::schema()).unwrap();
        let mut properties: Vec<&str> = axis["properties"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        let mut members: Vec<&str> = AxisKind::ALL.map(AxisKind::name).to_vec();
        members.push("pointer");
        properties.sort_unstable();
        members.sort_unstable();
        assert_eq!(properties, members);
    }

    #[test]
    fn choices_are_strings_and_nothing_else() {
        for design in [Design::Grid, Design::MonteCarlo, Design::LatinHypercube] {
            let text = serde_json::to_value(design).unwrap();
            assert_eq!(text, json!(design.as_str()));
            assert_eq!(serde_json::from_value::<Design>(text).unwrap(), design);
        }
        assert!(serde_json::from_value::<Design>(json!({"grid": null})).is_err());
        assert_eq!(
            serde_json::from_value::<Policy>(json!("fail_fast")).unwrap(),
            Policy::FailFast
        );
        assert!(serde_json::from_value::<InvalidRuns>(json!("Refuse")).is_err());
    }

    #[test]
    fn an_axis_reads_back_as_written() {
        let given = json!({"pointer": "/beam/modes", "linspace": [2, 8.0, 4]});
        let axis: SweepAxis = serde_json::from_value(given.clone()).unwrap();
        assert_eq!(axis.kind(), Some(AxisKind::Linspace));
        assert_eq!(serde_json::to_value(&axis).unwrap(), given);
        let given = json!({"pointer": "/g", "normal": {"mean": 1, "std": 0.5}});
        let axis: SweepAxis = serde_json::from_value(given.clone()).unwrap();
        assert!(axis.kind().is_some_and(AxisKind::is_random));
        assert_eq!(serde_json::to_value(&axis).unwrap(), given);
    }
}
