-- The job queue and its results.
--
-- Times are integer milliseconds since the Unix epoch (UTC), so that the queue's
-- clock can be injected in tests and comparisons stay exact.

CREATE TABLE jobs (
    -- Insertion order: the claim order (oldest first) and the keyset of `GET /jobs`.
    seq              INTEGER PRIMARY KEY,
    -- Public job id (UUID), used in URLs.
    id               TEXT    NOT NULL UNIQUE,
    process_id       TEXT    NOT NULL,
    -- The validated `inputs` object of the execution request (JSON text).
    inputs           TEXT    NOT NULL,
    status           TEXT    NOT NULL DEFAULT 'accepted'
                     CHECK (status IN ('accepted', 'running', 'successful', 'failed', 'dismissed')),
    -- Percent done, 0..=100.
    progress         INTEGER NOT NULL DEFAULT 0 CHECK (progress BETWEEN 0 AND 100),
    message          TEXT,
    created_at       INTEGER NOT NULL,
    started_at       INTEGER,
    finished_at      INTEGER,
    updated_at       INTEGER NOT NULL,
    -- Number of times a worker claimed this job.
    attempt          INTEGER NOT NULL DEFAULT 0,
    -- The worker holding the job while it runs, and until when (ms).
    lease_owner      TEXT,
    lease_expires_at INTEGER,
    cancel_requested INTEGER NOT NULL DEFAULT 0 CHECK (cancel_requested IN (0, 1)),
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
    samples  INTEGER NOT NULL,
    data     BLOB    NOT NULL,
    PRIMARY KEY (job_id, name)
);
