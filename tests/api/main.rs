//! Service tests: each starts a real server on an ephemeral port with a fresh database
//! (SQLite, and for the queue's core flows PostgreSQL too: `<module>::postgres::<test>`)
//! and talks to it over HTTP, with a small test process (`counting`).

mod counting;
mod devtools;
mod helpers;
mod postgres;
mod skip;

mod auto_basis;
mod callbacks;
mod capabilities;
mod contact_laws;
mod cors;
mod csv;
mod dashboard;
mod dashboard_hex;
mod dashboard_plots;
mod database;
mod dismissal;
mod earthquakes;
mod errors;
mod execution;
mod formats;
mod full_disk;
mod hex_loads;
mod idempotency;
mod impacts;
mod kinds;
mod limits;
mod listing;
mod load;
mod margins;
mod negotiation;
mod physics;
mod quality;
mod recovery;
mod report;
mod response_spectra;
mod responsiveness;
mod resultants;
mod results;
mod robustness;
mod scale_out;
mod schema_check;
mod shutdown;
mod signals;
mod spectra;
mod sweep_statistics;
mod sweeps;
mod tenants;
mod threads;
mod traceability;
mod units;
mod warnings;
