//! Point contacts between a pin and a wall or between two pins (BRIEF §3, API.md).
//!
//! In a row (pins bending along x) a contact at height z between `left` L and `right` R
//! has penetration δ = w_L(z) − w_R(z) − gap (a wall's deflection is 0 in the wrapper
//! frame). While δ > 0 it pushes L to the left and R to the right with
//! F = max(0, Kc δ + cc δ̇): the clamp keeps the dashpot from pulling the bodies
//! together while they separate.
//!
//! For pins bending in the transverse plane (x, y) each contact also has a unit normal n
//! from L toward R ([`crate::integrate::Plane`]): δ = n·(u_L(z) − u_R(z)) − gap, the
//! same force law, −F n on L and +F n on R. The row is the plane with every n = +x.
//! There is no friction: the sliding velocity t·(u̇_L − u̇_R), t = (−n_y, n_x), only
//! enters the wear work ∫ F |v_t| dt.

mod restitution;

pub use restitution::{
    hunt_crossley_factor, hunt_crossley_restitution, linear_damping_ratio, linear_restitution,
};

use super::{InputIssue, require_non_negative};

/// One side of a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Body {
    /// The wrapper wall (moves with the base: zero deflection in the wrapper frame).
    Wall,
    /// Pin number (0-based, counted from the left wall).
    Pin(usize),
}

/// A potential contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    pub left: Body,
    pub right: Body,
    /// Height from the pin feet (m).
    pub height: f64,
    /// Gap at rest (m); negative: an interference, the contact pushes at rest (a
    /// preload, which the model's other contacts must balance).
    pub gap: f64,
    /// Penalty stiffness K (N/mⁿ, N/m for the linear law), ≥ 0.
    pub stiffness: f64,
    /// Dashpot cc (N·s/m), ≥ 0.
    pub damping: f64,
    /// The rest of the law: exponent, Hunt–Crossley damping, restitution, friction.
    pub law: Law,
}

/// The rest of a contact's law, beside its stiffness and dashpot ([`Law::LINEAR`]: the
/// linear spring–dashpot without friction). See docs/contact-laws.md.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Law {
    /// n in F = K δⁿ: 1 for the linear law, 3/2 for Hertz (sphere or crossed
    /// cylinders), any n ≥ 1.
    pub exponent: f64,
    /// Hunt–Crossley factor α (s/m): F = K δⁿ (1 + α δ̇), no force jump at first touch
    /// (0: none). With n = 1 it is a dashpot α K δ that grows with the penetration.
    pub hunt_crossley: f64,
    /// A coefficient of restitution in (0, 1] that sets the damping when the model is
    /// laid out on its basis ([`Law::resolve`]); `None`: the damping is as given.
    pub restitution: Option<Restitution>,
    /// The force (N) at which the tangent stiffness n K δⁿ⁻¹ sizes the time step of a
    /// law with n > 1 (the step is stable below it; a run whose peak exceeds it is
    /// judged by its verdict). Unused by the linear law.
    pub force_scale: f64,
    /// Coulomb friction on the contact's tangent (plane contacts only).
    pub friction: Friction,
}

impl Law {
    /// The linear spring–dashpot without friction.
    pub const LINEAR: Law = Law {
        exponent: 1.0,
        hunt_crossley: 0.0,
        restitution: None,
        force_scale: 0.0,
        friction: Friction::NONE,
    };
}

