//! PWR fuel assemblies: square lattices of fuel rods, guide tubes and the
//! instrumentation tube held by spacer grids. So far the lattice itself (cells, positions,
//! neighbour pairs, the square's symmetries); the assembly's model is built on it.

pub mod lattice;

pub use lattice::{Cell, STANDARD_SIZES, SquareLattice, Symmetry};
