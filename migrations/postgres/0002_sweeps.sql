-- Sweeps: the PostgreSQL twin of `migrations/0002_sweeps.sql`. One request that
-- expands into many ordinary jobs (its runs), plus the content hash that lets identical
-- runs reuse a successful job's results.

CREATE TABLE sweeps (
    -- Insertion order: the keyset of `GET /sweeps`.
    seq         BIGINT  GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    -- Public sweep id (UUID), used in URLs.
    id          TEXT    NOT NULL UNIQUE,
    process_id  TEXT    NOT NULL,
    -- The normalized sweep definition (JSON text): base inputs, axes, design, samples,
    -- seed, policy.
    definition  TEXT    NOT NULL,
    design      TEXT    NOT NULL CHECK (design IN ('grid', 'monte_carlo', 'latin_hypercube')),
    policy      TEXT    NOT NULL CHECK (policy IN ('continue', 'fail_fast')),
    -- Number of runs (child jobs).
    runs        BIGINT  NOT NULL,
    -- Set by `DELETE /sweeps/{id}`.
    dismissed   BOOLEAN NOT NULL DEFAULT FALSE,
    created_at  BIGINT  NOT NULL,
    updated_at  BIGINT  NOT NULL
);

-- A run of a sweep is an ordinary job that knows its sweep and its run number.
ALTER TABLE jobs ADD COLUMN sweep_id TEXT REFERENCES sweeps (id) ON DELETE SET NULL;
ALTER TABLE jobs ADD COLUMN sweep_run BIGINT;
-- SHA-256 (hex) of process id, canonical inputs and solver version: identical runs
-- reuse the results of a successful job instead of computing again.
ALTER TABLE jobs ADD COLUMN content_hash TEXT;

CREATE INDEX jobs_sweep ON jobs (sweep_id, sweep_run) WHERE sweep_id IS NOT NULL;
CREATE INDEX jobs_reusable ON jobs (content_hash, seq) WHERE status = 'successful';
-- Claiming serves single jobs before sweep runs, each oldest first: one index in claim
-- order, read by `ORDER BY sweep_id IS NOT NULL, seq LIMIT 1 FOR UPDATE SKIP LOCKED`
-- (SQLite uses two partial indexes and a COALESCE of two lookups instead).
DROP INDEX jobs_ready;
CREATE INDEX jobs_ready ON jobs ((sweep_id IS NOT NULL), seq) WHERE status = 'accepted';
