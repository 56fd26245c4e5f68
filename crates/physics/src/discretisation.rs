//! How far a modal basis and an element mesh are from converged at the contacts: the
//! **impact probe**, a canonical first impact computed exactly (no time step) on a
//! basis, on the complete basis of its mesh, and on the complete basis of a mesh twice
//! as fine.
//!
//! **The probe.** A pin moving in its first mode with unit velocity at height z meets a
//! spring of stiffness k there (the contact closed, no gap). While it is closed the
//! motion is linear: in the coordinates q of a mass-normalised basis,
//! q̈ + (Ω² + k ψψᵀ) q = 0, q(0) = 0, q̇(0) = e₁ / φ₁(z), ψ the basis deflections at z
//! and Ω² their diagonal stiffness (eigenmodes and pseudo-modes alike). With
//! A = Ω² + k ψψᵀ = V Λ² Vᵀ, the penetration is δ(t) = ψᵀq(t) = Σⱼ cⱼ sin(λⱼt)/λⱼ,
//! cⱼ = (ψᵀvⱼ)(vⱼᵀq̇₀), and the contact force k δ(t). Its largest value before the
//! contact first opens (δ back to 0) is the probe's peak force per unit approach
//! velocity (N·s/m). A wall contact is probed with k = Kc; a contact between two
//! identical pins that meet symmetrically with k = 2 Kc (the spring's midpoint stays
//! put, each pin sees half of it).
//!
//! **What it measures.** The peak force of a first impact is set by the contact spring
//! in series with the beam's local dynamic flexibility at z, over the frequencies the
//! impact excites. A truncated basis is too stiff there (the dropped modes' flexibility
//! is missing: peaks too high), a static correction restores the static part of that
//! flexibility but not the dynamics of the dropped modes, and a coarse mesh is too stiff
//! in its upper modes. The probe sees all three, since it integrates nothing: the
//! truncation error of the probe is exact for the mesh ([`Probe::basis_error`], basis
//! against the complete basis of the same mesh) and the mesh error is estimated from
//! the same probe on the mesh refined twice ([`Probe::mesh_error`]).
//!
//! The run's reported peak contact force is a first impact of this kind on shocks; on
//! long rattling it is one of many. The probe's relative errors stand for the errors
//! of the reported peak due to the basis and to the mesh; `docs/accuracy.md` gives the
//! measurements that compare them with converged runs.

use crate::beam::BeamSpec;
use crate::contact::{Body, Contact};
use crate::integrate::Model;
use crate::modal::{ModalBasis, ModalError};

/// Samples per period of the fastest closed-contact frequency that carries weight.
const SAMPLES_PER_PERIOD: f64 = 24.0;
/// A closed-contact mode whose amplitude |cⱼ|/λⱼ in δ(t) is below this fraction of the
/// largest is left out of the sampling rate (it still enters the sum): the upper modes
/// of a fine mesh carry almost nothing and would ask for millions of samples.
const NEGLIGIBLE_AMPLITUDE: f64 = 1e-3;
/// The reported estimate is this multiple of the probe's relative error: a rattling run
/// meets its contacts in richer motions than the probe's first mode, and its peak
/// errors measured 0.3 to 3.2 times the probe's (docs/accuracy.md, "Impact probes").
pub const SAFETY_FACTOR: f64 = 3.0;
/// Contact heights closer than this fraction of the pin length are probed once (a
/// wire-wrapped bundle has hundreds of nearly equal heights).
const HEIGHT_RESOLUTION: f64 = 5e-3;
/// At most this many distinct probes per run: the contacts with the largest peaks.
pub const MAX_PROBES: usize = 24;
/// The probe stops after this many samples (never reached on beams: a guard).
const MAX_SAMPLES: usize = 2_000_000;

/// One contact height and stiffness to probe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeContact {
    /// Height from the pin feet (m).
    pub height: f64,
    /// Spring the pin meets there (N/m): Kc at a wall, 2 Kc between two pins.
    pub stiffness: f64,
}

/// The probe at one contact: peaks on the basis, on its complete mesh, on the mesh
/// refined twice, and the relative errors they give.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    pub contact: ProbeContact,
    /// Peak force per unit approach velocity (N·s/m) on the basis used.
    pub basis_peak: f64,
    /// The same on the complete basis of the same mesh (every free DOF).
    pub mesh_peak: f64,
    /// The same on the complete basis of a mesh with twice the elements.
    pub refined_mesh_peak: f64,
    /// |basis − mesh| / mesh: the error due to the modal truncation (and the static
    /// correction, when the basis carries one), dimensionless.
    pub basis_error: f64,
    /// |mesh − refined| / refined: the error due to the element mesh, dimensionless.
    pub mesh_error: f64,
}

