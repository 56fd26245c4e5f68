-- Signals: accelerograms uploaded once (`POST /signals`) and referenced by jobs and
-- sweeps as `{"type": "signal", "id": ...}`. A signal never changes once stored; it
-- belongs to the tenant that uploaded it, and only that tenant sees or uses it.

CREATE TABLE signals (
    -- Insertion order: the keyset of `GET /signals`.
    seq                INTEGER PRIMARY KEY,
    -- Public signal id (UUID), used in URLs and job inputs.
    id                 TEXT    NOT NULL UNIQUE,
    tenant             TEXT    NOT NULL,
    -- Summary of the record (computed once at upload): sample count, first time (s),
    -- duration (s), mean, shortest and longest sample intervals (s), uniform sampling,
    -- peak ground acceleration (m/s²) and its time (s), Arias intensity (m/s).
    samples            INTEGER NOT NULL CHECK (samples >= 2),
    start_time         REAL    NOT NULL,
    duration           REAL    NOT NULL,
    sampling_interval  REAL    NOT NULL,
    shortest_interval  REAL    NOT NULL,
    longest_interval   REAL    NOT NULL,
    uniform            INTEGER NOT NULL CHECK (uniform IN (0, 1)),
    pga                REAL    NOT NULL,
    pga_time           REAL    NOT NULL,
    arias_intensity    REAL    NOT NULL,
    -- The record as a stored history (`src/service/store.rs`): byte-shuffled
    -- little-endian f64 columns `time` then `acceleration`, deflated.
    data               BLOB    NOT NULL,
    created_at         INTEGER NOT NULL
);

-- Listings are per tenant, newest first.
CREATE INDEX signals_tenant ON signals (tenant, seq);