impl Law {
    /// Every problem with this law of a contact whose dashpot is `damping`: n ≥ 1, α
    /// ≥ 0, a force scale for n > 1, a restitution in (0, 1] instead of (not beside) a
    /// damping, with a speed for n > 1, friction μ ≥ 0 with k_t > 0.
    pub fn validate(&self, issues: &mut Vec<InputIssue>, damping: f64) {
        if !(self.exponent.is_finite() && self.exponent >= 1.0) {
            issues.push(InputIssue::new(
                "exponent",
                format!(
                    "must be a number ≥ 1 (1: linear, 1.5: Hertz), got {}",
                    crate::number(self.exponent)
                ),
            ));
        }
        require_non_negative(issues, "hunt_crossley", self.hunt_crossley);
        if self.exponent > 1.0 && !(self.force_scale.is_finite() && self.force_scale > 0.0) {
            issues.push(InputIssue::new(
                "force_scale",
                "a power law (exponent > 1) needs the largest force expected (N, > 0): its tangent \
                 stiffness there sizes the time step",
            ));
        }
        if let Some(restitution) = &self.restitution {
            let e = restitution.coefficient;
            if !(e.is_finite() && e > 0.0 && e <= 1.0) {
                issues.push(InputIssue::new(
                    "restitution",
                    format!("must be in (0, 1] (1: no loss), got {}", crate::number(e)),
                ));
            }
            if damping != 0.0 || self.hunt_crossley != 0.0 {
                issues.push(InputIssue::new(
                    "restitution",
                    "sets the damping: give either a restitution or a damping, not both",
                ));
            }
            if self.exponent > 1.0 && !(restitution.speed.is_finite() && restitution.speed > 0.0) {
                issues.push(InputIssue::new(
                    "restitution_speed",
                    "a power law rebounds with e at one approach speed: give it (m/s, > 0)",
                ));
            }
            if let Some(mass) = restitution.mass
                && !(mass.is_finite() && mass > 0.0)
            {
                issues.push(InputIssue::new("restitution_mass", "must be a mass > 0 (kg)"));
            }
        }
        let friction = &self.friction;
        require_non_negative(issues, "friction/coefficient", friction.coefficient);
        if friction.coefficient > 0.0
            && !(friction.tangential_stiffness.is_finite() && friction.tangential_stiffness > 0.0)
        {
            issues.push(InputIssue::new(
                "friction/tangential_stiffness",
                "friction needs the stick stiffness k_t (N/m, > 0)",
            ));
        }
    }

    /// The damping of a contact of stiffness K that this law's restitution sets: (c, α)
    /// for the linear law, c = 2 ζ(e) √(K m) with the reduced mass m
    /// (`reduced_mass()`, asked only when the restitution gives none), and for n > 1 the
    /// Hunt–Crossley α = a(n, e)/v₀ ([`restitution`]). Without a restitution: as given.
    pub fn damping(&self, stiffness: f64, damping: f64, reduced_mass: impl FnOnce() -> f64) -> (f64, f64) {
        let Some(restitution) = &self.restitution else {
            return (damping, self.hunt_crossley);
        };
        if self.exponent == 1.0 {
            let mass = restitution.mass.unwrap_or_else(reduced_mass);
            let zeta = linear_damping_ratio(restitution.coefficient);
            (2.0 * zeta * (stiffness * mass).sqrt(), 0.0)
        } else {
            let a = hunt_crossley_factor(self.exponent, restitution.coefficient);
            (0.0, a / restitution.speed)
        }
    }
}

impl Default for Law {
    fn default() -> Self {
        Law::LINEAR
    }
}

/// A coefficient of restitution, and for the power law the approach speed at which the
/// impact rebounds with it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Restitution {
    /// e in (0, 1]: rebound over approach speed of a two-body impact.
    pub coefficient: f64,
    /// Approach speed (m/s) at which a Hunt–Crossley law rebounds with e (its e falls
    /// with the speed); unused by the linear law, whose e holds at every speed.
    pub speed: f64,
    /// The reduced mass m₁m₂/(m₁+m₂) (kg) of the linear law's two-body impact; `None`:
    /// from the basis, each pin's apparent mass 1/Σᵢ φᵢ(z)² at the contact (a wall has
    /// infinite mass).
    pub mass: Option<f64>,
}

/// Coulomb friction with a tangential spring (stick) and a slip force μ F_n (code_aster's
/// DIS_CHOC style): the tangential force follows −k_t × the sliding while it stays
/// within μ F_n, and is μ F_n against the sliding beyond. The default is none.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Friction {
    /// μ ≥ 0 (0: no friction).
    pub coefficient: f64,
    /// k_t (N/m) of the stick phase, > 0 when μ > 0.
    pub tangential_stiffness: f64,
}

impl Friction {
    pub const NONE: Friction = Friction {
        coefficient: 0.0,
        tangential_stiffness: 0.0,
    };

    #[inline(always)]
    pub fn is_on(&self) -> bool {
        self.coefficient > 0.0
    }

