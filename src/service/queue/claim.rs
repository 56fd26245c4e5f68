//! Claim: a worker atomically takes the next accepted job and a lease on it.
//!
//! SQLite: one `UPDATE ... WHERE seq = (SELECT ...) RETURNING` statement; SQLite takes
//! the write lock before it reads, so two workers can never claim the same row.
//! PostgreSQL: the candidate is picked in a CTE with `FOR UPDATE SKIP LOCKED` and
//! `LIMIT 1` (a CTE is evaluated once, so the planner cannot claim more rows than
//! asked), then updated: concurrent claimers skip each other's row instead of waiting
//! or taking the same one. The statement runs in its own explicit transaction, committed
//! before the claim is returned: a `RETURNING` read alone in autocommit would drop the
//! commit's error (sqlx issue #3430), and a worker would run a job whose claim was never
//! stored. Nothing is held once the claim returns.
//!
//! Order: fair share between tenants. The tenant whose turn it is has the fewest running
//! jobs (across every process); ties go to the tenant served least recently (the latest
//! claim of any of its jobs; a tenant never served first), then to the tenant whose oldest
//! queued job is oldest. The recency matters when several workers free up at once: a
//! tenant whose runs just ended has no running job either, and its oldest queued job is
//! older than a newcomer's, so without it every freed worker would serve it again.
//! Within that tenant, its oldest single job, else its oldest sweep run (a sweep's runs
//! count as their tenant's). So one tenant's 300 queued jobs delay another tenant's
//! single job by one run at most, and a sweep of thousands of runs never makes its own
//! tenant's single jobs wait for more than the runs already computing.
//!
//! Each step is an index probe (migration 0008): the distinct tenants with queued work
//! come from a skip-scan of `jobs_ready_tenant` (one probe per tenant), their running
//! counts from `jobs_running_tenant`, their latest claims from `jobs_tenant_started`
//! (migration 0011), their oldest jobs from `jobs_ready_tenant` and
//! `jobs_ready_tenant_single` (SQLite is told the index of the skip-scan: without
//! statistics its planner would scan every queued job). The cost grows with the number of tenants that have
//! queued work, not with the number of jobs.
//!
//! PostgreSQL claimers run concurrently and skip each other's locked rows, so its query
//! ranks a few candidate jobs of every tenant (the first [`CANDIDATES_PER_TENANT`]
//! singles and sweep runs) rather than one: a claimer that finds the turn's first job
//! locked takes the next candidate instead of finding nothing.

use std::time::Duration;

use sqlx::Row;

use super::{ClaimedJob, JobQueue, Lease};
use crate::service::clock::duration_ms;
use crate::service::db::with_pool;

/// Candidates per tenant and kind (single, sweep run) that a PostgreSQL claim ranks:
/// at least as many as claims likely to run at the same moment.
pub const CANDIDATES_PER_TENANT: i64 = 16;

const CLAIM_SQLITE: &str = "\
    WITH RECURSIVE queued(tenant) AS ( \
        SELECT MIN(tenant) FROM jobs INDEXED BY jobs_ready_tenant WHERE status = 'accepted' \
        UNION ALL \
        SELECT (SELECT MIN(tenant) FROM jobs INDEXED BY jobs_ready_tenant \
                WHERE status = 'accepted' AND tenant > queued.tenant) \
        FROM queued WHERE queued.tenant IS NOT NULL), \
    turn(tenant) AS ( \
        SELECT tenant FROM queued WHERE tenant IS NOT NULL \
        ORDER BY (SELECT COUNT(*) FROM jobs r WHERE r.status = 'running' AND r.tenant = queued.tenant), \
            COALESCE((SELECT MAX(started_at) FROM jobs s INDEXED BY jobs_tenant_started \
                WHERE s.started_at IS NOT NULL AND s.tenant = queued.tenant), -1), \
            (SELECT MIN(seq) FROM jobs o WHERE o.status = 'accepted' AND o.tenant = queued.tenant) \
        LIMIT 1) \
    UPDATE jobs SET status = 'running', attempt = attempt + 1, lease_owner = $1, \
        lease_expires_at = $2, started_at = $3, updated_at = $3, progress = 0, message = 'running' \
    WHERE seq = COALESCE( \
        (SELECT seq FROM jobs WHERE status = 'accepted' AND sweep_id IS NULL \
            AND tenant = (SELECT tenant FROM turn) ORDER BY seq LIMIT 1), \
        (SELECT seq FROM jobs WHERE status = 'accepted' \
            AND tenant = (SELECT tenant FROM turn) ORDER BY seq LIMIT 1)) \
    RETURNING id, process_id, inputs, attempt, created_at, content_hash, tenant";

