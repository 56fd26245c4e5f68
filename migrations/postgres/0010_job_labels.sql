-- Traceability of jobs: the PostgreSQL twin of `migrations/0010_job_labels.sql`. Labels
-- (a JSON array of text, `[]` when none) and a free-text note, written in the
-- transaction that queues the job; the quality verdict of a successful job's results,
-- written with them, for the job list. The label filter of `GET /jobs` tests
-- containment (`labels::jsonb @> '["a"]'`).

ALTER TABLE jobs ADD COLUMN labels TEXT NOT NULL DEFAULT '[]';
ALTER TABLE jobs ADD COLUMN note TEXT;
ALTER TABLE jobs ADD COLUMN verdict TEXT;