    /// One step of the stick–slip law (an elastic predictor and a return to the
    /// Coulomb limit): from T₀, the tangential force a step ago (0 on the step the
    /// contact closes), the trial T₀ + k_t v_t Δt sticks while |trial| ≤ μ F_n and
    /// slips at μ F_n beyond, for the sliding speed v_t = t·(u̇_L − u̇_R). T pushes the
    /// right body by +T t and the left one by −T t: it resists the sliding.
    #[inline(always)]
    pub fn step(&self, previous: f64, sliding: f64, dt: f64, normal: f64) -> Tangential {
        let limit = self.coefficient * normal;
        let trial = previous + self.tangential_stiffness * sliding * dt;
        let (force, slipping) = if trial.abs() > limit {
            (limit.copysign(trial), true)
        } else {
            (trial, false)
        };
        // The power the contact absorbs, T v_t, less the rate at which the stick
        // spring stores energy, (T² − T₀²)/(2 k_t Δt).
        let stored = (force * force - previous * previous) / (2.0 * self.tangential_stiffness * dt);
        Tangential {
            force,
            slipping,
            dissipation: force * sliding - stored,
        }
    }

    /// The energy T²/(2 k_t) the stick spring holds at tangential force T (J).
    pub fn energy(&self, force: f64) -> f64 {
        if self.is_on() {
            force * force / (2.0 * self.tangential_stiffness)
        } else {
            0.0
        }
    }
}

/// The force (x, y) a contact with normal n = (n_x, n_y) puts on its right body: F n +
/// T t with t = (−n_y, n_x); the left body gets its opposite.
#[inline(always)]
pub fn force_vector(normal_force: f64, tangential_force: f64, [n_x, n_y]: [f64; 2]) -> [f64; 2] {
    [
        normal_force * n_x - tangential_force * n_y,
        normal_force * n_y + tangential_force * n_x,
    ]
}

/// The tangential state of a closed contact after a step of [`Friction::step`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tangential {
    /// T (N), along t on the right body.
    pub force: f64,
    /// Whether it slips (|T| = μ F_n) rather than sticks.
    pub slipping: bool,
    /// The power friction dissipates (W).
    pub dissipation: f64,
}

/// The normal law as every step loop evaluates it: F = max(0, K δⁿ (1 + α δ̇) + c δ̇)
/// while δ > 0. One law, one place: the row, the plane (one and several threads) and
/// the moving walls call [`NormalLaw::force`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NormalLaw {
    pub stiffness: f64,
    pub damping: f64,
    pub exponent: f64,
    pub hunt_crossley: f64,
}

/// The force of a closed contact and its elastic part K δⁿ (N): the dissipation power
/// is (force − elastic) δ̇.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalForce {
    pub force: f64,
    pub elastic: f64,
}

impl NormalLaw {
    /// The linear spring–dashpot K δ + c δ̇.
    #[inline(always)]
    pub const fn linear(stiffness: f64, damping: f64) -> Self {
        Self {
            stiffness,
            damping,
            exponent: 1.0,
            hunt_crossley: 0.0,
        }
    }

    /// Whether this is the linear spring–dashpot.
    pub fn is_linear(&self) -> bool {
        self.exponent == 1.0 && self.hunt_crossley == 0.0
    }

    /// The force of a contact penetrating by δ > 0 at the rate δ̇: never pulling (the
    /// dashpot and the Hunt–Crossley term cannot make it negative).
    #[inline(always)]
    pub fn force(&self, penetration: f64, rate: f64) -> NormalForce {
        let elastic = if self.exponent == 1.0 {
            self.stiffness * penetration
        } else {
            self.stiffness * penetration.powf(self.exponent)
        };
        let damped = if self.hunt_crossley == 0.0 {
            elastic
        } else {
            elastic * (1.0 + self.hunt_crossley * rate)
        };
        let force = damped + self.damping * rate;
        NormalForce {
            force: force.max(0.0),
            elastic,
        }
    }

    /// Whether the force depends on the penetration rate (then the loops compute it).
    #[inline(always)]
    pub fn needs_rate(&self) -> bool {
        self.damping > 0.0 || self.hunt_crossley > 0.0
    }