const CLAIM_POSTGRES: &str = "\
    WITH RECURSIVE queued(tenant) AS ( \
        (SELECT tenant FROM jobs WHERE status = 'accepted' ORDER BY tenant LIMIT 1) \
        UNION ALL \
        SELECT (SELECT j.tenant FROM jobs j WHERE j.status = 'accepted' AND j.tenant > queued.tenant \
                ORDER BY j.tenant LIMIT 1) \
        FROM queued WHERE queued.tenant IS NOT NULL), \
    tenants AS MATERIALIZED ( \
        SELECT tenant, \
            (SELECT COUNT(*) FROM jobs r WHERE r.status = 'running' AND r.tenant = queued.tenant) AS running, \
            COALESCE((SELECT MAX(started_at) FROM jobs s WHERE s.started_at IS NOT NULL \
                AND s.tenant = queued.tenant), -1) AS served, \
            (SELECT MIN(seq) FROM jobs o WHERE o.status = 'accepted' AND o.tenant = queued.tenant) AS oldest \
        FROM queued WHERE tenant IS NOT NULL), \
    candidates AS ( \
        SELECT c.seq, c.sweep_run, t.running, t.served, t.oldest FROM tenants t CROSS JOIN LATERAL ( \
            (SELECT seq, FALSE AS sweep_run FROM jobs WHERE status = 'accepted' AND sweep_id IS NULL \
                AND tenant = t.tenant ORDER BY seq LIMIT $4) \
            UNION ALL \
            (SELECT seq, TRUE AS sweep_run FROM jobs WHERE status = 'accepted' AND sweep_id IS NOT NULL \
                AND tenant = t.tenant ORDER BY seq LIMIT $4)) c), \
    next AS ( \
        SELECT jobs.seq FROM jobs JOIN candidates ON candidates.seq = jobs.seq \
        WHERE jobs.status = 'accepted' \
        ORDER BY candidates.running, candidates.served, candidates.oldest, candidates.sweep_run, jobs.seq LIMIT 1 \
        FOR UPDATE OF jobs SKIP LOCKED) \
    UPDATE jobs SET status = 'running', attempt = attempt + 1, lease_owner = $1, \
        lease_expires_at = $2, started_at = $3, updated_at = $3, progress = 0, message = 'running' \
    FROM next WHERE jobs.seq = next.seq \
    RETURNING jobs.id, jobs.process_id, jobs.inputs, jobs.attempt, jobs.created_at, jobs.content_hash, \
        jobs.tenant";

impl JobQueue {
    /// Takes the next accepted job for `owner`, leased for `lease`; `None` if the queue is empty.
    pub async fn claim(&self, owner: &str, lease: Duration) -> Result<Option<ClaimedJob>, sqlx::Error> {
        let now = self.now();
        let sql = self.db.choose(CLAIM_SQLITE, CLAIM_POSTGRES);
        with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            let query = sqlx::query(sql)
                .bind(owner)
                .bind(now.saturating_add(duration_ms(lease)))
                .bind(now);
            // Only PostgreSQL's statement ranks several candidates per tenant.
            let query = if self.db.as_postgres().is_some() {
                query.bind(CANDIDATES_PER_TENANT)
            } else {
                query
            };
            let row = query.fetch_optional(&mut *tx).await?;
            let Some(row) = row else {
                tx.rollback().await?;
                return Ok(None);
            };
            tx.commit().await?;
            let inputs: String = row.try_get("inputs")?;
            let inputs = serde_json::from_str(&inputs).map_err(|e| sqlx::Error::ColumnDecode {
                index: "inputs".into(),
                source: Box::new(e),
            })?;
            Ok(Some(ClaimedJob {
                lease: Lease {
                    job_id: row.try_get("id")?,
                    owner: owner.to_owned(),
                    attempt: row.try_get("attempt")?,
                },
                process_id: row.try_get("process_id")?,
                inputs,
                tenant: row.try_get("tenant")?,
                content_hash: row.try_get("content_hash")?,
                created_at: row.try_get("created_at")?,
                started_at: now,
            }))
        })
    }
}
