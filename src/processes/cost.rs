//! What a run will cost, estimated at validation, and the ceilings a service puts on it.
//!
//! Every process returns a [`WorkEstimate`] from [`super::Process::validate`]: the number
//! of time steps, the modal degrees of freedom and contacts updated at each step, and
//! the values its histories will hold, with the input fields that drive each figure.
//!
//! One kind of ceiling, [`CostLimits`], checked in one place for every process
//! ([`super::simulation`]): [`CostLimits::ABSOLUTE`], what chocmodal runs at all (the
//! CLI included; a refusal is a plain invalid-inputs error), and a service's own, lower
//! ceilings (`--max-work`, `--max-history-values`; a refusal is `too-costly`).
//!
//! Work is counted in "updates": steps × (pins × modes + contacts), the two loops of an
//! explicit step. On the development VM an update costs about 6 ns (`row17`: 1.0e8
//! updates in 0.6 s), so the default ceiling of 2e10 is about two minutes on one core.

use super::FieldError;

/// Most time steps of one pass of a run (the step-halving check's passes not counted).
pub const MAX_STEPS: f64 = 5e7;
/// Default [`CostLimits::max_work`]: about two minutes on one laptop core.
pub const DEFAULT_MAX_WORK: f64 = 2e10;
/// Default [`CostLimits::max_history_values`]: 160 MB of f64 while the run lasts.
pub const DEFAULT_MAX_HISTORY_VALUES: f64 = 2e7;

/// The cost of one run, estimated from its inputs before it runs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WorkEstimate {
    /// Time steps of the whole run (duration / time step), every pass of the accuracy
    /// check included.
    pub steps: f64,
    /// Time steps of one pass (duration / time step): what [`CostLimits::max_steps`]
    /// bounds.
    pub pass_steps: f64,
    /// What set the step, added to a refusal for too many steps (empty for a given step).
    pub step_note: String,
    /// Modal degrees of freedom updated at each step: pins × modes.
    pub modal_dofs: f64,
    /// Contacts evaluated at each step.
    pub contacts: f64,
    /// Values the histories will hold: samples × columns (time included), all histories.
    pub history_values: f64,
    /// The input fields that drive [`WorkEstimate::work`], as pointers into the request
    /// body (`/inputs/solver/duration`, ...).
    pub work_drivers: Vec<String>,
    /// The input fields that drive [`WorkEstimate::history_values`].
    pub history_drivers: Vec<String>,
}

impl WorkEstimate {
    /// Updates: steps × (pins × modes + contacts), proportional to the computing time.
    pub fn work(&self) -> f64 {
        self.steps * (self.modal_dofs + self.contacts)
    }
}

/// Ceilings on the estimated cost of one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostLimits {
    /// Largest [`WorkEstimate::pass_steps`].
    pub max_steps: f64,
    /// Largest [`WorkEstimate::work`].
    pub max_work: f64,
    /// Largest [`WorkEstimate::history_values`].
    pub max_history_values: f64,
}

impl Default for CostLimits {
    fn default() -> Self {
        Self {
            max_steps: MAX_STEPS,
            max_work: DEFAULT_MAX_WORK,
            max_history_values: DEFAULT_MAX_HISTORY_VALUES,
        }
    }
}

/// One ceiling a run exceeds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Excess {
    /// `steps`, `work` or `history_values`.
    pub quantity: String,
    /// The run's estimate.
    pub estimate: f64,
    /// The ceiling.
    pub limit: f64,
}

/// Why a run is refused: the ceilings it exceeds, and one error per driving field.
#[derive(Debug, Clone, PartialEq)]
pub struct TooCostly {
    pub exceeded: Vec<Excess>,
    pub errors: Vec<FieldError>,
}

impl CostLimits {
    /// What chocmodal runs at all, the CLI included: 5e7 steps per pass, 6e11 updates
    /// (about an hour on one core) and 1e8 history values (800 MB of f64).
    pub const ABSOLUTE: CostLimits = CostLimits {
        max_steps: MAX_STEPS,
        max_work: 6e11,
        max_history_values: 1e8,
    };

    /// No ceiling beyond [`CostLimits::ABSOLUTE`], which every run meets anyway (the CLI).
    pub fn unlimited() -> Self {
        Self::ABSOLUTE
    }

    /// `Ok` when the estimate is within every ceiling; otherwise every ceiling exceeded,
    /// with an error at each field that drives it. The messages name the service's
    /// options that set the ceilings.
    pub fn check(&self, estimate: &WorkEstimate) -> Result<(), TooCostly> {
        self.check_with(estimate, "this service's limit", |flag| format!(" (`{flag}`)"))
    }

    /// [`CostLimits::check`] against [`CostLimits::ABSOLUTE`], worded as chocmodal's own limit.
    pub fn check_absolute(estimate: &WorkEstimate) -> Result<(), TooCostly> {
        Self::ABSOLUTE.check_with(estimate, "the limit", |_| String::new())
    }

