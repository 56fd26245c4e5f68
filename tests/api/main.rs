//! Service tests: each starts a real server on an ephemeral port with a fresh SQLite
//! database and talks to it over HTTP, with a small test process (`counting`).

mod counting;
mod helpers;

mod capabilities;
mod dashboard;
mod database;
mod dismissal;
mod errors;
mod execution;
mod limits;
mod listing;
mod load;
mod negotiation;
mod physics;
mod recovery;
mod responsiveness;
mod results;
mod robustness;
mod spectra;
mod sweeps;
mod tenants;
