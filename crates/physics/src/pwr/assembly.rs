//! The contacts of a PWR assembly on its lattice: each body held in its cell of every
//! spacer grid by a spring and a dimple along x and along y, and side-by-side bodies
//! touching in the spans between grids.
//!
//! # Grid cells
//! At a grid height, the cell of a body pushes it with a spring from one side and holds
//! it with a dimple on the other, along each lattice axis: four contacts with the grid
//! (which moves with the assembly's supports: the walls of the plane model). The spring
//! of stiffness k_s is on the +x (+y) side and pushes toward −x (−y), the dimple of
//! stiffness k_d on the −x (−y) side pushes toward +x (+y). A preloaded cell (preload
//! P > 0) has interferences P/k_s at the spring and P/k_d at the dimple: they balance at
//! rest, and the body moves with the grid as long as the load it carries there stays
//! below what unloads a side. A relaxed cell (P = 0) has gaps instead (the body against
//! its dimples with the spring `spring_gap` away, or loose on both sides).
//!
//! # Spans
//! Between consecutive grids, side-by-side bodies (the lattice's neighbour pairs, normal
//! +x or −y) may touch at `span_points` heights spread evenly in the span, with the gap
//! pitch − (D₁ + D₂)/2 between their surfaces.
//!
//! Contacts are listed grid by grid (each body's four cell contacts: spring and dimple
//! along x, then along y), then span by span (each height, the neighbour pairs in the
//! lattice's order); [`AssemblyContacts::normals`] holds each one's unit normal (from
//! `left` toward `right`, as the plane model takes it).

use super::lattice::{Cell, SquareLattice};
use crate::InputIssue;
use crate::contact::{Body, Contact, Law};

/// How a grid's cells hold one kind of body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellSupport {
    /// Spring and dimple stiffness (N/m).
    pub spring: f64,
    pub dimple: f64,
    /// Preload P (N) of the spring against the dimple, ≥ 0.
    pub preload: f64,
    /// With no preload, the gaps (m) between the body and its spring and dimple, ≥ 0
    /// (a relaxed spring: the body against its dimple, the spring `spring_gap` away).
    pub spring_gap: f64,
    pub dimple_gap: f64,
    /// Dashpot of each contact (N·s/m).
    pub damping: f64,
}

impl CellSupport {
    /// The gaps of the spring and the dimple: interferences P/k with a preload, the
    /// given gaps without.
    fn gaps(&self) -> (f64, f64) {
        if self.preload > 0.0 {
            (-self.preload / self.spring, -self.preload / self.dimple)
        } else {
            (self.spring_gap, self.dimple_gap)
        }
    }
}

/// One spacer grid: its height and how its cells hold each kind of body.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Height from the foot of the bodies (m).
    pub height: f64,
    /// The cells of the fuel rods, of the guide tubes and of the instrumentation tube.
    pub rods: CellSupport,
    pub guide_tubes: CellSupport,
    pub instrument: CellSupport,
}

/// The assembly whose contacts [`AssemblyContacts::of`] lists.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblySpec<'a> {
    pub lattice: &'a SquareLattice,
    /// Cell pitch (m).
    pub pitch: f64,
    /// Outer diameter (m) of the fuel rods, the guide tubes and the instrumentation tube.
    pub diameters: [f64; 3],
    /// Length of the bodies (m): every grid within it.
    pub length: f64,
    /// The grids, by increasing height.
    pub grids: Vec<Grid>,
    /// Heights per span where side-by-side bodies may touch (0: none).
    pub span_points: usize,
    /// Stiffness (N/m) and dashpot (N·s/m) of a body-to-body contact.
    pub body_stiffness: f64,
    pub body_damping: f64,
}

/// The contacts of an assembly and their normals.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyContacts {
    pub contacts: Vec<Contact>,
    pub normals: Vec<[f64; 2]>,
    /// How many of `contacts` are the grids' (the span contacts follow).
    pub grid_contacts: usize,
}

fn kind_index(cell: Cell) -> usize {
    match cell {
        Cell::Rod => 0,
        Cell::GuideTube => 1,
        Cell::InstrumentTube => 2,
    }
}

