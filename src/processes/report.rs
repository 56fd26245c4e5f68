//! The parts of a results document every process shares: the `quality` section (the
//! physics' [`Quality`], serialized as it is, its schema derived from it) and the energy
//! balance with its residual.

use serde::Serialize;
use utoipa::ToSchema;

pub use crate::physics::integrate::{Quality as QualityReport, StepHalving as StepHalvingReport};
use crate::physics::statistics::EnergyBalance;

/// The energy balance at the end of the run (J), in the frame of the moving base, with
/// how far it is from closing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct EnergyReport {
    #[serde(flatten)]
    pub balance: EnergyBalance,
    /// kinetic + strain + contact + dissipated − external_work − initial (J): zero for
    /// exact integration.
    pub residual: f64,
    /// |residual| over the largest energy involved (dimensionless).
    pub relative_residual: f64,
}

impl From<EnergyBalance> for EnergyReport {
    fn from(balance: EnergyBalance) -> Self {
        Self {
            balance,
            residual: balance.residual(),
            relative_residual: balance.relative_residual(),
        }
    }
}
