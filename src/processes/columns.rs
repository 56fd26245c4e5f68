//! What each column of a history is: its name (the CSV header, `c12`, `p0`, which
//! scripts index), its unit and what it measures (`contact wall–p0 at 0.18 m`), for the
//! JSON form of a history and its descriptive CSV header (`?header=long`).
//!
//! A process describes its columns from the results document of the run (the contacts'
//! bodies and heights are there), so the histories stored by any version are described.

use serde::Serialize;
use utoipa::ToSchema;

/// One column of a history.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, ToSchema)]
pub struct Column {
    /// The CSV column name (`time`, `c12`, `p0`, `numerical`).
    pub name: String,
    /// Its unit (`s`, `N`, `m`); null when the process does not say.
    pub unit: Option<String>,
    /// What it measures (`contact wall–p0 at 0.18 m`); null when the process does not say.
    pub description: Option<String>,
}

impl Column {
    pub fn new(name: impl Into<String>, unit: &str, description: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: Some(unit.to_owned()),
            description: Some(description.into()),
        }
    }

    /// The time column of every history.
    pub fn time() -> Self {
        Self::new("time", "s", "time from the start of the run")
    }

    /// A column its process does not describe.
    pub fn unknown(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: None,
            description: None,
        }
    }

    /// The cell of a descriptive CSV header: `c12 [N] contact wall–p0 at 0.18 m` (the
    /// name first, so that its first word is the short header's cell).
    pub fn long_header(&self) -> String {
        let mut cell = self.name.clone();
        if let Some(unit) = &self.unit {
            cell.push_str(&format!(" [{unit}]"));
        }
        if let Some(description) = &self.description {
            cell.push(' ');
            cell.push_str(description);
        }
        cell
    }
}

/// What the `_peaks` companion of a history adds to a column's description.
pub const PEAKS: &str = "the extreme (largest magnitude, signed) over each output interval";

/// `description`, with the peaks' qualifier when `output` is a `_peaks` history.
pub fn of_output(output: &str, description: String) -> String {
    match output.ends_with("_peaks") {
        true => format!("{description}: {PEAKS}"),
        false => description,
    }
}

/// A height (m) as the descriptions write it: six significant digits.
pub fn metres(height: f64) -> String {
    format!("{} m", crate::physics::number(height))
}

/// The contact index `k` of a `c<k>` column.
pub fn contact_index(name: &str) -> Option<usize> {
    name.strip_prefix('c')?.parse().ok()
}

/// The pin and where of a `p<pin>` column (`at its tip`), or a `p<pin>@<height>` one,
/// with the axis letter of a hexagonal bundle's `p<pin>x` columns when `axes`.
pub fn deflection(name: &str, axes: bool) -> Option<(usize, Option<char>, String)> {
    let (line, at) = match name.strip_prefix('p')?.split_once('@') {
        Some((line, height)) => (line, metres(height.parse().ok()?)),
        None => (name.strip_prefix('p')?, "its tip".to_owned()),
    };
    let (pin, axis) = match axes {
        true => {
            let axis = line.chars().last().filter(|a| matches!(a, 'x' | 'y'))?;
            (&line[..line.len() - 1], Some(axis))
        }
        false => (line, None),
    };
    Some((pin.parse().ok()?, axis, at))
}

/// A row's body as the results write it (`"wall"` or a pin number): `wall`, `p3`.
pub fn body(value: &serde_json::Value) -> Option<String> {
    match value {
        serde_json::Value::String(wall) => Some(wall.clone()),
        serde_json::Value::Number(pin) => Some(format!("p{pin}")),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_long_header_starts_with_the_short_name() {
        let column = Column::new("c12", "N", "contact wall–p0 at 0.18 m");
        assert_eq!(column.long_header(), "c12 [N] contact wall–p0 at 0.18 m");
        assert_eq!(Column::unknown("x").long_header(), "x");
        assert_eq!(of_output("contact_forces", "a".into()), "a");
        assert!(of_output("contact_forces_peaks", "a".into()).starts_with("a: the extreme"));
    }
}
