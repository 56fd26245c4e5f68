-- Fair share between tenants, ties: among the tenants with the fewest running jobs, the
-- one served least recently (the latest `started_at` of its jobs; never served first),
-- then the one whose oldest queued job is oldest (`src/service/queue/claim.rs`). Without
-- it, two workers freed at once by a tenant's runs would both serve that tenant again
-- (its oldest queued job is older than any newcomer's), and a tenant with one job could
-- wait behind many runs of another. This index makes a tenant's latest claim one probe.
CREATE INDEX jobs_tenant_started ON jobs (tenant, started_at) WHERE started_at IS NOT NULL;
