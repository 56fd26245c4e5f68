//! Per-contact and per-pin aggregates of a sweep: for each grid cell of the list axes,
//! each entry k of the runs' `contacts` (or `pins`) list and each of its figures (the
//! entry's numeric members, dotted as in the contact table: `max_force`,
//! `impact_statistics.impacts`, `utilisation`, `bending.stress`), the
//! [`FigureStatistics`] over the successful runs. The same code serves the row
//! (`bundle-dynamics`) and the hexagonal bundle: both list their contacts and pins.
//!
//! Fed one results document at a time ([`ItemValues::add`]): the service reads the runs'
//! documents page by page and drops each once its figures are kept. What is kept is the
//! values themselves (exact quantiles and order statistics need them all): 8 bytes per
//! value, at most `ceiling` values ([`DEFAULT_CEILING`]: 64 MiB), refused beyond it
//! with the count, so that a request names fewer figures.

use std::collections::HashMap;

use serde_json::{Map, Value};

use super::figures::{BoundRequest, FigureStatistics, StatisticsTable, statistics_columns, statistics_row};
use super::table::is_seed;
use crate::processes::metrics::flatten_scalars;

/// The most values kept for one request: 8 Mi values, 64 MiB.
pub const DEFAULT_CEILING: usize = 8 * 1024 * 1024;

/// Which list of the results documents.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemList {
    Contacts,
    Pins,
}

impl ItemList {
    /// The member of a results document (`contacts`, `pins`).
    pub fn member(self) -> &'static str {
        match self {
            ItemList::Contacts => "contacts",
            ItemList::Pins => "pins",
        }
    }

    /// The column naming an entry by its index (`contact`, `pin`): the k of `c<k>`, the
    /// p of `p<p>`.
    pub fn key(self) -> &'static str {
        match self {
            ItemList::Contacts => "contact",
            ItemList::Pins => "pin",
        }
    }
}

/// Whether an entry's member names a body or a place in the model (which pin, ring,
/// level, wall or flat) rather than a quantity: left out, like seeds.
pub fn names_a_body(member: &str) -> bool {
    matches!(
        member.rsplit('.').next(),
        Some(
            "pin"
                | "ring"
                | "level"
                | "left"
                | "right"
                | "wire_pin"
                | "touched_pin"
                | "touched_flat"
                | "flat"
        )
    ) || is_seed(member)
}

/// Too many values for one request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TooManyValues {
    /// Values kept when the ceiling was passed.
    pub values: usize,
    pub ceiling: usize,
    /// The figures being kept (named in the refusal, to choose from).
    pub figures: Vec<String>,
}

/// The values of one grid cell: per item, per figure (index into `figures`).
#[derive(Debug, Default)]
struct CellValues {
    cell: Map<String, Value>,
    runs: usize,
    values: Vec<Vec<Vec<f64>>>,
}

/// The accumulated figures of a sweep's runs.
#[derive(Debug)]
pub struct ItemValues {
    list: ItemList,
    list_axes: Vec<String>,
    /// The figures asked for (`None`: every figure).
    wanted: Option<Vec<String>>,
    ceiling: usize,
    /// Every figure kept, in order of first appearance, and its index.
    figures: Vec<String>,
    index: HashMap<String, usize>,
    /// Every figure seen (kept or not), for the refusal of an unknown one.
    seen: Vec<String>,
    cells: Vec<CellValues>,
    kept: usize,
}

impl ItemValues {
    /// Nothing yet, for the entries of `list`, grouped by `list_axes`; only the figures
    /// `wanted` when given.
    pub fn new(list: ItemList, list_axes: Vec<String>, wanted: Option<Vec<String>>, ceiling: usize) -> Self {
        Self {
            list,
            list_axes,
            wanted,
            ceiling,
            figures: Vec::new(),
            index: HashMap::new(),
            seen: Vec::new(),
            cells: Vec::new(),
            kept: 0,
        }
    }

    /// Adds the figures of one successful run: its `inputs` (the cell's axis values are
    /// read there) and its results `document`.
    pub fn add(&mut self, inputs: &Value, document: &Value) -> Result<(), TooManyValues> {
        let cell: Map<String, Value> = self
            .list_axes
            .iter()
            .map(|p| (p.clone(), inputs.pointer(p).cloned().unwrap_or(Value::Null)))
            .collect();
        let at = match self.cells.iter().position(|c| c.cell == cell) {
            Some(at) => at,
            None => {
                self.cells.push(CellValues {
                    cell,
                    ..CellValues::default()
                });
                self.cells.len() - 1
            }
        };
        self.cells[at].runs += 1;
        let Some(entries) = document[self.list.member()].as_array() else {
            return Ok(());
        };
        for (item, entry) in entries.iter().enumerate() {
            for (name, value) in flatten_scalars(entry) {
                let Some(x) = value.as_f64().filter(|x| x.is_finite()) else {
                    continue;
                };
                if names_a_body(&name) {
                    continue;
                }
                let Some(figure) = self.figure_index(name) else {
                    continue;
                };
                let cell = &mut self.cells[at];
                if cell.values.len() <= item {
                    cell.values.resize_with(item + 1, Vec::new);
                }
                let slots = &mut cell.values[item];
                if slots.len() <= figure {
                    slots.resize_with(figure + 1, Vec::new);
                }
                slots[figure].push(x);
                self.kept += 1;
                if self.kept > self.ceiling {
                    return Err(TooManyValues {
                        values: self.kept,
                        ceiling: self.ceiling,
                        figures: self.figures.clone(),
                    });
                }
            }
        }
        Ok(())
    }

