//! The square lattice of a PWR fuel assembly: n × n cells at a pitch P, each holding a
//! fuel rod, a guide tube or the instrumentation tube. Pure topology; lengths enter only
//! through the pitch.
//!
//! # Numbering (stable: part of the results' contract)
//! Cell (row, column), both from 0, row 0 on top (+y) and column 0 on the left (−x), as
//! an assembly is drawn seen from its top nozzle; cell number = row · n + column. Its
//! centre is x = (column − (n − 1)/2) P, y = ((n − 1)/2 − row) P about the assembly's
//! axis.
//!
//! # Neighbour pairs
//! Along x each of the n rows holds n − 1 pairs of side-by-side cells, along y each
//! column: 2n(n − 1) pairs (17 × 17: 544), each with its unit normal from the first cell
//! to the second, +x or −y. These are where rods can touch in a span between grids.
//!
//! # Symmetries
//! The square's eight symmetries (the dihedral group D4: the quarter turns and the four
//! mirrors, [`Symmetry`]) map cells onto cells; [`SquareLattice::symmetries`] gives those
//! that map every guide tube onto a guide tube and the instrumentation tube onto itself.
//! The standard lattices have all eight.

use crate::InputIssue;

/// What a cell of the lattice holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cell {
    Rod,
    GuideTube,
    InstrumentTube,
}

/// One of the eight symmetries of the square about the assembly's axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Symmetry {
    /// Counter-clockwise by 0, 90, 180 or 270°.
    Turn(u8),
    /// Mirror across the vertical axis (x → −x), the horizontal one (y → −y), the
    /// diagonal y = x and the anti-diagonal y = −x.
    MirrorX,
    MirrorY,
    MirrorDiagonal,
    MirrorAntiDiagonal,
}

impl Symmetry {
    /// All eight.
    pub const ALL: [Symmetry; 8] = [
        Symmetry::Turn(0),
        Symmetry::Turn(1),
        Symmetry::Turn(2),
        Symmetry::Turn(3),
        Symmetry::MirrorX,
        Symmetry::MirrorY,
        Symmetry::MirrorDiagonal,
        Symmetry::MirrorAntiDiagonal,
    ];

    /// The image of the point (x, y) about the axis.
    pub fn apply(self, [x, y]: [f64; 2]) -> [f64; 2] {
        match self {
            Symmetry::Turn(k) => match k % 4 {
                0 => [x, y],
                1 => [-y, x],
                2 => [-x, -y],
                _ => [y, -x],
            },
            Symmetry::MirrorX => [-x, y],
            Symmetry::MirrorY => [x, -y],
            Symmetry::MirrorDiagonal => [y, x],
            Symmetry::MirrorAntiDiagonal => [-y, -x],
        }
    }
}

/// The lattice sizes whose guide-tube pattern is built in ([`SquareLattice::standard`]).
pub const STANDARD_SIZES: [usize; 1] = [17];

/// The guide tubes of the standard 17 × 17 lattice (Westinghouse type) in one octant of
/// the square, (row, column) from its centre cell (0 ≤ column offset ≤ row offset): the
/// rest by the eight symmetries; the instrumentation tube at the centre.
const GUIDE_TUBES_17: [(i64, i64); 5] = [(3, 0), (3, 3), (6, 0), (5, 5), (6, 3)];

/// A square lattice of cells and what each holds.
#[derive(Debug, Clone, PartialEq)]
pub struct SquareLattice {
    size: usize,
    cells: Vec<Cell>,
}

impl SquareLattice {
    /// The standard lattice of `size` × `size` cells (one of [`STANDARD_SIZES`]): 17 × 17,
    /// 264 fuel rods, 24 guide tubes and the central instrumentation tube.
    pub fn standard(size: usize) -> Result<Self, String> {
        if size != 17 {
            return Err(format!(
                "no built-in guide-tube pattern for {size} × {size} (built in: {}); give the \
                 guide-tube positions",
                STANDARD_SIZES.map(|s| format!("{s} × {s}")).join(", ")
            ));
        }
        let centre = (size / 2) as i64;
        let mut guide_tubes = Vec::new();
        for (a, b) in GUIDE_TUBES_17 {
            for (dr, dc) in [(a, b), (b, a)] {
                for (sr, sc) in [(1, 1), (1, -1), (-1, 1), (-1, -1)] {
                    let cell = ((centre + sr * dr) as usize, (centre + sc * dc) as usize);
                    if !guide_tubes.contains(&cell) {
                        guide_tubes.push(cell);
                    }
                }
            }
        }
        let centre = centre as usize;
        Self::new(size, &guide_tubes, Some((centre, centre))).map_err(|issues| format!("{issues:?}"))
    }

