-- Plausibility warnings: the PostgreSQL twin of `migrations/0004_job_warnings.sql`. A
-- job's input warnings (JSON array of {code, pointer, message}), found when it was
-- submitted (a sweep run: when its sweep was) and shown with its status. NULL for jobs
-- submitted before warnings existed.

ALTER TABLE jobs ADD COLUMN warnings TEXT;
