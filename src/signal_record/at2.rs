//! PEER AT2 files (the NGA strong-motion databases): three title lines, the third naming
//! the quantity and unit (`ACCELERATION TIME SERIES IN UNITS OF G`), a fourth giving the
//! sample count and interval, in either of the two layouts the databases have used
//! (`NPTS=  3908, DT=   .0100 SEC` in NGA-West2, `3908    0.0100    NPTS, DT` before),
//! then the accelerations in g, several to a line, at k·DT from 0.

use super::{RecordError, invalid};
use crate::physics::loads::Table;
use crate::processes::FieldError;

/// Title lines before the count line.
const TITLE_LINES: usize = 3;

/// Whether `text` is an AT2 file: its first line starts with `PEER`, or its fourth
/// names `NPTS`.
pub fn recognises(text: &str) -> bool {
    let mut lines = text.lines();
    let first = lines.next().unwrap_or_default().trim_start().to_ascii_uppercase();
    first.starts_with("PEER")
        || lines
            .nth(2)
            .is_some_and(|line| line.to_ascii_uppercase().contains("NPTS"))
}

/// The count and interval of the fourth line.
fn count_and_interval(line: &str) -> Option<(usize, f64)> {
    let upper = line.to_ascii_uppercase();
    let number_after = |key: &str| -> Option<&str> {
        let start = upper.find(key)? + key.len();
        let rest = line[start..].trim_start_matches([' ', '=']);
        rest.split([' ', ',']).find(|s| !s.is_empty())
    };
    let (count, interval) = if upper.contains("NPTS=") || upper.contains("NPTS =") {
        (number_after("NPTS")?, number_after("DT")?)
    } else {
        let mut fields = line.split([' ', ',', '\t']).filter(|s| !s.is_empty());
        (fields.next()?, fields.next()?)
    };
    let count = count
        .parse::<f64>()
        .ok()
        .filter(|c| c.fract() == 0.0 && *c >= 0.0)? as usize;
    let interval = interval
        .parse::<f64>()
        .ok()
        .filter(|dt| dt.is_finite() && *dt > 0.0)?;
    Some((count, interval))
}

/// The record (accelerations still in g) and the line of each sample.
pub fn parse(text: &str) -> Result<(Table, Vec<usize>), RecordError> {
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() <= TITLE_LINES {
        return Err(invalid(
            "",
            "a PEER AT2 file has three title lines, a line with NPTS and DT, then the samples",
        ));
    }
    let quantity = lines[2].to_ascii_uppercase();
    if !quantity.contains("ACCELERATION") {
        return Err(invalid(
            "",
            format!(
                "line 3: `{}` is not an acceleration record (a VT2 or DT2 file holds velocities or \
                 displacements)",
                lines[2].trim()
            ),
        ));
    }
    if !quantity
        .split(|c: char| !c.is_ascii_alphanumeric())
        .any(|word| word == "G")
    {
        return Err(invalid(
            "/unit",
            format!("line 3: `{}` does not give the unit g", lines[2].trim()),
        ));
    }
    let (count, interval) = count_and_interval(lines[3]).ok_or_else(|| {
        invalid(
            "/dt",
            format!(
                "line 4: `{}` gives no sample count and positive interval (`NPTS= 3908, DT= .0100 SEC`)",
                lines[3].trim()
            ),
        )
    })?;
    let mut values = Vec::with_capacity(count);
    let mut sample_lines = Vec::with_capacity(count);
    let mut errors = Vec::new();
    for (index, raw) in lines.iter().enumerate().skip(TITLE_LINES + 1) {
        for field in raw.split_whitespace() {
            let sample = values.len();
            match field.parse::<f64>() {
                Ok(value) if value.is_finite() => values.push(value),
                _ => {
                    errors.push(FieldError::new(
                        format!("/acceleration/{sample}"),
                        format!(
                            "line {}: `{field}` is not a finite number (acceleration)",
                            index + 1
                        ),
                    ));
                    values.push(0.0);
                }
            }
            sample_lines.push(index + 1);
        }
        if errors.len() >= super::MAX_REPORTED {
            break;
        }
    }
    if !errors.is_empty() {
        return Err(RecordError::Invalid(errors));
    }
    if values.len() != count {
        return Err(invalid(
            "/acceleration",
            format!(
                "the file holds {} samples where its fourth line announces NPTS = {count}",
                values.len()
            ),
        ));
    }
    let time = (0..values.len()).map(|k| k as f64 * interval).collect();
    Ok((Table { time, values }, sample_lines))
}
