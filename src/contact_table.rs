//! The tables of a results document, one row per entry of one of its lists:
//! - [`ContactTable`]: the per-contact statistics, one row per entry of `contacts` in input
//!   order, with `contact` (the index k of the history column `c<k>`) then every scalar
//!   of the entry, dotted (its description, statistics, impact statistics, friction and
//!   wear: `left`, `max_force`, `impact_statistics.impacts`);
//! - [`PinTable`]: one row per entry of `pins` (every scalar: deflections, bending stress
//!   and strain, utilisations, the largest resultant contact force);
//! - [`ResultantTable`]: one row per pin and contact height, `pin` then the scalars of
//!   each entry of the pin's `resultant_forces`.
//!
//! One writer for every place a table goes: `chocmodal run --out DIR` writes
//! `DIR/contacts.csv`, `DIR/pins.csv` and `DIR/resultants.csv`, and `GET
//! /jobs/{jobId}/results/contacts` (`pins`, `resultants`) serves each as CSV or JSON (the
//! same columns, the same values).

use serde::Serialize;
use serde_json::{Map, Value};

use crate::csv_format;
use crate::processes::metrics::flatten_scalars;

/// The table: its columns and one flat record per contact.
#[derive(Debug, Clone, PartialEq, Serialize, utoipa::ToSchema)]
pub struct ContactTable {
    /// Column names: `contact`, then every member some contact has, in order of first
    /// appearance (a contact without one, e.g. a family's friction, has none of it).
    pub columns: Vec<String>,
    /// One record per contact, `{"contact": 0, "left": "wall", "max_force": 12.5, ...}`:
    /// units as in the results document (N, s, N·s, m).
    #[schema(value_type = Vec<Object>)]
    pub contacts: Vec<Map<String, Value>>,
}

/// The per-pin table: its columns and one flat record per pin.
#[derive(Debug, Clone, PartialEq, Serialize, utoipa::ToSchema)]
pub struct PinTable {
    /// Column names: `pin`, then every scalar member some pin has, dotted
    /// (`bending.stress`, `max_resultant_force.max_force`), in order of first appearance.
    pub columns: Vec<String>,
    /// One record per pin, units as in the results document (m, s, N·m, Pa, N).
    #[schema(value_type = Vec<Object>)]
    pub pins: Vec<Map<String, Value>>,
}

/// The resultant contact forces: one flat record per pin and contact height.
#[derive(Debug, Clone, PartialEq, Serialize, utoipa::ToSchema)]
pub struct ResultantTable {
    /// Column names: `pin`, `height` (m), `contacts`, `max_force` (N), `time` (s).
    pub columns: Vec<String>,
    /// One record per pin and height where a contact acts on it, by pin then height.
    #[schema(value_type = Vec<Object>)]
    pub resultants: Vec<Map<String, Value>>,
}

/// Columns (the union of the records' names, first seen first) and records.
type Rows = (Vec<String>, Vec<Map<String, Value>>);

/// The rows of `records`, each a list of (name, scalar).
fn rows(records: impl Iterator<Item = Vec<(String, Value)>>) -> Rows {
    let mut columns: Vec<String> = Vec::new();
    let rows = records
        .map(|pairs| {
            let mut record = Map::new();
            for (name, value) in pairs {
                if !columns.contains(&name) {
                    columns.push(name.clone());
                }
                record.insert(name, value);
            }
            record
        })
        .collect();
    (columns, rows)
}

/// The non-empty list `name` of a results document.
fn list<'a>(document: &'a Value, name: &str) -> Option<&'a Vec<Value>> {
    document[name].as_array().filter(|entries| !entries.is_empty())
}

impl ContactTable {
    /// The table of a results document; `None` for a process without a contact list.
    pub fn of(document: &Value) -> Option<ContactTable> {
        let entries = list(document, "contacts")?;
        let records = entries.iter().enumerate().map(|(k, entry)| {
            let mut pairs = vec![("contact".to_owned(), Value::from(k))];
            pairs.extend(flatten_scalars(entry));
            pairs
        });
        let (columns, contacts) = rows(records);
        Some(ContactTable { columns, contacts })
    }

    /// The table as CSV ([`csv_format::records`]).
    pub fn to_csv(&self) -> String {
        csv_format::records(&self.columns, &self.contacts)
    }
}

