//! Accuracy of `time_step: auto` and of the step-halving check on the class of jobs
//! engineers submit: rows of 5 to 20 pins (E from 2e9 to 2.1e11 Pa, Kc from 1e5 to
//! 1e7 N/m, gaps 0 to 1 mm) under sine, half-sine and table base excitation.
//!
//! The Δt → 0 limit of a result X is estimated from runs at Δt/10 and Δt/20 of the
//! `auto` step by Richardson extrapolation for a second-order scheme:
//! X* = X(h/20) + (X(h/20) − X(h/10)) / 3. Nothing here is compared with a number
//! copied from our own output.

use super::*;
use crate::physics::beam::{BeamSpec, Section, Support};
use crate::physics::contact::Body;
use crate::physics::loads::Table;

/// A row of identical pins between two walls.
#[derive(Debug, Clone)]
struct Row {
    pins: usize,
    length: f64,
    young_modulus: f64,
    levels: usize,
    stiffness: f64,
    gap: f64,
    modes: usize,
    excitation: BaseAcceleration,
    duration: f64,
}

impl Row {
    /// The plausible job: 7 pins of 1.2 m, tube 9.7/8.5 mm, 6 levels,
    /// Kc = 1e6 N/m, gaps 0.1 mm, a 10 Hz sine base shake.
    fn plausible() -> Self {
        Self {
            pins: 7,
            length: 1.2,
            young_modulus: 2.1e11,
            levels: 6,
            stiffness: 1e6,
            gap: 1e-4,
            modes: 10,
            excitation: BaseAcceleration::Sine {
                amplitude: 20.0,
                frequency: 10.0,
                cycles: 100.0,
            },
            duration: 0.3,
        }
    }

    fn basis(&self) -> ModalBasis {
        let spec = BeamSpec {
            length: self.length,
            young_modulus: self.young_modulus,
            density: 7800.0,
            section: Section::Tube {
                outer_diameter: 0.0097,
                inner_diameter: 0.0085,
            },
            added_mass_per_length: 0.3,
            elements: 30,
            foot: Support::Clamped,
            top: Support::Free,
        };
        ModalBasis::compute(&spec, self.modes).expect("valid pin")
    }

    fn model<'a>(&self, basis: &'a ModalBasis) -> Model<'a> {
        let mut contacts = Vec::new();
        for level in 1..=self.levels {
            let height = self.length * level as f64 / self.levels as f64;
            let bodies: Vec<Body> = std::iter::once(Body::Wall)
                .chain((0..self.pins).map(Body::Pin))
                .chain(std::iter::once(Body::Wall))
                .collect();
            for pair in bodies.windows(2) {
                contacts.push(Contact {
                    left: pair[0],
                    right: pair[1],
                    height,
                    gap: self.gap,
                    stiffness: self.stiffness,
                    damping: 0.0,
                });
            }
        }
        Model {
            basis,
            pins: self.pins,
            damping_ratios: vec![0.01; basis.modes()],
            contacts,
            initial_tip_displacements: vec![],
            base_acceleration: Some(self.excitation.clone()),
            point_forces: vec![],
        }
    }

    fn settings(&self, time_step: TimeStep) -> Settings {
        Settings {
            scheme: Scheme::CentralDifference,
            time_step,
            tolerance: DEFAULT_TOLERANCE,
            check: Check::None,
            duration: self.duration,
            output_interval: Some(1e-3),
            output_heights: vec![self.length],
        }
    }
}

fn figures(simulation: &Simulation) -> (f64, f64, f64) {
    let figures = quality::KeyFigures::of(simulation);
    (
        figures.peak_force,
        figures.peak_displacement,
        simulation.energy.relative_residual(),
    )
}

/// Prints, for several steps per period, the energy residual and the peak errors
/// against the extrapolated limit (calibration of [`step_size::STEPS_PER_PERIOD`]).
#[test]
#[ignore = "calibration table, run by hand with --nocapture"]
fn calibration_table() {
    let mut cases = vec![("plausible", Row::plausible())];
    let base = Row::plausible();
    cases.push((
        "soft E 2e9",
        Row {
            young_modulus: 2e9,
            ..base.clone()
        },
    ));
    cases.push((
        "Kc 1e7 gap 0",
        Row {
            stiffness: 1e7,
            gap: 0.0,
            ..base.clone()
        },
    ));
    cases.push((
        "Kc 1e5 gap 1mm",
        Row {
            stiffness: 1e5,
            gap: 1e-3,
            ..base.clone()
        },
    ));
    cases.push((
        "20 pins half-sine",
        Row {
            pins: 20,
            excitation: BaseAcceleration::HalfSine {
                amplitude: 100.0,
                duration: 0.01,
            },
            duration: 0.1,
            ..base.clone()
        },
    ));
    cases.push((
        "5 pins table",
        Row {
            pins: 5,
            excitation: BaseAcceleration::Table(Table {
                time: (0..=200).map(|k| k as f64 * 5e-4).collect(),
                values: (0..=200)
                    .map(|k| 30.0 * ((k as f64 * 0.37).sin() + (k as f64 * 0.11).cos()))
                    .collect(),
            }),
            duration: 0.15,
            ..base.clone()
        },
    ));
    cases.push((
        "E in MPa",
        Row {
            young_modulus: 2.1e5,
            ..base.clone()
        },
    ));
    let short: Vec<(String, Row)> = cases
        .iter()
        .map(|(name, row)| (format!("{name}, first 30 ms"), Row { duration: 0.03, ..row.clone() }))
        .collect();
    let cases: Vec<(String, Row)> = cases
        .into_iter()
        .map(|(n, r)| (n.to_owned(), r))
        .chain(short)
        .collect();
    for (name, row) in cases {
        let basis = row.basis();
        let model = row.model(&basis);
        let omega = step_size::max_frequency(&model);
        let period = std::f64::consts::TAU / omega;
        let at = |dt: f64| {
            simulate(&model, &row.settings(TimeStep::Fixed(dt)), &mut |_| ControlFlow::Continue(()))
                .map(|s| figures(&s))
        };
        let reference_dt = period / 30.0;
        let (Ok(fine), Ok(finer)) = (at(reference_dt / 10.0), at(reference_dt / 20.0)) else {
            println!("{name}: reference runs failed");
            continue;
        };
        let limit_force = finer.0 + (finer.0 - fine.0) / 3.0;
        let limit_disp = finer.1 + (finer.1 - fine.1) / 3.0;
        println!(
            "{name}: ω_max {omega:.3e} rad/s, critical {:.3e} s, limit force {limit_force:.5e} N, disp {limit_disp:.5e} m",
            2.0 / omega
        );
        for per_period in [20.0, 30.0, 40.0, 50.0, 60.0] {
            let dt = period / per_period;
            match at(dt) {
                Ok((force, disp, residual)) => {
                    let half = at(dt / 2.0).expect("half step runs");
                    let estimate = 4.0 / 3.0 * (force - half.0).abs() / half.0.max(1e-300);
                    println!(
                        "  N {per_period:>4}: residual {residual:.2e}, force err {:+.2e} (est {estimate:.2e}), disp err {:+.2e}",
                        force / limit_force - 1.0,
                        disp / limit_disp - 1.0
                    );
                }
                Err(e) => println!("  N {per_period:>4}: {e}"),
            }
        }
    }
}
