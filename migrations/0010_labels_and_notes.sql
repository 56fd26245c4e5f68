-- Traceability: labels (a JSON array of text, `[]` when none) and a free-text note on
-- jobs, sweeps and signals, both given at submission and written in the transaction that creates
-- the resource; and the quality verdict of a successful job's results (`good`,
-- `doubtful`, `poor`), written with its results, so that the job list shows it without
-- reading results. NULL verdict: not successful, or finished before verdicts were kept.

ALTER TABLE jobs ADD COLUMN labels TEXT NOT NULL DEFAULT '[]';
ALTER TABLE jobs ADD COLUMN note TEXT;
ALTER TABLE jobs ADD COLUMN verdict TEXT;

ALTER TABLE sweeps ADD COLUMN labels TEXT NOT NULL DEFAULT '[]';
ALTER TABLE sweeps ADD COLUMN note TEXT;

ALTER TABLE signals ADD COLUMN labels TEXT NOT NULL DEFAULT '[]';
ALTER TABLE signals ADD COLUMN note TEXT;