/// Peak force per unit approach velocity (N·s/m) of the first impact at `contact` on
/// `basis` (module doc); `None` where the first mode does not move (a fixed support).
pub fn first_impact_peak(basis: &ModalBasis, contact: ProbeContact) -> Option<f64> {
    let psi = basis.deflection_at(contact.height);
    let terms = closed_contact_terms(basis.angular_frequencies(), &psi, contact.stiffness)?;
    Some(contact.stiffness * first_peak(&terms))
}

/// The terms (cⱼ, λⱼ) of δ(t) = Σ cⱼ sin(λⱼt)/λⱼ for the basis frequencies `omega`
/// (rad/s), deflections `psi` at the contact and spring `k` (module doc); `None` when the
/// first mode does not move at the contact.
///
/// A = Ω² + k ψψᵀ is a rank-one update of a diagonal: its eigenvalues μ are the roots
/// of the secular equation 1 + k Σᵢ ψᵢ²/(ωᵢ² − μ) = 0, one in each interval between two
/// consecutive ωᵢ² and one above the last (found by bisection: the left side increases
/// from −∞ to +∞ on each), with eigenvectors u = (Ω² − μ)⁻¹ψ. Then ψᵀu = −1/k and
/// cⱼ = (ψᵀûⱼ)(ûⱼ₁)/ψ₁ = 1/(k (μⱼ − ω₁²) ‖uⱼ‖²). O(n²) where a dense eigensolver would
/// be O(n³): the complete bases of fine meshes are probed at many contacts.
fn closed_contact_terms(omega: &[f64], psi: &[f64], k: f64) -> Option<Vec<(f64, f64)>> {
    let first = *psi.first()?;
    let largest = psi.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let (first_moves, pushes) = (first.abs() > 1e-6 * largest, k > 0.0);
    if !first_moves || !pushes {
        return None;
    }
    // Modes that do not move at the contact do not take part; the rest by frequency.
    let mut parts: Vec<(f64, f64)> = omega
        .iter()
        .zip(psi)
        .filter(|(_, p)| p.abs() > 1e-12 * largest)
        .map(|(w, p)| (w * w, p * p))
        .collect();
    parts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let d0 = omega[0] * omega[0];
    let secular = |mu: f64| 1.0 + k * parts.iter().map(|&(d, p2)| p2 / (d - mu)).sum::<f64>();
    let total: f64 = parts.iter().map(|&(_, p2)| p2).sum();
    let mut terms = Vec::with_capacity(parts.len());
    for (j, &(d, _)) in parts.iter().enumerate() {
        let upper = parts.get(j + 1).map_or(d + k * total, |next| next.0);
        let (mut lo, mut hi) = (d, upper);
        let open = hi > lo;
        if !open {
            // Two modes at the same frequency: the root sits on it (no weight).
            continue;
        }
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if secular(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let mu = 0.5 * (lo + hi);
        let norm2: f64 = parts.iter().map(|&(d, p2)| p2 / ((d - mu) * (d - mu))).sum();
        let c = 1.0 / (k * (mu - d0) * norm2);
        if mu > 0.0 && c.is_finite() {
            terms.push((c, mu.sqrt()));
        }
    }
    Some(terms)
}

/// The largest δ(t) = Σ cⱼ sin(λⱼt)/λⱼ before δ first returns to 0 (m per m/s).
fn first_peak(terms: &[(f64, f64)]) -> f64 {
    let largest = terms.iter().map(|&(c, l)| c.abs() / l).fold(0.0f64, f64::max);
    let weighted = || {
        terms
            .iter()
            .filter(move |&&(c, l)| c.abs() / l > NEGLIGIBLE_AMPLITUDE * largest)
    };
    let fastest = weighted().map(|&(_, l)| l).fold(0.0f64, f64::max);
    let slowest = weighted().map(|&(_, l)| l).fold(f64::INFINITY, f64::min);
    let moving = fastest > 0.0;
    if !moving {
        return 0.0;
    }
    let dt = std::f64::consts::TAU / (SAMPLES_PER_PERIOD * fastest);
    let penetration = |t: f64| terms.iter().map(|&(c, l)| c * (l * t).sin() / l).sum::<f64>();
    // The contact opens within half the slowest weighted period (the guard bounds the
    // loop should it not).
    let horizon = 4.0 * (std::f64::consts::PI / slowest).max(dt);
    // On the grid t = k·dt each term's (sin λt, cos λt) turns by λ·dt: a rotation instead
    // of a sine per term and sample (the sampling is most of a probe's cost), taken from
    // the exact values again every ANCHOR samples so that rounding stays near 1e-13.
    const ANCHOR: usize = 256;
    let turn: Vec<(f64, f64)> = terms.iter().map(|&(_, l)| (l * dt).sin_cos()).collect();
    let weights: Vec<f64> = terms.iter().map(|&(c, l)| c / l).collect();
    let exact = |k: usize| -> Vec<(f64, f64)> {
        let t = k as f64 * dt;
        terms.iter().map(|&(_, l)| (l * t).sin_cos()).collect()
    };
    let mut phases = exact(1);
    let mut best = (0.0f64, 0.0f64);
    for k in 1..=MAX_SAMPLES {
        if k % ANCHOR == 0 {
            phases = exact(k);
        }
        let t = k as f64 * dt;
        let d: f64 = weights.iter().zip(&phases).map(|(w, (sin, _))| w * sin).sum();
        if d <= 0.0 || t > horizon {
            break;
        }
        if d > best.1 {
            best = (t, d);
        }
        for ((sin, cos), (step_sin, step_cos)) in phases.iter_mut().zip(&turn) {
            (*sin, *cos) = (
                *sin * step_cos + *cos * step_sin,
                *cos * step_cos - *sin * step_sin,
            );
        }
    }
    // Refine the largest sample by golden-section search within one sample either side.
    let (mut lo, mut hi) = ((best.0 - dt).max(0.0), best.0 + dt);
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (x1, x2) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
        if penetration(x1) > penetration(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    penetration(0.5 * (lo + hi)).max(best.1)
}

/// The complete basis of `spec`'s mesh (every free DOF): the mesh's exact dynamics.
pub fn complete_basis(spec: &BeamSpec) -> Result<ModalBasis, ModalError> {
    ModalBasis::compute(spec, spec.free_dof_count())
}

/// The probes of a mesh at some contacts: its complete basis and the mesh twice as fine
/// (computed once, then compared with any basis on that mesh).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshProbes {
    /// The probed contacts (those where the first mode moves) with the peaks of the
    /// complete basis and of the refined mesh (N·s/m).
    probes: Vec<(ProbeContact, f64, f64)>,
}

impl MeshProbes {
    /// Probes `spec`'s mesh and the mesh twice as fine at `contacts`.
    pub fn new(spec: &BeamSpec, contacts: &[ProbeContact]) -> Result<Self, ModalError> {
        let mesh = complete_basis(spec)?;
        let refined = complete_basis(&BeamSpec {
            elements: 2 * spec.elements,
            ..spec.clone()
        })?;
        Ok(Self {
            probes: contacts
                .iter()
                .filter_map(|&contact| {
                    Some((
                        contact,
                        first_impact_peak(&mesh, contact)?,
                        first_impact_peak(&refined, contact)?,
                    ))
                })
                .collect(),
        })
    }

    /// The probes of `basis` (built on this mesh) against the mesh's.
    pub fn compare(&self, basis: &ModalBasis) -> Vec<Probe> {
        self.probes
            .iter()
            .filter_map(|&(contact, mesh_peak, refined_mesh_peak)| {
                let basis_peak = first_impact_peak(basis, contact)?;
                Some(Probe {
                    contact,
                    basis_peak,
                    mesh_peak,
                    refined_mesh_peak,
                    basis_error: relative(basis_peak, mesh_peak),
                    mesh_error: relative(mesh_peak, refined_mesh_peak),
                })
            })
            .collect()
    }

    /// The contacts probed (those where the first mode moves).
    pub fn len(&self) -> usize {
        self.probes.len()
    }

    /// Whether no contact could be probed.
    pub fn is_empty(&self) -> bool {
        self.probes.is_empty()
    }

    /// The largest mesh error over the contacts (dimensionless).
    pub fn mesh_error(&self) -> f64 {
        self.probes
            .iter()
            .map(|&(_, mesh, refined)| relative(mesh, refined))
            .fold(0.0, f64::max)
    }
}

/// The probes at `contacts` for `basis` built on `spec`: basis against its complete
/// mesh, mesh against the mesh twice as fine. Contacts where the first mode does not
/// move are left out.
pub fn probe(
    spec: &BeamSpec,
    basis: &ModalBasis,
    contacts: &[ProbeContact],
) -> Result<Vec<Probe>, ModalError> {
    Ok(MeshProbes::new(spec, contacts)?.compare(basis))
}

/// The estimated error of the reported peak contact force due to one discretisation
/// (the modal basis or the element mesh), at the contact where it is largest.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ProbeError {
    /// Estimated relative error of the peak contact force (dimensionless):
    /// [`SAFETY_FACTOR`] times the probe's, at the contact where it is largest.
    pub estimated_peak_force_error: f64,
    /// Height (m) of the contact where it is largest; null when no contact was probed.
    pub height: Option<f64>,
    /// The spring probed there (N/m): Kc at a wall, 2 Kc between two pins.
    pub probed_stiffness: Option<f64>,
}

