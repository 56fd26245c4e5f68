//! PWR fuel assemblies: square lattices of fuel rods, guide tubes and the
//! instrumentation tube held by spacer grids: the lattice (cells, positions, neighbour
//! pairs, the square's symmetries) and the contacts of the bodies with their grid cells
//! and with each other in the spans, for the plane model of the integrator.

pub mod assembly;
pub mod lattice;

pub use assembly::{AssemblyContacts, AssemblySpec, CellSupport, Grid};
pub use lattice::{Cell, STANDARD_SIZES, SquareLattice, Symmetry};