    /// `size` × `size` cells of fuel rods but for the guide tubes at `guide_tubes` and the
    /// instrumentation tube at `instrument` ((row, column) each): refused when a position
    /// is outside the lattice or given twice (issues at `guide_tubes/<k>`, `instrument`).
    pub fn new(
        size: usize,
        guide_tubes: &[(usize, usize)],
        instrument: Option<(usize, usize)>,
    ) -> Result<Self, Vec<InputIssue>> {
        let mut issues = Vec::new();
        if size == 0 {
            issues.push(InputIssue::new("size", "a lattice needs at least one cell"));
            return Err(issues);
        }
        let mut cells = vec![Cell::Rod; size * size];
        let placed =
            std::iter::once(instrument.map(|at| (at, Cell::InstrumentTube, "instrument".to_owned())))
                .flatten()
                .chain(
                    guide_tubes
                        .iter()
                        .enumerate()
                        .map(|(k, at)| (*at, Cell::GuideTube, format!("guide_tubes/{k}"))),
                );
        for ((row, column), kind, field) in placed {
            if row >= size || column >= size {
                issues.push(InputIssue::new(
                    field,
                    format!(
                        "({row}, {column}) is outside the {size} × {size} lattice (rows and columns 0 to {})",
                        size - 1
                    ),
                ));
                continue;
            }
            let cell = &mut cells[row * size + column];
            if *cell != Cell::Rod {
                issues.push(InputIssue::new(
                    field,
                    format!("({row}, {column}) already holds a {}", name(*cell)),
                ));
                continue;
            }
            *cell = kind;
        }
        if issues.is_empty() {
            Ok(Self { size, cells })
        } else {
            Err(issues)
        }
    }

    /// Cells per side.
    pub fn size(&self) -> usize {
        self.size
    }

    /// What cell `index` holds.
    pub fn cell(&self, index: usize) -> Cell {
        self.cells[index]
    }

    /// How many cells hold `kind`.
    pub fn count(&self, kind: Cell) -> usize {
        self.cells.iter().filter(|c| **c == kind).count()
    }

    /// The cells holding `kind`, in number order.
    pub fn cells_of(&self, kind: Cell) -> Vec<usize> {
        (0..self.cells.len()).filter(|i| self.cells[*i] == kind).collect()
    }

    /// (row, column) of cell `index`.
    pub fn row_column(&self, index: usize) -> (usize, usize) {
        (index / self.size, index % self.size)
    }

    /// Centre of cell `index` (m) for the pitch `pitch` (module doc).
    pub fn position(&self, index: usize, pitch: f64) -> [f64; 2] {
        let (row, column) = self.row_column(index);
        let half = (self.size as f64 - 1.0) / 2.0;
        [(column as f64 - half) * pitch, (half - row as f64) * pitch]
    }

    /// Every pair of side-by-side cells (first, second, unit normal from the first to
    /// the second): along x row by row, then along y column by column (module doc).
    pub fn neighbours(&self) -> Vec<(usize, usize, [f64; 2])> {
        let n = self.size;
        let along_x =
            (0..n).flat_map(move |row| (0..n - 1).map(move |c| (row * n + c, row * n + c + 1, [1.0, 0.0])));
        let along_y = (0..n).flat_map(move |column| {
            (0..n - 1).map(move |r| (r * n + column, (r + 1) * n + column, [0.0, -1.0]))
        });
        along_x.chain(along_y).collect()
    }

    /// The cell `symmetry` maps cell `index` onto.
    pub fn image(&self, index: usize, symmetry: Symmetry) -> usize {
        // About the axis in units of the pitch, doubled to stay on integers.
        let (row, column) = self.row_column(index);
        let last = self.size as f64 - 1.0;
        let [x, y] = symmetry.apply([2.0 * column as f64 - last, last - 2.0 * row as f64]);
        let (column, row) = ((x + last) / 2.0, (last - y) / 2.0);
        row.round() as usize * self.size + column.round() as usize
    }

    /// The symmetries of the square that map every cell onto a cell holding the same.
    pub fn symmetries(&self) -> Vec<Symmetry> {
        Symmetry::ALL
            .into_iter()
            .filter(|s| (0..self.cells.len()).all(|i| self.cells[self.image(i, *s)] == self.cells[i]))
            .collect()
    }
}

