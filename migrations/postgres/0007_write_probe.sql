-- The readiness probe's row: the PostgreSQL twin of `migrations/0007_write_probe.sql`.

CREATE TABLE write_probe (
    id        INTEGER PRIMARY KEY CHECK (id = 1),
    -- ms since the Unix epoch.
    probed_at BIGINT NOT NULL
);
