-- Job callbacks: the PostgreSQL twin of `migrations/0009_job_callbacks.sql`. The URIs
-- a job's outcome and progress are POSTed to (the OGC `subscriber` of its execution
-- request), stored with the job in the transaction that queues it, and the state of
-- their delivery: the durable to-do list of the deliverers of every API process.

CREATE TABLE job_callbacks (
    job_id           TEXT    PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    -- The job's tenant: its secrets sign the deliveries.
    tenant           TEXT    NOT NULL,
    -- Absolute http(s) URIs, each optional: `successful` to the first, `failed` and
    -- `dismissed` to the second, progress while running to the third.
    success_uri      TEXT,
    failed_uri       TEXT,
    in_progress_uri  TEXT,
    -- `pending`, `delivered` (a 2xx answer), `abandoned` (given up), `unsubscribed`
    -- (no URI for the job's outcome).
    final_state      TEXT    NOT NULL DEFAULT 'pending'
                     CHECK (final_state IN ('pending', 'delivered', 'abandoned', 'unsubscribed')),
    -- Attempts so far and the earliest time (ms) of the next; a claim moves it past
    -- the claimed attempt and names its deliverer in `claimed_by`.
    attempts         BIGINT  NOT NULL DEFAULT 0,
    next_attempt_at  BIGINT  NOT NULL DEFAULT 0,
    claimed_by       TEXT,
    -- Why the last attempt failed.
    last_error       TEXT,
    -- The last progress (percent) sent to `in_progress_uri`, and when (ms).
    progress_sent    BIGINT,
    progress_sent_at BIGINT,
    created_at       BIGINT  NOT NULL
);

-- The deliverer polls the outcomes still to deliver, due first.
CREATE INDEX job_callbacks_pending ON job_callbacks (next_attempt_at) WHERE final_state = 'pending';