fn name(cell: Cell) -> &'static str {
    match cell {
        Cell::Rod => "fuel rod",
        Cell::GuideTube => "guide tube",
        Cell::InstrumentTube => "instrumentation tube",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PITCH: f64 = 0.0126;

    #[test]
    fn the_standard_17_by_17_lattice_holds_264_rods_24_guide_tubes_and_one_instrumentation_tube() {
        let lattice = SquareLattice::standard(17).expect("built in");
        assert_eq!(lattice.count(Cell::Rod), 264);
        assert_eq!(lattice.count(Cell::GuideTube), 24);
        assert_eq!(lattice.count(Cell::InstrumentTube), 1);
        assert_eq!(lattice.cells_of(Cell::InstrumentTube), vec![8 * 17 + 8]);
        // Its top rows as drawn: guide tubes at columns 5, 8, 11 of row 2 and 3, 13 of row 3.
        let guide = |row: usize| -> Vec<usize> {
            (0..17)
                .filter(|c| lattice.cell(row * 17 + c) == Cell::GuideTube)
                .collect()
        };
        assert_eq!(guide(0), Vec::<usize>::new());
        assert_eq!(guide(2), vec![5, 8, 11]);
        assert_eq!(guide(3), vec![3, 13]);
        assert_eq!(guide(5), vec![2, 5, 8, 11, 14]);
        assert_eq!(guide(8), vec![2, 5, 11, 14]);
        // No guide tube touches another.
        for (a, b, _) in lattice.neighbours() {
            assert!(!(lattice.cell(a) != Cell::Rod && lattice.cell(b) != Cell::Rod));
        }
        assert!(
            SquareLattice::standard(15)
                .unwrap_err()
                .contains("guide-tube positions")
        );
    }

    #[test]
    fn positions_are_at_the_pitch_about_the_axis_and_symmetries_turn_them() {
        let lattice = SquareLattice::standard(17).expect("built in");
        let centre = lattice.position(8 * 17 + 8, PITCH);
        assert!(centre[0].abs() < 1e-15 && centre[1].abs() < 1e-15);
        let corner = lattice.position(0, PITCH);
        assert!((corner[0] + 8.0 * PITCH).abs() < 1e-15 && (corner[1] - 8.0 * PITCH).abs() < 1e-15);
        // Every neighbour pair is one pitch apart along its normal.
        let pairs = lattice.neighbours();
        assert_eq!(pairs.len(), 2 * 17 * 16);
        for (a, b, n) in &pairs {
            let (pa, pb) = (lattice.position(*a, PITCH), lattice.position(*b, PITCH));
            let along = (pb[0] - pa[0]) * n[0] + (pb[1] - pa[1]) * n[1];
            assert!((along - PITCH).abs() < 1e-15, "{a}-{b}");
        }
        // A symmetry's image of a cell sits where the symmetry takes its centre.
        for symmetry in Symmetry::ALL {
            for index in [0, 5, 38, 100, 288] {
                let image = lattice.position(lattice.image(index, symmetry), PITCH);
                let turned = symmetry.apply(lattice.position(index, PITCH));
                assert!((image[0] - turned[0]).abs() < 1e-14 && (image[1] - turned[1]).abs() < 1e-14);
            }
        }
        // The quarter turn four times is the identity, a mirror twice too.
        for index in 0..289 {
            let mut turned = index;
            for _ in 0..4 {
                turned = lattice.image(turned, Symmetry::Turn(1));
            }
            assert_eq!(turned, index);
            assert_eq!(
                lattice.image(
                    lattice.image(index, Symmetry::MirrorDiagonal),
                    Symmetry::MirrorDiagonal
                ),
                index
            );
        }
    }

    #[test]
    fn the_standard_lattice_has_the_eight_symmetries_of_the_square_and_an_odd_one_fewer() {
        let lattice = SquareLattice::standard(17).expect("built in");
        assert_eq!(lattice.symmetries(), Symmetry::ALL.to_vec());
        // One guide tube moved off its place: only the mirror that keeps it is left.
        let mut guide_tubes: Vec<(usize, usize)> = lattice
            .cells_of(Cell::GuideTube)
            .iter()
            .map(|i| lattice.row_column(*i))
            .collect();
        let moved = guide_tubes
            .iter()
            .position(|g| *g == (2, 8))
            .expect("on the axis");
        guide_tubes[moved] = (1, 8);
        let odd = SquareLattice::new(17, &guide_tubes, Some((8, 8))).expect("valid");
        assert_eq!(odd.symmetries(), vec![Symmetry::Turn(0), Symmetry::MirrorX]);
    }

    #[test]
    fn positions_outside_the_lattice_or_given_twice_are_refused_at_their_field() {
        let issues = SquareLattice::new(5, &[(1, 1), (5, 0), (1, 1), (2, 2)], Some((2, 2))).unwrap_err();
        let fields: Vec<&str> = issues.iter().map(|i| i.field.as_str()).collect();
        assert_eq!(fields, ["guide_tubes/1", "guide_tubes/2", "guide_tubes/3"]);
        assert!(issues[0].reason.contains("outside") && issues[1].reason.contains("guide tube"));
        assert!(issues[2].reason.contains("instrumentation tube"));
    }
}
