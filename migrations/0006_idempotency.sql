-- Idempotency keys (`Idempotency-Key` on job, sweep and signal creation): per tenant,
-- a key names the one resource its first request created, with a hash of that request
-- (route, process, body bytes). A retry with the same key and request gets the same
-- resource back; the same key with another request is refused (422). The key row is
-- written in the transaction that creates its resource and deleted with it (the
-- foreign keys cascade), so a key lives exactly as long as its resource.

CREATE TABLE idempotency_keys (
    tenant          TEXT    NOT NULL,
    idempotency_key TEXT    NOT NULL,
    -- What the key created: `job`, `sweep` or `signal` (the one id column set).
    kind            TEXT    NOT NULL CHECK (kind IN ('job', 'sweep', 'signal')),
    -- SHA-256 (hex) of the request the key was first used with.
    request_hash    TEXT    NOT NULL,
    job_id          TEXT    REFERENCES jobs (id) ON DELETE CASCADE,
    sweep_id        TEXT    REFERENCES sweeps (id) ON DELETE CASCADE,
    signal_id       TEXT    REFERENCES signals (id) ON DELETE CASCADE,
    -- ms since the Unix epoch.
    created_at      INTEGER NOT NULL,
    PRIMARY KEY (tenant, idempotency_key),
    CHECK ((job_id IS NOT NULL) + (sweep_id IS NOT NULL) + (signal_id IS NOT NULL) = 1)
);

-- The cascades look keys up by resource.
CREATE INDEX idempotency_keys_job ON idempotency_keys (job_id) WHERE job_id IS NOT NULL;
CREATE INDEX idempotency_keys_sweep ON idempotency_keys (sweep_id) WHERE sweep_id IS NOT NULL;
CREATE INDEX idempotency_keys_signal ON idempotency_keys (signal_id) WHERE signal_id IS NOT NULL;