/// What the impact probes say of a run's basis and mesh (`quality.modal_truncation`
/// and `quality.mesh`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BasisErrors {
    /// Basis against the complete basis of its mesh.
    pub modal_truncation: ProbeError,
    /// Mesh against the mesh twice as fine.
    pub mesh: ProbeError,
    /// Distinct (height, spring) pairs probed.
    pub probed_contacts: usize,
}

impl ProbeContact {
    /// The probe of `contact` on pins of `length` (m): its height (to
    /// [`HEIGHT_RESOLUTION`] of the length) with Kc at a wall and 2 Kc between two pins
    /// (Kc the law's stiffness at its force scale); `None` for a contact without
    /// stiffness (it never pushes).
    pub fn of(contact: &Contact, length: f64) -> Option<Self> {
        let pushes = contact.stiffness > 0.0;
        let spring = contact.stability_stiffness();
        if !pushes {
            return None;
        }
        let between_pins = matches!((contact.left, contact.right), (Body::Pin(_), Body::Pin(_)));
        let resolution = HEIGHT_RESOLUTION * length;
        Some(ProbeContact {
            height: (contact.height / resolution).round() * resolution,
            stiffness: if between_pins { 2.0 * spring } else { spring },
        })
    }
}

impl BasisErrors {
    /// No probe: every estimate 0 at no height (a run in which no contact pushed, or
    /// whose probes could not be computed; the verdict says which).
    pub fn unmeasured() -> Self {
        let none = ProbeError {
            estimated_peak_force_error: 0.0,
            height: None,
            probed_stiffness: None,
        };
        Self {
            modal_truncation: none,
            mesh: none,
            probed_contacts: 0,
        }
    }
}

