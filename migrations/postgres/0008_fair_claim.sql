-- Fair share between tenants: the PostgreSQL twin of `migrations/0007_fair_claim.sql`.

-- A tenant's queued jobs in insertion order (also its distinct tenants, by skip-scan).
CREATE INDEX jobs_ready_tenant ON jobs (tenant, seq) WHERE status = 'accepted';
-- A tenant's queued single jobs, and its queued sweep runs, in insertion order.
CREATE INDEX jobs_ready_tenant_single ON jobs (tenant, seq) WHERE status = 'accepted' AND sweep_id IS NULL;
CREATE INDEX jobs_ready_tenant_sweep ON jobs (tenant, seq) WHERE status = 'accepted' AND sweep_id IS NOT NULL;
-- A tenant's running jobs (counted at each claim).
CREATE INDEX jobs_running_tenant ON jobs (tenant) WHERE status = 'running';

-- Superseded: the claim no longer serves every tenant's single jobs first, and the
-- per-tenant count of queued jobs uses `jobs_ready_tenant`.
DROP INDEX jobs_ready;
DROP INDEX jobs_tenant_queued;