impl PinTable {
    /// The table of a results document; `None` for a process without a pin list.
    pub fn of(document: &Value) -> Option<PinTable> {
        let records = list(document, "pins")?.iter().enumerate().map(|(p, entry)| {
            // `pin` first, as `contact` leads the contact table.
            let pin = entry.get("pin").cloned().unwrap_or_else(|| Value::from(p));
            let mut pairs = vec![("pin".to_owned(), pin)];
            pairs.extend(
                flatten_scalars(entry)
                    .into_iter()
                    .filter(|(name, _)| name != "pin"),
            );
            pairs
        });
        let (columns, pins) = rows(records);
        Some(PinTable { columns, pins })
    }

    /// The table as CSV ([`csv_format::records`]).
    pub fn to_csv(&self) -> String {
        csv_format::records(&self.columns, &self.pins)
    }
}

impl ResultantTable {
    /// The table of a results document; `None` for a process whose pins report no
    /// resultant contact forces.
    pub fn of(document: &Value) -> Option<ResultantTable> {
        let pins = list(document, "pins")?;
        let records = pins.iter().flat_map(|pin| {
            let entries = pin["resultant_forces"].as_array().map_or(&[][..], Vec::as_slice);
            entries.iter().map(|entry| {
                let mut pairs = vec![("pin".to_owned(), pin["pin"].clone())];
                pairs.extend(flatten_scalars(entry));
                pairs
            })
        });
        let (columns, resultants) = rows(records);
        (!resultants.is_empty()).then_some(ResultantTable { columns, resultants })
    }

    /// The table as CSV ([`csv_format::records`]).
    pub fn to_csv(&self) -> String {
        csv_format::records(&self.columns, &self.resultants)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn one_row_per_contact_with_the_union_of_their_members_and_empty_cells_for_the_missing() {
        let document = json!({"contacts": [
            {"left": "wall", "right": 0, "max_force": 2.5, "impact_statistics": {"impacts": 3}},
            {"left": 0, "right": "wall", "max_force": 0.1, "wear": {"work": 1e-7}, "spectrum": [1, 2]}
        ]});
        let table = ContactTable::of(&document).unwrap();
        // Members in the order the document's maps give them (by name), first seen first.
        assert_eq!(
            table.columns,
            [
                "contact",
                "impact_statistics.impacts",
                "left",
                "max_force",
                "right",
                "wear.work"
            ]
        );
        assert_eq!(table.contacts[1]["contact"], json!(1));
        assert_eq!(
            table.to_csv(),
            "contact,impact_statistics.impacts,left,max_force,right,wear.work\n\
             0,3,wall,2.5,0,\n\
             1,,0,0.1,wall,1e-7\n"
        );
    }

    #[test]
    fn a_document_without_contacts_has_no_table() {
        assert_eq!(ContactTable::of(&json!({"numerical": {"impacts": 3}})), None);
        assert_eq!(ContactTable::of(&json!({"contacts": []})), None);
        assert_eq!(PinTable::of(&json!({"numerical": {"impacts": 3}})), None);
        assert_eq!(
            ResultantTable::of(&json!({"pins": [{"pin": 0, "resultant_forces": []}]})),
            None
        );
    }

    #[test]
    fn one_row_per_pin_and_one_per_pin_and_height_for_the_resultants() {
        let document = json!({"pins": [
            {"pin": 0, "bending": {"stress": 200}, "resultant_forces": [
                {"height": 0.5, "contacts": 2, "max_force": 3.5, "time": 0.01},
                {"height": 1.25, "contacts": 1, "max_force": 4.5, "time": 0.02}
            ]},
            {"pin": 1, "bending": {"stress": 100}, "resultant_forces": [
                {"height": 1.25, "contacts": 1, "max_force": 0.5, "time": 0.03}
            ]}
        ]});
        let pins = PinTable::of(&document).unwrap();
        // The per-height list is an array: not a column of the pin table.
        assert_eq!(pins.columns, ["pin", "bending.stress"]);
        assert_eq!(pins.to_csv(), "pin,bending.stress\n0,200\n1,100\n");
        let resultants = ResultantTable::of(&document).unwrap();
        assert_eq!(
            resultants.columns,
            ["pin", "contacts", "height", "max_force", "time"]
        );
        assert_eq!(
            resultants.to_csv(),
            "pin,contacts,height,max_force,time\n0,2,0.5,3.5,0.01\n0,1,1.25,4.5,0.02\n1,1,1.25,0.5,0.03\n"
        );
    }
}
