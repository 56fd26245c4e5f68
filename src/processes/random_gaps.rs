//! The laws of random gaps the generators share.

use serde::Deserialize;
use utoipa::ToSchema;

use crate::physics::bundle::GapDistribution;

/// Law of random gaps (m, or factors on the nominal gaps when `relative`): `uniform` or
/// `normal`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum DistributionInput {
    /// Uniform law on [low, high].
    Uniform {
        /// Lowest value (m; dimensionless for `relative` gaps).
        #[schema(minimum = 0.0)]
        low: f64,
        /// Highest value, at least `low` (m; dimensionless for `relative` gaps).
        #[schema(minimum = 0.0)]
        high: f64,
    },
    /// Normal law truncated at 0 (resampled, a true truncated normal).
    Normal {
        /// Mean of the law before truncation (m; dimensionless for `relative` gaps), at
        /// least −30 × `std` (and at least 0 when `std` is 0).
        mean: f64,
        /// Standard deviation of the law before truncation (m; dimensionless for
        /// `relative` gaps).
        #[schema(minimum = 0.0)]
        std: f64,
    },
}

impl DistributionInput {
    /// The law the physics draws from.
    pub fn physics(self) -> GapDistribution {
        match self {
            Self::Uniform { low, high } => GapDistribution::Uniform { low, high },
            Self::Normal { mean, std } => GapDistribution::Normal { mean, std },
        }
    }
}
