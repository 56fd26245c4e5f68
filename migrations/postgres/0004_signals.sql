-- Signals: the PostgreSQL twin of `migrations/0004_signals.sql`. Accelerograms
-- uploaded once (`POST /signals`) and referenced by jobs and sweeps as
-- `{"type": "signal", "id": ...}`. A signal never changes once stored; it belongs to
-- the tenant that uploaded it, and only that tenant sees or uses it.

CREATE TABLE signals (
    -- Insertion order: the keyset of `GET /signals`.
    seq                BIGINT  GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    -- Public signal id (UUID), used in URLs and job inputs.
    id                 TEXT    NOT NULL UNIQUE,
    tenant             TEXT    NOT NULL,
    -- Summary of the record (computed once at upload): sample count, first time (s),
    -- duration (s), mean, shortest and longest sample intervals (s), uniform sampling,
    -- peak ground acceleration (m/s²) and its time (s), Arias intensity (m/s).
    samples            BIGINT  NOT NULL CHECK (samples >= 2),
    start_time         DOUBLE PRECISION NOT NULL,
    duration           DOUBLE PRECISION NOT NULL,
    sampling_interval  DOUBLE PRECISION NOT NULL,
    shortest_interval  DOUBLE PRECISION NOT NULL,
    longest_interval   DOUBLE PRECISION NOT NULL,
    uniform            BOOLEAN NOT NULL,
    pga                DOUBLE PRECISION NOT NULL,
    pga_time           DOUBLE PRECISION NOT NULL,
    arias_intensity    DOUBLE PRECISION NOT NULL,
    -- The record as a stored history (`src/service/store.rs`): byte-shuffled
    -- little-endian f64 columns `time` then `acceleration`, deflated.
    data               BYTEA   NOT NULL,
    created_at         BIGINT  NOT NULL
);
-- The data is deflated already: store it out of line without a second compression.
ALTER TABLE signals ALTER COLUMN data SET STORAGE EXTERNAL;

-- Listings are per tenant, newest first.
CREATE INDEX signals_tenant ON signals (tenant, seq);
