-- The PostgreSQL twin of `migrations/0011_fair_claim_recency.sql`.
-- Fair share between tenants, ties: among the tenants with the fewest running jobs, the
-- one served least recently (the latest `started_at` of its jobs; never served first),
-- then the one whose oldest queued job is oldest (`src/service/queue/claim.rs`). This
-- index makes a tenant's latest claim one probe.
CREATE INDEX jobs_tenant_started ON jobs (tenant, started_at) WHERE started_at IS NOT NULL;