/// The probes of one contact of `model` ([`ProbeContact::of`]), each with the kind of
/// the pin it probes (0: the basis's beam, k + 1: `model.kinds[k]`): one, or one per
/// kind when it joins pins of two kinds (each meets the spring of the contact).
fn probe_contact(model: &Model<'_>, pin_kinds: &[usize], contact: usize) -> Vec<(usize, ProbeContact)> {
    let Some(probe) = ProbeContact::of(&model.contacts[contact], model.basis.length()) else {
        return Vec::new();
    };
    let c = &model.contacts[contact];
    let mut kinds: Vec<usize> = [c.left, c.right]
        .iter()
        .filter_map(|body| match body {
            Body::Pin(p) => pin_kinds.get(*p).copied(),
            Body::Wall => None,
        })
        .collect();
    kinds.dedup();
    kinds.into_iter().map(|kind| (kind, probe)).collect()
}

/// The distinct probes of the contacts of `model` that pushed in the run (`peaks`: each
/// contact's peak force, N), the largest peaks first, at most [`MAX_PROBES`]. None when
/// no contact pushed. (Probing only the contacts near the largest peak was tried: it
/// missed a 2.8 % error that the other contacts' probes flag, docs/accuracy.md.)
pub fn probe_contacts(model: &Model<'_>, peaks: &[f64]) -> Vec<ProbeContact> {
    probe_kind_contacts(model, peaks)
        .into_iter()
        .map(|(_, c)| c)
        .collect()
}