    /// The derivatives (∂F/∂δ, ∂F/∂δ̇) of [`NormalLaw::force`]'s unclamped force at δ > 0,
    /// δ̇: n K δⁿ⁻¹ (1 + α δ̇) and K δⁿ α + c (the implicit solve of the `exact_modal`
    /// scheme linearises the law with them).
    pub fn tangent(&self, penetration: f64, rate: f64) -> (f64, f64) {
        let (spring, power) = if self.exponent == 1.0 {
            (self.stiffness, self.stiffness * penetration)
        } else {
            (
                self.exponent * self.stiffness * penetration.powf(self.exponent - 1.0),
                self.stiffness * penetration.powf(self.exponent),
            )
        };
        (
            spring * (1.0 + self.hunt_crossley * rate),
            power * self.hunt_crossley + self.damping,
        )
    }

    /// Whether it can push at all: only such contacts count impacts.
    pub fn is_active(&self) -> bool {
        self.stiffness > 0.0 || self.damping > 0.0
    }

    /// The elastic energy K δⁿ⁺¹/(n + 1) stored at penetration δ (J); 0 when open.
    #[inline]
    pub fn energy(&self, penetration: f64) -> f64 {
        if penetration <= 0.0 {
            0.0
        } else if self.exponent == 1.0 {
            0.5 * self.stiffness * penetration * penetration
        } else {
            self.stiffness * penetration.powf(self.exponent + 1.0) / (self.exponent + 1.0)
        }
    }

    /// The penetration (m) at which the spring alone carries `force` (N).
    pub fn penetration_at(&self, force: f64) -> f64 {
        if force <= 0.0 || self.stiffness <= 0.0 {
            return 0.0;
        }
        (force / self.stiffness).powf(1.0 / self.exponent)
    }
}

impl Contact {
    /// The normal law of this contact (its damping as given: [`Law::resolve`] turns a
    /// restitution into one).
    pub fn normal_law(&self) -> NormalLaw {
        NormalLaw {
            stiffness: self.stiffness,
            damping: self.damping,
            exponent: self.law.exponent,
            hunt_crossley: self.law.hunt_crossley,
        }
    }

    /// The normal law with its damping resolved for bodies of reduced mass
    /// `reduced_mass` ([`Law::damping`]): what the step loops evaluate.
    pub fn resolved_law(&self, reduced_mass: impl FnOnce() -> f64) -> NormalLaw {
        let (damping, hunt_crossley) = self.law.damping(self.stiffness, self.damping, reduced_mass);
        NormalLaw {
            damping,
            hunt_crossley,
            ..self.normal_law()
        }
    }

    /// Force magnitude (N) for penetration δ (m) and its rate δ̇ (m/s): the law while
    /// δ > 0, zero otherwise.
    #[inline]
    pub fn force(&self, penetration: f64, penetration_rate: f64) -> f64 {
        if penetration > 0.0 {
            self.normal_law().force(penetration, penetration_rate).force
        } else {
            0.0
        }
    }

    /// The stiffness (N/m) the stability analysis and the step rules size the step
    /// with: K for the linear law, the tangent n K δⁿ⁻¹ at the force scale for n > 1,
    /// plus nothing for friction (its stick stiffness acts across the normal, see
    /// [`Contact::tangential_stiffness`]).
    pub fn stability_stiffness(&self) -> f64 {
        let law = self.normal_law();
        if law.exponent == 1.0 {
            return self.stiffness;
        }
        let penetration = law.penetration_at(self.law.force_scale);
        law.exponent * self.stiffness * penetration.powf(law.exponent - 1.0)
    }

    /// The stick stiffness k_t (N/m) of the friction, 0 without.
    pub fn tangential_stiffness(&self) -> f64 {
        if self.law.friction.is_on() {
            self.law.friction.tangential_stiffness
        } else {
            0.0
        }
    }

    /// The preload (N) this contact pushes with at rest: the spring at the interference
    /// −gap, 0 with a gap.
    pub fn preload(&self) -> f64 {
        if self.gap < 0.0 {
            self.normal_law().force(-self.gap, 0.0).elastic
        } else {
            0.0
        }
    }

