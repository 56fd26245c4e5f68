-- The job queue and its results: the PostgreSQL twin of `migrations/0001_jobs.sql`.
--
-- Same tables, columns and meaning as the SQLite schema, so that one set of queue
-- statements serves both: times are integer milliseconds since the Unix epoch (UTC)
-- read from the service's clock, every integer is BIGINT (Rust i64), flags are BOOLEAN.

CREATE TABLE jobs (
    -- Insertion order: the claim order (oldest first) and the keyset of `GET /jobs`.
    seq              BIGINT  GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    -- Public job id (UUID), used in URLs.
    id               TEXT    NOT NULL UNIQUE,
    process_id       TEXT    NOT NULL,
    -- The validated `inputs` object of the execution request (JSON text).
    inputs           TEXT    NOT NULL,
    status           TEXT    NOT NULL DEFAULT 'accepted'
                     CHECK (status IN ('accepted', 'running', 'successful', 'failed', 'dismissed')),
    -- Percent done, 0..=100.
    progress         BIGINT  NOT NULL DEFAULT 0 CHECK (progress BETWEEN 0 AND 100),
    message          TEXT,
    created_at       BIGINT  NOT NULL,
    started_at       BIGINT,
    finished_at      BIGINT,
    updated_at       BIGINT  NOT NULL,
    -- Number of times a worker claimed this job.
    attempt          BIGINT  NOT NULL DEFAULT 0,
    -- The worker holding the job while it runs, and until when (ms).
    lease_owner      TEXT,
    lease_expires_at BIGINT,
    cancel_requested BOOLEAN NOT NULL DEFAULT FALSE,
    -- Failed jobs: the RFC 9457 problem document (JSON text).
    error            TEXT,
    -- Successful jobs: the results document (JSON text), with its `outputs` links.
    results          TEXT
);

-- Claiming scans the accepted jobs in insertion order.
CREATE INDEX jobs_ready ON jobs (seq) WHERE status = 'accepted';
-- Recovery scans the running jobs by lease expiry.
CREATE INDEX jobs_leases ON jobs (lease_expires_at) WHERE status = 'running';
-- Listing filters.
CREATE INDEX jobs_status ON jobs (status, seq);
CREATE INDEX jobs_process ON jobs (process_id, seq);
-- Retention deletes finished jobs by age.
CREATE INDEX jobs_finished ON jobs (finished_at) WHERE finished_at IS NOT NULL;

-- Time histories of successful jobs: binary little-endian f64 columns (time first,
-- then each series), concatenated and deflate-compressed.
CREATE TABLE job_histories (
    job_id   TEXT    NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    name     TEXT    NOT NULL,
    -- JSON array of the series names, in column order (without `time`).
    series   TEXT    NOT NULL,
    -- Number of samples (rows).
    samples  BIGINT  NOT NULL,
    data     BYTEA   NOT NULL,
    PRIMARY KEY (job_id, name)
);
-- The data is deflated already: store it out of line without a second compression.
ALTER TABLE job_histories ALTER COLUMN data SET STORAGE EXTERNAL;