/// [`probe_contacts`] with the kind of pin each probes.
fn probe_kind_contacts(model: &Model<'_>, peaks: &[f64]) -> Vec<(usize, ProbeContact)> {
    let pin_kinds = model.pin_kinds();
    let mut candidates: Vec<(f64, (usize, ProbeContact))> = (0..model.contacts.len())
        .filter_map(|c| Some((*peaks.get(c)?, probe_contact(model, &pin_kinds, c))))
        .filter(|(peak, _)| *peak > 0.0)
        .flat_map(|(peak, probes)| probes.into_iter().map(move |p| (peak, p)))
        .collect();
    // The largest peaks first; each distinct probe once, at most MAX_PROBES of them.
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut contacts = distinct(candidates.into_iter().map(|(_, contact)| contact));
    contacts.truncate(MAX_PROBES);
    contacts
}

/// Each probe of `contacts` once, in their order, up to one more than [`MAX_PROBES`].
fn distinct<T: PartialEq>(contacts: impl Iterator<Item = T>) -> Vec<T> {
    let mut kept: Vec<T> = Vec::new();
    for contact in contacts {
        if kept.len() > MAX_PROBES {
            break;
        }
        if !kept.contains(&contact) {
            kept.push(contact);
        }
    }
    kept
}

/// The probes of `model`'s basis and mesh at the contacts that pushed in the run
/// (`peaks`: each contact's peak force, N), each on the basis and beam of the kind of
/// pin it probes.
pub fn assess(model: &Model<'_>, peaks: &[f64]) -> Result<BasisErrors, ModalError> {
    let contacts = probe_kind_contacts(model, peaks);
    let mut probes = Vec::new();
    for kind in 0..=model.kinds.len() {
        let of_kind: Vec<ProbeContact> = contacts
            .iter()
            .filter(|(k, _)| *k == kind)
            .map(|(_, c)| *c)
            .collect();
        if of_kind.is_empty() {
            continue;
        }
        let basis = if kind == 0 {
            model.basis
        } else {
            model.kinds[kind - 1].basis
        };
        probes.extend(probe(basis.spec(), basis, &of_kind)?);
    }
    Ok(BasisErrors::of(&probes))
}

/// The probes of every contact of `model` that could push, computed before its run says
/// which did (on a thread the run leaves free), when there are at most [`MAX_PROBES`]
/// of them (then the run's probes are among them); `None` otherwise.
pub fn prepare(model: &Model<'_>) -> Option<Result<Vec<Probe>, ModalError>> {
    // Bodies of several kinds are probed after the run ([`assess`]).
    if !model.kinds.is_empty() {
        return None;
    }
    let pin_kinds = model.pin_kinds();
    let contacts: Vec<ProbeContact> =
        distinct((0..model.contacts.len()).flat_map(|c| probe_contact(model, &pin_kinds, c)))
            .into_iter()
            .map(|(_, c)| c)
            .collect();
    if contacts.len() > MAX_PROBES {
        return None;
    }
    Some(if contacts.is_empty() {
        Ok(Vec::new())
    } else {
        probe(model.basis.spec(), model.basis, &contacts)
    })
}

/// [`assess`] from the probes [`prepare`] computed: the same figures, bit for bit (each
/// probe is computed alone, and they are taken in the order [`assess`] takes them).
pub fn assess_prepared(model: &Model<'_>, peaks: &[f64], prepared: &[Probe]) -> BasisErrors {
    let probes: Vec<Probe> = probe_contacts(model, peaks)
        .iter()
        .filter_map(|contact| prepared.iter().find(|p| p.contact == *contact).copied())
        .collect();
    BasisErrors::of(&probes)
}

impl BasisErrors {
    /// The worst of `probes`, each estimate [`SAFETY_FACTOR`] times its probe's.
    fn of(probes: &[Probe]) -> Self {
        let worst = |error: fn(&Probe) -> f64| {
            probes.iter().max_by(|a, b| error(a).total_cmp(&error(b))).map_or(
                ProbeError {
                    estimated_peak_force_error: 0.0,
                    height: None,
                    probed_stiffness: None,
                },
                |p| ProbeError {
                    estimated_peak_force_error: SAFETY_FACTOR * error(p),
                    height: Some(p.contact.height),
                    probed_stiffness: Some(p.contact.stiffness),
                },
            )
        };
        Self {
            modal_truncation: worst(|p| p.basis_error),
            mesh: worst(|p| p.mesh_error),
            probed_contacts: probes.len(),
        }
    }
}

fn relative(value: f64, reference: f64) -> f64 {
    if reference == 0.0 {
        if value == 0.0 { 0.0 } else { 1.0 }
    } else {
        (value - reference).abs() / reference.abs()
    }
}

pub mod auto;

#[cfg(test)]
mod tests;
