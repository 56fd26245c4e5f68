-- Job callbacks (the OGC `subscriber` of an execution request): the URIs a job's
-- outcome and progress are POSTed to, stored with the job in the transaction that
-- queues it, and the state of their delivery. A background task of every API process
-- delivers them (`src/service/callbacks/`); this row is its durable to-do list, so a
-- callback still undelivered when a process stops is delivered after a restart.

CREATE TABLE job_callbacks (
    job_id           TEXT    PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
    -- The job's tenant: its secrets sign the deliveries.
    tenant           TEXT    NOT NULL,
    -- Absolute http(s) URIs, each optional: the outcome `successful` goes to the first,
    -- `failed` and `dismissed` to the second, progress while running to the third.
    success_uri      TEXT,
    failed_uri       TEXT,
    in_progress_uri  TEXT,
    -- The outcome's delivery: `pending` (job not finished yet, or not delivered yet),
    -- `delivered` (a 2xx answer), `abandoned` (given up), `unsubscribed` (no URI for
    -- the job's outcome).
    final_state      TEXT    NOT NULL DEFAULT 'pending'
                     CHECK (final_state IN ('pending', 'delivered', 'abandoned', 'unsubscribed')),
    -- Attempts at delivering the outcome so far, and the earliest time (ms) of the
    -- next; a deliverer that claims it moves this past its attempt (a claim it loses by
    -- crashing expires by itself), and `claimed_by` names it.
    attempts         INTEGER NOT NULL DEFAULT 0,
    next_attempt_at  INTEGER NOT NULL DEFAULT 0,
    claimed_by       TEXT,
    -- Why the last attempt failed (HTTP status or transport error).
    last_error       TEXT,
    -- The last progress (percent) sent to `in_progress_uri`, and when (ms).
    progress_sent    INTEGER,
    progress_sent_at INTEGER,
    created_at       INTEGER NOT NULL
);

-- The deliverer polls the outcomes still to deliver, due first.
CREATE INDEX job_callbacks_pending ON job_callbacks (next_attempt_at) WHERE final_state = 'pending';
