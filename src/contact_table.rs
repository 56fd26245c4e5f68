//! The per-contact statistics table of a results document: one row per entry of its
//! `contacts` list, in input order, with `contact` (the index k of the history column
//! `c<k>`) then every scalar of the entry, dotted (its description, statistics, impact
//! statistics, friction and wear: `left`, `max_force`, `impact_statistics.impacts`).
//!
//! One writer for every place the table goes: `chocmodal run --out DIR` writes
//! `DIR/contacts.csv`, and `GET /jobs/{jobId}/results/contacts` serves it as CSV or JSON
//! (the same columns, the same values).

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

impl ContactTable {
    /// The table of a results document; `None` for a process without a contact list.
    pub fn of(document: &Value) -> Option<ContactTable> {
        let entries = document["contacts"].as_array().filter(|c| !c.is_empty())?;
        let mut columns = vec!["contact".to_owned()];
        let contacts = entries
            .iter()
            .enumerate()
            .map(|(k, entry)| {
                let mut record = Map::new();
                record.insert("contact".into(), Value::from(k));
                for (name, value) in flatten_scalars(entry) {
                    if !columns.contains(&name) {
                        columns.push(name.clone());
                    }
                    record.insert(name, value);
                }
                record
            })
            .collect();
        Some(ContactTable { columns, contacts })
    }

    /// CSV: the columns as header, a row per contact; a member a contact lacks is an
    /// empty cell. Numbers and quoting as [`csv_format`] writes them.
    pub fn to_csv(&self) -> String {
        let header: Vec<String> = self
            .columns
            .iter()
            .map(|c| csv_format::quote(c).into_owned())
            .collect();
        let mut out = header.join(",");
        out.push('\n');
        for record in &self.contacts {
            let cells: Vec<String> = self
                .columns
                .iter()
                .map(|name| record.get(name).map_or_else(String::new, csv_format::cell))
                .collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        out
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
    }
}