    /// Every problem with this contact for a row of `pins` pins of length `length`.
    pub fn validate(&self, pins: usize, length: f64) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        for (field, body) in [("left", self.left), ("right", self.right)] {
            if let Body::Pin(p) = body
                && p >= pins
            {
                let reason = match pins {
                    0 => format!("pin {p} does not exist (the row has no pin)"),
                    _ => format!("pin {p} does not exist (pins are 0..{})", pins - 1),
                };
                issues.push(InputIssue::new(field, reason));
            }
        }
        if self.left == self.right {
            issues.push(InputIssue::new("right", "a contact needs two different bodies"));
        }
        if !self.height.is_finite() || self.height < 0.0 || self.height > length {
            issues.push(InputIssue::new(
                "height",
                format!("must be within the pin, between 0 and {length} m"),
            ));
        }
        if !self.gap.is_finite() {
            issues.push(InputIssue::new("gap", "must be a finite number"));
        } else if self.gap < 0.0 && (self.stiffness.is_nan() || self.stiffness <= 0.0) {
            issues.push(InputIssue::new(
                "gap",
                "a negative gap (an interference) needs a stiffness > 0 to carry the preload",
            ));
        }
        require_non_negative(&mut issues, "stiffness", self.stiffness);
        require_non_negative(&mut issues, "damping", self.damping);
        let mut law = Vec::new();
        self.law.validate(&mut law, self.damping);
        issues.extend(law.into_iter().map(|issue| issue.within("law")));
        issues
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_acts_only_in_penetration_and_never_pulls() {
        let contact = Contact {
            left: Body::Wall,
            right: Body::Pin(0),
            height: 1.0,
            gap: 0.0,
            stiffness: 100.0,
            damping: 10.0,
            law: Law::LINEAR,
        };
        assert_eq!(contact.force(-1e-3, 5.0), 0.0);
        assert!((contact.force(1e-3, 0.0) - 0.1).abs() < 1e-15);
        assert_eq!(
            contact.force(1e-3, -1.0),
            0.0,
            "separating fast: the dashpot must not pull"
        );
    }

    #[test]
    fn invalid_contact_names_fields() {
        let contact = Contact {
            left: Body::Pin(3),
            right: Body::Wall,
            height: 2.0,
            gap: -1.0,
            stiffness: f64::NAN,
            damping: 0.0,
            law: Law {
                exponent: 0.5,
                restitution: Some(Restitution {
                    coefficient: 1.5,
                    speed: f64::NAN,
                    mass: Some(-1.0),
                }),
                friction: Friction {
                    coefficient: 0.2,
                    tangential_stiffness: 0.0,
                },
                ..Law::LINEAR
            },
        };
        let fields: Vec<String> = contact.validate(2, 1.8).into_iter().map(|i| i.field).collect();
        // A negative gap is an interference, refused here only for want of a stiffness.
        assert_eq!(
            fields,
            [
                "left",
                "height",
                "gap",
                "stiffness",
                "law/exponent",
                "law/restitution",
                "law/restitution_mass",
                "law/friction/tangential_stiffness"
            ]
        );
    }

    #[test]
    fn the_power_law_has_no_force_jump_at_first_touch_and_stores_its_work() {
        let hertz = NormalLaw {
            stiffness: 1e10,
            damping: 0.0,
            exponent: 1.5,
            hunt_crossley: 0.3,
        };
        // A dashpot jumps to c δ̇ at touch; K δⁿ (1 + α δ̇) starts from zero.
        let touch = hertz.force(1e-12, 1.0).force;
        assert!(touch < 1e-7, "{touch}");
        // The elastic energy is the work of the spring: ∫₀^δ K xⁿ dx, by quadrature.
        let depth = 2e-5;
        let steps = 100_000;
        let work: f64 = (0..steps)
            .map(|i| {
                let x = (i as f64 + 0.5) * depth / steps as f64;
                hertz.force(x, 0.0).elastic * depth / steps as f64
            })
            .sum();
        assert!(
            (hertz.energy(depth) - work).abs() < 1e-8 * work,
            "{} vs {work}",
            hertz.energy(depth)
        );
        // The stability stiffness is the tangent dF/dδ at the force scale.
        let contact = Contact {
            left: Body::Wall,
            right: Body::Pin(0),
            height: 1.0,
            gap: 0.0,
            stiffness: hertz.stiffness,
            damping: 0.0,
            law: Law {
                exponent: 1.5,
                force_scale: 200.0,
                ..Law::LINEAR
            },
        };
        let at = hertz.penetration_at(200.0);
        let h = 1e-6 * at;
        let tangent = (hertz.force(at + h, 0.0).elastic - hertz.force(at - h, 0.0).elastic) / (2.0 * h);
        assert!((contact.stability_stiffness() - tangent).abs() < 1e-6 * tangent);
    }
}
