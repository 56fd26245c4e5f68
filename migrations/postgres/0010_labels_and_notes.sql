-- Traceability: the PostgreSQL twin of `migrations/0010_labels_and_notes.sql`. Labels
-- (a JSON array of text, `[]` when none) and a free-text note on jobs, sweeps and signals,
-- written in the transaction that creates them; the quality verdict of a successful
-- job's results, written with them, for the job list. The label filters of the lists
-- test containment (`labels::jsonb @> '["a"]'`).

ALTER TABLE jobs ADD COLUMN labels TEXT NOT NULL DEFAULT '[]';
ALTER TABLE jobs ADD COLUMN note TEXT;
ALTER TABLE jobs ADD COLUMN verdict TEXT;

ALTER TABLE sweeps ADD COLUMN labels TEXT NOT NULL DEFAULT '[]';
ALTER TABLE sweeps ADD COLUMN note TEXT;

ALTER TABLE signals ADD COLUMN labels TEXT NOT NULL DEFAULT '[]';
ALTER TABLE signals ADD COLUMN note TEXT;