    fn check_with(
        &self,
        estimate: &WorkEstimate,
        whose: &str,
        option: impl Fn(&str) -> String,
    ) -> Result<(), TooCostly> {
        let mut exceeded = Vec::new();
        let mut errors = Vec::new();
        if estimate.pass_steps > self.max_steps {
            exceeded.push(Excess {
                quantity: "steps".into(),
                estimate: estimate.pass_steps,
                limit: self.max_steps,
            });
            errors.push(FieldError::new(
                "/inputs/solver/duration",
                format!(
                    "needs {:.3e} time steps, above {whose} of {:e}{}",
                    estimate.pass_steps, self.max_steps, estimate.step_note
                ),
            ));
        }
        // Too many steps make the run too much work and too many samples too: the other
        // ceilings are listed as exceeded, but their errors would only restate it at
        // fields that are not the cause (the modes, the pins).
        let steps_exceeded = !errors.is_empty();
        let work = estimate.work();
        if work > self.max_work {
            exceeded.push(Excess {
                quantity: "work".into(),
                estimate: work,
                limit: self.max_work,
            });
            let detail = format!(
                "the run would take {work:.3e} updates ({:.3e} steps × ({} modal DOFs + {} contacts)), \
                 above {whose} of {:.3e}{}: shorten the duration, lengthen \
                 the time step, or use fewer modes, pins or contacts{}",
                estimate.steps,
                estimate.modal_dofs,
                estimate.contacts,
                self.max_work,
                option("--max-work"),
                estimate.step_note
            );
            errors.extend(
                estimate
                    .work_drivers
                    .iter()
                    .filter(|_| !steps_exceeded)
                    .map(|pointer| FieldError::new(pointer.clone(), detail.clone())),
            );
        }
        if estimate.history_values > self.max_history_values {
            exceeded.push(Excess {
                quantity: "history_values".into(),
                estimate: estimate.history_values,
                limit: self.max_history_values,
            });
            let detail = format!(
                "the histories would hold {:.3e} values, above {whose} of {:.3e}{}: \
                 sample less often or over a shorter duration",
                estimate.history_values,
                self.max_history_values,
                option("--max-history-values")
            );
            errors.extend(
                estimate
                    .history_drivers
                    .iter()
                    .filter(|_| !steps_exceeded)
                    .map(|pointer| FieldError::new(pointer.clone(), detail.clone())),
            );
        }
        if exceeded.is_empty() {
            Ok(())
        } else {
            Err(TooCostly { exceeded, errors })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate() -> WorkEstimate {
        WorkEstimate {
            steps: 1e6,
            pass_steps: 1e6,
            modal_dofs: 340.0,
            contacts: 180.0,
            history_values: 4e5,
            work_drivers: vec!["/inputs/solver/duration".into(), "/inputs/pin/modes".into()],
            history_drivers: vec!["/inputs/output/interval".into()],
            ..WorkEstimate::default()
        }
    }

    #[test]
    fn work_is_steps_times_dofs_and_contacts() {
        assert_eq!(estimate().work(), 1e6 * 520.0);
    }

    #[test]
    fn an_estimate_within_the_ceilings_passes() {
        let limits = CostLimits {
            max_steps: 1e6,
            max_work: 5.2e8,
            max_history_values: 4e5,
        };
        assert_eq!(limits.check(&estimate()), Ok(()));
        assert_eq!(CostLimits::unlimited().check(&estimate()), Ok(()));
    }

    #[test]
    fn each_ceiling_exceeded_names_its_drivers_the_estimate_and_the_limit() {
        let limits = CostLimits {
            max_steps: 1e6,
            max_work: 1e8,
            max_history_values: 1e5,
        };
        let refused = limits.check(&estimate()).unwrap_err();
        assert_eq!(refused.exceeded.len(), 2);
        assert_eq!(refused.exceeded[0].estimate, 5.2e8);
        assert_eq!(refused.exceeded[0].limit, 1e8);
        let pointers: Vec<&str> = refused.errors.iter().map(|e| e.pointer.as_str()).collect();
        assert_eq!(
            pointers,
            [
                "/inputs/solver/duration",
                "/inputs/pin/modes",
                "/inputs/output/interval"
            ]
        );
        assert!(
            refused.errors[0].detail.contains("5.200e8"),
            "{:?}",
            refused.errors[0]
        );
        assert!(
            refused.errors[0].detail.contains("1.000e8"),
            "{:?}",
            refused.errors[0]
        );
    }

    #[test]
    fn too_many_steps_point_at_the_duration_and_say_what_set_the_step() {
        let mut estimate = estimate();
        estimate.pass_steps = 6e7;
        estimate.step_note = " (auto chose it)".into();
        let refused = CostLimits::check_absolute(&estimate).unwrap_err();
        assert_eq!(refused.exceeded[0].quantity, "steps");
        assert_eq!(refused.errors[0].pointer, "/inputs/solver/duration");
        assert!(
            refused.errors[0].detail.ends_with("(auto chose it)"),
            "{:?}",
            refused.errors
        );
        assert!(
            !refused.errors[0].detail.contains("service"),
            "{:?}",
            refused.errors
        );
    }

    /// A duration of 1e308 s is too many steps, hence too much work and too many
    /// samples: all three are exceeded, but only the duration is at fault.
    #[test]
    fn too_many_steps_are_not_restated_at_the_other_ceilings_drivers() {
        let mut estimate = estimate();
        estimate.pass_steps = f64::INFINITY;
        estimate.steps = f64::INFINITY;
        estimate.history_values = f64::INFINITY;
        let refused = CostLimits::check_absolute(&estimate).unwrap_err();
        let quantities: Vec<&str> = refused.exceeded.iter().map(|e| e.quantity.as_str()).collect();
        assert_eq!(quantities, ["steps", "work", "history_values"]);
        let pointers: Vec<&str> = refused.errors.iter().map(|e| e.pointer.as_str()).collect();
        assert_eq!(pointers, ["/inputs/solver/duration"]);
    }
}
