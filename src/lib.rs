//! chocmodal: modal multi-contact dynamics of slender beam bundles.
//!
//! Data flows one way: HTTP/CLI → validated process inputs → queue → worker →
//! physics → results store → HTTP. The physics core is pure (no IO, no async).

/// Labels and a note attached to a job, checked (a leaf above the processes' errors).
pub mod annotations;
/// A run's calculation note: one printable HTML page (CLI and HTTP, one writer).
pub mod calculation_note;
/// The `chocmodal` command line (serve, run).
pub mod cli;
/// The per-contact statistics table of a results document (CLI and HTTP, one writer).
pub mod contact_table;
/// CSV as every output writes it: one number format, one quoting rule (a leaf).
pub mod csv_format;
/// Request bodies as JSON values, with pointer-bearing errors (numbers out of range).
pub mod json_body;
/// Pure numerics: beams, modal bases, contacts, explicit integration, reference solution.
/// Its own crate (`crates/physics`), so its purity is the compiler's to enforce.
pub use chocmodal_physics as physics;
/// JSON pointers of serde paths (a leaf: nothing else in the crate is imported).
pub mod pointer;
/// RFC 9457 problem details shared by the HTTP API and the CLI.
pub mod problem;
/// One module per process: JSON inputs (validated) → physics → results document + histories.
pub mod processes;
/// Solver version, build and inputs hash stamped on every results document (a leaf).
pub mod provenance;
/// A results document's quality verdict in the words users see (job message, CLI, sweeps).
pub mod quality_note;
/// The HTTP service: OGC API – Processes, SQLite job queue, workers, results store.
pub mod service;
/// Accelerograms as clients send them (CSV or JSON) into checked records, and back.
pub mod signal_record;
/// Sweeps: expansion of axes into runs, results tables and aggregates (pure).
pub mod sweep;

#[cfg(test)]
mod architecture_tests;
