-- Idempotency keys: the PostgreSQL twin of `migrations/0006_idempotency.sql`. Per
-- tenant, a key names the one resource (job, sweep or signal) its first request
-- created, with a hash of that request; written in the transaction that creates the
-- resource, deleted with it (the foreign keys cascade).

CREATE TABLE idempotency_keys (
    tenant          TEXT   NOT NULL,
    idempotency_key TEXT   NOT NULL,
    kind            TEXT   NOT NULL CHECK (kind IN ('job', 'sweep', 'signal')),
    -- SHA-256 (hex) of the request the key was first used with.
    request_hash    TEXT   NOT NULL,
    job_id          TEXT   REFERENCES jobs (id) ON DELETE CASCADE,
    sweep_id        TEXT   REFERENCES sweeps (id) ON DELETE CASCADE,
    signal_id       TEXT   REFERENCES signals (id) ON DELETE CASCADE,
    -- ms since the Unix epoch.
    created_at      BIGINT NOT NULL,
    PRIMARY KEY (tenant, idempotency_key),
    CHECK (num_nonnulls(job_id, sweep_id, signal_id) = 1)
);

CREATE INDEX idempotency_keys_job ON idempotency_keys (job_id) WHERE job_id IS NOT NULL;
CREATE INDEX idempotency_keys_sweep ON idempotency_keys (sweep_id) WHERE sweep_id IS NOT NULL;
CREATE INDEX idempotency_keys_signal ON idempotency_keys (signal_id) WHERE signal_id IS NOT NULL;
