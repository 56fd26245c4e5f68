//! Bending moments, outer-fibre stresses and strains, from the curvatures a run records
//! (the one place they are converted): M = EI κ, ε = c κ, σ = E c κ = M c / I, with c
//! the distance from the neutral axis to the outer fibre (half the outer diameter of a
//! tube; unknown for an explicit section without a diameter, when only the moment is
//! reported). Where a pin bends in two directions, κ is the resultant √(κx² + κy²),
//! which a circular section's outer fibre sees whole.

use serde::Serialize;
use utoipa::ToSchema;

use super::common_inputs::{BeamInput, SectionInput};
use crate::physics::integrate::{CurvaturePeak, Simulation};

/// What turns a curvature into a moment, a stress and a strain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flexure {
    /// EI (N·m²).
    pub bending_stiffness: f64,
    /// E (Pa).
    pub young_modulus: f64,
    /// c (m), when known.
    pub fibre: Option<f64>,
}

impl Flexure {
    /// The pin or beam `beam`; `diameter` its outer diameter when given apart from an
    /// explicit section (a hexagonal bundle's D).
    pub fn of(beam: &BeamInput, diameter: Option<f64>) -> Self {
        Self {
            bending_stiffness: beam.spec().bending_stiffness(),
            young_modulus: beam.young_modulus,
            fibre: Self::fibre(beam, diameter),
        }
    }

    /// c (m) of `beam`, as [`Flexure::of`] takes it; `None` when unknown (no stress).
    pub fn fibre(beam: &BeamInput, diameter: Option<f64>) -> Option<f64> {
        match beam.section {
            SectionInput::Tube { outer_diameter, .. } => Some(outer_diameter / 2.0),
            SectionInput::Explicit { .. } => diameter.map(|d| d / 2.0),
        }
    }

    /// M = EI κ (N·m).
    pub fn moment(&self, curvature: f64) -> f64 {
        self.bending_stiffness * curvature
    }

    /// The largest bending at one place as the results give it.
    pub fn bending(&self, peak: &CurvaturePeak) -> Bending {
        Bending {
            height: peak.height,
            pin: peak.pin,
            time: peak.time,
            moment: self.moment(peak.curvature),
            stress: self.fibre.map(|c| self.young_modulus * c * peak.curvature),
            strain: self.fibre.map(|c| c * peak.curvature),
        }
    }
}

/// The flexure of every pin: one per kind of body (`kinds`, the pin's first), and the
/// kind of each pin (none: every pin the first's).
#[derive(Debug, Clone, PartialEq)]
pub struct Flexures {
    kinds: Vec<Flexure>,
    pin_kinds: Vec<usize>,
}

impl Flexures {
    /// Every pin of `flexure`.
    pub fn uniform(flexure: Flexure) -> Self {
        Self {
            kinds: vec![flexure],
            pin_kinds: Vec::new(),
        }
    }

    /// `kinds[k]` for the pins `pin_kinds` gives kind k.
    pub fn by_kind(kinds: Vec<Flexure>, pin_kinds: Vec<usize>) -> Self {
        Self { kinds, pin_kinds }
    }

    /// Pin `pin`'s.
    pub fn of_pin(&self, pin: usize) -> &Flexure {
        &self.kinds[self.pin_kinds.get(pin).copied().unwrap_or(0)]
    }

    /// The bending of `peak`, on its pin.
    pub fn bending(&self, peak: &CurvaturePeak) -> Bending {
        self.of_pin(peak.pin).bending(peak)
    }
}

/// The largest bending at one place over the output samples: at a height (over every
/// pin), of a pin (over its height), or of the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct Bending {
    /// Height from the foot (m).
    pub height: f64,
    /// The pin.
    pub pin: usize,
    /// When (s): an output sample.
    pub time: f64,
    /// Bending moment |M| = EI |κ| (N·m), the resultant of both directions where the pin
    /// bends in two.
    pub moment: f64,
    /// Outer-fibre bending stress |M| c / I (Pa); null for an explicit section without
    /// a diameter.
    pub stress: Option<f64>,
    /// Outer-fibre bending strain c |κ| (dimensionless; 1e-6 is one µε); null likewise.
    pub strain: Option<f64>,
}

/// What a run reports of its bending.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct BendingReport {
    /// The largest bending of the run: where, which pin, when.
    pub max_bending: Bending,
    /// Along the height, at every mesh node from the foot, the largest bending over
    /// every pin and output sample, with the pin and the time.
    pub bending_envelope: Vec<Bending>,
}

impl BendingReport {
    /// The bending of `run`, each pin of its flexure in `flexures`: the envelope's pin at
    /// each node is the most stressed there (the run compares pins of several kinds by
    /// their stress per unit curvature, [`crate::physics::integrate::BodyKind`]), and the
    /// largest bending the most stressed of the envelope (the largest moment where a
    /// stress is unknown).
    pub fn of(run: &Simulation, flexures: &Flexures) -> Self {
        let envelope: Vec<Bending> = (run.curvature_envelope.iter())
            .map(|peak| flexures.bending(peak))
            .collect();
        let severity = |b: &Bending| b.stress.unwrap_or(b.moment);
        let worst = (envelope.iter())
            .max_by(|a, b| severity(a).total_cmp(&severity(b)))
            .copied()
            .unwrap_or_else(|| flexures.bending(&CurvaturePeak::default()));
        Self {
            max_bending: worst,
            bending_envelope: envelope,
        }
    }
}

/// The moment histories: per output height and line (the order of the run's
/// deflections), EI κ per sample (N·m, signed as the curvature), each line of its pin's
/// flexure.
pub fn moment_columns(run: &Simulation, flexures: &Flexures) -> Vec<Vec<f64>> {
    let pins = run.pin_curvatures.len();
    (run.curvatures.iter())
        .flat_map(|per_line| per_line.iter().enumerate())
        .map(|(line, history)| {
            let flexure = flexures.of_pin(line % pins.max(1));
            history.iter().map(|k| flexure.moment(*k)).collect()
        })
        .collect()
}