impl AssemblyContacts {
    /// The contacts of `spec` (module doc), or every problem with it: diameters that
    /// fit their pitch, grids within the bodies in increasing order, valid supports.
    pub fn of(spec: &AssemblySpec<'_>) -> Result<Self, Vec<InputIssue>> {
        let issues = validate(spec);
        if !issues.is_empty() {
            return Err(issues);
        }
        let lattice = spec.lattice;
        let bodies = lattice.size() * lattice.size();
        let (mut contacts, mut normals) = (Vec::new(), Vec::new());
        for grid in &spec.grids {
            for body in 0..bodies {
                let support = [grid.rods, grid.guide_tubes, grid.instrument][kind_index(lattice.cell(body))];
                let (spring_gap, dimple_gap) = support.gaps();
                for axis in [[1.0, 0.0], [0.0, 1.0]] {
                    // The spring on the + side pushes toward −axis, the dimple toward +axis:
                    // the grid is the left body, the force pushes the right one along n.
                    for (gap, stiffness, sign) in [
                        (spring_gap, support.spring, -1.0),
                        (dimple_gap, support.dimple, 1.0),
                    ] {
                        contacts.push(Contact {
                            left: Body::Wall,
                            right: Body::Pin(body),
                            height: grid.height,
                            gap,
                            stiffness,
                            damping: support.damping,
                            law: Law::LINEAR,
                        });
                        normals.push([sign * axis[0], sign * axis[1]]);
                    }
                }
            }
        }
        let grid_contacts = contacts.len();
        let pairs = lattice.neighbours();
        for span in spec.grids.windows(2) {
            let (low, high) = (span[0].height, span[1].height);
            for k in 1..=spec.span_points {
                let height = low + (high - low) * k as f64 / (spec.span_points + 1) as f64;
                for (a, b, normal) in &pairs {
                    let diameter = |i: usize| spec.diameters[kind_index(lattice.cell(i))];
                    contacts.push(Contact {
                        left: Body::Pin(*a),
                        right: Body::Pin(*b),
                        height,
                        gap: spec.pitch - 0.5 * (diameter(*a) + diameter(*b)),
                        stiffness: spec.body_stiffness,
                        damping: spec.body_damping,
                        law: Law::LINEAR,
                    });
                    normals.push(*normal);
                }
            }
        }
        Ok(Self {
            contacts,
            normals,
            grid_contacts,
        })
    }
}

fn validate(spec: &AssemblySpec<'_>) -> Vec<InputIssue> {
    let mut issues = Vec::new();
    crate::require_positive(&mut issues, "pitch", spec.pitch);
    crate::require_positive(&mut issues, "length", spec.length);
    for (k, d) in spec.diameters.iter().enumerate() {
        let field = format!("diameters/{k}");
        crate::require_positive(&mut issues, &field, *d);
        if d.is_finite() && spec.pitch.is_finite() && *d >= spec.pitch {
            issues.push(InputIssue::new(
                field,
                format!("must be below the pitch {} m", spec.pitch),
            ));
        }
    }
    for (g, grid) in spec.grids.iter().enumerate() {
        let field = format!("grids/{g}");
        if !(grid.height.is_finite() && (0.0..=spec.length).contains(&grid.height)) {
            issues.push(InputIssue::new(
                format!("{field}/height"),
                format!("must be within the bodies, 0 to {} m", spec.length),
            ));
        } else if g > 0 && grid.height <= spec.grids[g - 1].height {
            issues.push(InputIssue::new(
                format!("{field}/height"),
                "must be above the grid before it",
            ));
        }
        for (name, support) in [
            ("rods", grid.rods),
            ("guide_tubes", grid.guide_tubes),
            ("instrument", grid.instrument),
        ] {
            let at = format!("{field}/{name}");
            crate::require_positive(&mut issues, &format!("{at}/spring"), support.spring);
            crate::require_positive(&mut issues, &format!("{at}/dimple"), support.dimple);
            crate::require_non_negative(&mut issues, &format!("{at}/preload"), support.preload);
            crate::require_non_negative(&mut issues, &format!("{at}/spring_gap"), support.spring_gap);
            crate::require_non_negative(&mut issues, &format!("{at}/dimple_gap"), support.dimple_gap);
            crate::require_non_negative(&mut issues, &format!("{at}/damping"), support.damping);
            if support.preload > 0.0 && support.spring_gap + support.dimple_gap > 0.0 {
                issues.push(InputIssue::new(
                    format!("{at}/preload"),
                    "a preloaded cell has no gap: give a preload or gaps",
                ));
            }
        }
    }
    crate::require_non_negative(&mut issues, "body_stiffness", spec.body_stiffness);
    crate::require_non_negative(&mut issues, "body_damping", spec.body_damping);
    issues
}

#[cfg(test)]
mod tests;
