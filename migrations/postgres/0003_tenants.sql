-- Tenants: the PostgreSQL twin of `migrations/0003_tenants.sql`. Every job and sweep
-- belongs to the tenant that created it (a name from the auth file), and only that
-- tenant sees it. Rows created before tenants existed, and every row of a service
-- without an auth file, belong to the implicit tenant `default`.

ALTER TABLE jobs ADD COLUMN tenant TEXT NOT NULL DEFAULT 'default';
ALTER TABLE sweeps ADD COLUMN tenant TEXT NOT NULL DEFAULT 'default';

-- Listings are per tenant, newest first.
CREATE INDEX jobs_tenant ON jobs (tenant, seq);
CREATE INDEX sweeps_tenant ON sweeps (tenant, seq);
-- The per-tenant limit on queued jobs counts these.
CREATE INDEX jobs_tenant_queued ON jobs (tenant) WHERE status = 'accepted';
