-- The readiness probe's row (`GET /readyz`): rewritten in a transaction on every probe,
-- to learn whether the database takes a write (a full disk refuses it).

CREATE TABLE write_probe (
    id        INTEGER PRIMARY KEY CHECK (id = 1),
    -- ms since the Unix epoch.
    probed_at INTEGER NOT NULL
);