    /// The index of figure `name` if it is kept, registering it on first sight.
    fn figure_index(&mut self, name: String) -> Option<usize> {
        if let Some(&at) = self.index.get(&name) {
            return Some(at);
        }
        if !self.seen.contains(&name) {
            self.seen.push(name.clone());
        }
        if self.wanted.as_ref().is_some_and(|wanted| !wanted.contains(&name)) {
            return None;
        }
        self.figures.push(name.clone());
        self.index.insert(name, self.figures.len() - 1);
        Some(self.figures.len() - 1)
    }

    /// The figures asked for that no run had: (the unknown ones, every figure seen).
    pub fn unknown_figures(&self) -> Option<(Vec<String>, Vec<String>)> {
        let wanted = self.wanted.as_ref()?;
        let unknown: Vec<String> = wanted
            .iter()
            .filter(|w| !self.index.contains_key(*w))
            .cloned()
            .collect();
        (!unknown.is_empty() && !self.cells.is_empty()).then(|| (unknown, self.seen.clone()))
    }

    /// The table: one row per cell, item and figure with a value, cells in order of
    /// first appearance, items by index, figures in order of first appearance.
    pub fn table(&self, request: BoundRequest) -> StatisticsTable {
        let key = self.list.key();
        let mut rows = Vec::new();
        for cell in &self.cells {
            for (item, slots) in cell.values.iter().enumerate() {
                for (figure, values) in slots.iter().enumerate() {
                    if let Some(statistics) = FigureStatistics::of(values, request) {
                        rows.push(statistics_row(
                            &cell.cell,
                            Some((key, item)),
                            &self.figures[figure],
                            cell.runs,
                            &statistics,
                        ));
                    }
                }
            }
        }
        StatisticsTable {
            columns: statistics_columns(&self.list_axes, Some(key)),
            rows,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn document(forces: &[f64]) -> Value {
        json!({"contacts": forces.iter().enumerate().map(|(k, f)| json!({
            "left": if k == 0 { json!("wall") } else { json!(k - 1) }, "right": k,
            "max_force": f, "impact_statistics": {"impacts": 2 * k}, "utilisation": null
        })).collect::<Vec<_>>()})
    }

    /// Each contact's figures over the runs, by cell of the list axis; bodies and nulls
    /// left out.
    #[test]
    fn each_contact_is_summarised_over_the_runs_of_its_cell() {
        let mut values = ItemValues::new(ItemList::Contacts, vec!["/rk".into()], None, DEFAULT_CEILING);
        for (rk, forces) in [(1, [1.0, 4.0]), (1, [3.0, 2.0]), (2, [10.0, 20.0])] {
            values.add(&json!({"rk": rk}), &document(&forces)).unwrap();
        }
        let table = values.table(BoundRequest::default());
        assert_eq!(table.columns[..3], ["/rk", "contact", "figure"]);
        let row = |rk: i64, contact: usize, figure: &str| {
            table
                .rows
                .iter()
                .find(|r| r["/rk"] == rk && r["contact"] == contact && r["figure"] == figure)
                .unwrap_or_else(|| panic!("{rk} {contact} {figure} in {:?}", table.rows))
        };
        assert_eq!(row(1, 1, "max_force")["mean"], 3.0);
        assert_eq!(row(1, 1, "max_force")["max"], 4.0);
        assert_eq!(row(1, 0, "max_force")["count"], 2);
        assert_eq!(row(2, 0, "max_force")["runs"], 1);
        assert_eq!(row(2, 1, "impact_statistics.impacts")["mean"], 2.0);
        assert!(
            table
                .rows
                .iter()
                .all(|r| !["left", "right", "utilisation"].contains(&r["figure"].as_str().unwrap())),
            "no bodies, no null figures: {:?}",
            table.rows
        );
    }

    #[test]
    fn the_ceiling_and_unknown_figures_are_reported() {
        let mut values = ItemValues::new(ItemList::Contacts, vec![], None, 3);
        assert_eq!(values.add(&json!({}), &document(&[1.0])), Ok(()));
        let refused = values.add(&json!({}), &document(&[1.0])).unwrap_err();
        assert_eq!((refused.values, refused.ceiling), (4, 3));
        let mut values = ItemValues::new(
            ItemList::Contacts,
            vec![],
            Some(vec!["max_force".into(), "nothing".into()]),
            DEFAULT_CEILING,
        );
        values.add(&json!({}), &document(&[1.0, 2.0])).unwrap();
        let (unknown, seen) = values.unknown_figures().unwrap();
        assert_eq!(unknown, ["nothing"]);
        assert!(seen.contains(&"impact_statistics.impacts".to_owned()), "{seen:?}");
        assert_eq!(values.table(BoundRequest::default()).rows.len(), 2);
    }
}
