-- Fair share between tenants: a claim picks the tenant with the fewest running jobs
-- (ties: the one whose oldest queued job is oldest), then that tenant's oldest single
-- job, else its oldest sweep run (`src/service/queue/claim.rs`). These indexes keep each
-- step a short index probe, however many jobs are queued or finished.

-- A tenant's queued jobs in insertion order (also its distinct tenants, by skip-scan).
CREATE INDEX jobs_ready_tenant ON jobs (tenant, seq) WHERE status = 'accepted';
-- A tenant's queued single jobs in insertion order.
CREATE INDEX jobs_ready_tenant_single ON jobs (tenant, seq) WHERE status = 'accepted' AND sweep_id IS NULL;
-- A tenant's running jobs (counted at each claim).
CREATE INDEX jobs_running_tenant ON jobs (tenant) WHERE status = 'running';

-- Superseded: the claim no longer serves every tenant's single jobs first, and the
-- per-tenant count of queued jobs uses `jobs_ready_tenant`.
DROP INDEX jobs_ready_single;
DROP INDEX jobs_tenant_queued;
