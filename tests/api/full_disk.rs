//! Fault injection: the disk fills up under a running service, then space is freed.
//!
//! The SQLite data directory lives on a small file system the test fills: a tmpfs the
//! test mounts when it runs as root (`mount -t tmpfs -o size=…`, unmounted by a drop
//! guard), filled with a filler file; where no mount is possible (not root, no
//! `CAP_SYS_ADMIN`) the database is capped with SQLite's own limit (`max_page_count`,
//! `--max-database-mib`) and filled with filler signals, so the same checks run
//! everywhere (never skipped, under CI or not). The full disk meets signal uploads, job
//! submissions, a signal deletion and a job's results write. Then:
//!
//! - every write the service refused said so: 507 (or 503) with `Retry-After` and a
//!   problem document naming the cause; reads kept working; `/readyz` and `/healthz`
//!   said the service could not write; `chocmodal_failed_writes_total` counted it;
//! - once space is freed the service writes again on its own, at once (no connection
//!   left inside a transaction holding the write lock: writes do not wait for the busy
//!   timeout), `/readyz` is ready again, and the job's held results land;
//! - after a restart on the same data, every `201`/`204` answered is there (each
//!   accepted signal and job, the deleted signal gone) and nothing else: nothing lost,
//!   nothing duplicated.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use reqwest::{Response, StatusCode};
use serde_json::{Value, json};
use tempfile::TempDir;

use crate::helpers::{
    Backend, TestApp, TestStore, assert_problem, on_both_backends, spawn_app_in, spawn_app_on,
};

on_both_backends!(answers_of_201_and_204_are_durable_across_a_restart);

/// Size of the mounted file system (MiB).
const TMPFS_MIB: u64 = 24;
/// Cap of the database when no file system can be mounted (MiB).
const PAGE_LIMIT_MIB: u64 = 4;

/// A tmpfs mounted on a temporary directory, unmounted when dropped.
struct Tmpfs {
    dir: TempDir,
}

impl Tmpfs {
    /// Mounts a tmpfs of `mib` MiB; `Err` says why not (not root, no permission).
    fn mount(mib: u64) -> Result<Self, String> {
        let dir = TempDir::new().map_err(|e| e.to_string())?;
        let output = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={mib}m"), "tmpfs"])
            .arg(dir.path())
            .output()
            .map_err(|e| format!("cannot run mount: {e}"))?;
        if output.status.success() {
            Ok(Self { dir })
        } else {
            Err(format!(
                "mount -t tmpfs failed: {}",
                String::from_utf8_lossy(&output.stderr).trim()
            ))
        }
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let unmounted = Command::new("umount")
            .arg(self.dir.path())
            .status()
            .is_ok_and(|status| status.success());
        if !unmounted {
            // Still busy (a test that failed while its service held files): detach it.
            let _ = Command::new("umount").arg("-l").arg(self.dir.path()).status();
        }
    }
}

/// Where the data directory lives and how it is filled.
enum Disk {
    /// A mounted tmpfs, filled with a filler file.
    Tmpfs(Tmpfs),
    /// A temporary directory whose database is capped at [`PAGE_LIMIT_MIB`], filled
    /// with filler signals.
    PageLimit(TempDir),
}

/// What was written to fill the disk (to free it again).
enum Filler {
    File(PathBuf),
    Signals(Vec<String>),
}

impl Disk {
    fn new(prefer_mount: bool) -> Self {
        if prefer_mount {
            match Tmpfs::mount(TMPFS_MIB) {
                Ok(tmpfs) => return Self::Tmpfs(tmpfs),
                Err(why) => {
                    eprintln!("full-disk test: {why}; capping the database with max_page_count instead")
                }
            }
        }
        Self::PageLimit(TempDir::new().unwrap())
    }

    fn dir(&self) -> &Path {
        match self {
            Self::Tmpfs(tmpfs) => tmpfs.path(),
            Self::PageLimit(dir) => dir.path(),
        }
    }

    fn store(&self) -> TestStore {
        TestStore::sqlite_at(self.dir().join("chocmodal.sqlite"))
    }

    fn max_database_bytes(&self) -> Option<u64> {
        match self {
            Self::Tmpfs(_) => None,
            Self::PageLimit(_) => Some(PAGE_LIMIT_MIB << 20),
        }
    }

    /// Fills the disk: after this, a write of a few pages fails.
    async fn fill(&self, app: &TestApp) -> Filler {
        match self {
            Self::Tmpfs(tmpfs) => {
                // An empty WAL: every write from now on needs new space (a WAL that was
                // reset after a checkpoint would take writes into its old frames).
                let pool = app.queue.database().as_sqlite().unwrap();
                sqlx::query("PRAGMA wal_checkpoint(TRUNCATE)")
                    .execute(pool)
                    .await
                    .unwrap();
                let path = tmpfs.path().join("filler");
                let mut file = std::fs::File::create(&path).unwrap();
                let chunk = vec![0u8; 64 << 10];
                let mut written = 0usize;
                loop {
                    match file.write(&chunk) {
                        Ok(0) => break,
                        Ok(n) => written += n,
                        Err(error) if error.raw_os_error() == Some(28) => break,
                        Err(error) => panic!("filling the tmpfs: {error}"),
                    }
                }
                let _ = file.sync_all();
                assert!(written > 0, "the filler wrote nothing");
                Filler::File(path)
            }
            Self::PageLimit(_) => {
                // Large fillers first, then smaller ones: what is left is less than a
                // small signal's pages (about 8 KB).
                let mut fillers = Vec::new();
                for (samples, seed0) in [(200_000, 1000u64), (20_000, 2000), (1_000, 3000)] {
                    for seed in seed0..seed0 + 40 {
                        let response = app.post_signal(noise_csv(samples, seed), "text/csv", "").await;
                        match response.status() {
                            StatusCode::CREATED => {
                                let body: Value = response.json().await.unwrap();
                                fillers.push(body["id"].as_str().unwrap().to_owned());
                            }
                            StatusCode::INSUFFICIENT_STORAGE => break,
                            other => {
                                panic!("filling: unexpected {other}: {}", response.text().await.unwrap())
                            }
                        }
                    }
                }
                Filler::Signals(fillers)
            }
        }
    }

    /// Frees the space the filler took.
    async fn free(&self, app: &TestApp, filler: Filler) {
        match filler {
            Filler::File(path) => std::fs::remove_file(path).unwrap(),
            Filler::Signals(ids) => {
                for id in ids {
                    let status = app.delete(&format!("/signals/{id}")).await.status();
                    assert_eq!(status, StatusCode::NO_CONTENT, "deleting filler signal {id}");
                }
            }
        }
    }
}

/// `samples` samples of pseudo-random noise at 100 Hz (incompressible: every sample
/// costs its 8 bytes in the store).
fn noise_csv(samples: usize, seed: u64) -> String {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut csv = String::with_capacity(samples * 28);
    csv.push_str("time,acceleration\n");
    for k in 0..samples {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let value = (state >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0;
        csv.push_str(&format!("{},{value}\n", k as f64 * 0.01));
    }
    csv
}

/// What the service answered to a write made while the disk was full.
#[derive(Debug)]
enum Outcome {
    /// 201/204: it must be durable.
    Accepted(Option<String>),
    /// 507/503 with a problem document naming the cause: nothing was stored.
    Refused,
}

/// Checks that `response` is either a success (`expected`) or a storage refusal.
async fn outcome(response: Response, expected: StatusCode, what: &str) -> Outcome {
    let status = response.status();
    if status == expected {
        if status == StatusCode::NO_CONTENT {
            return Outcome::Accepted(None);
        }
        let body: Value = response.json().await.unwrap();
        let id = body["id"].as_str().or(body["jobID"].as_str()).unwrap().to_owned();
        return Outcome::Accepted(Some(id));
    }
    assert!(
        matches!(
            status,
            StatusCode::INSUFFICIENT_STORAGE | StatusCode::SERVICE_UNAVAILABLE
        ),
        "{what}: a refused write is 507 or 503, got {status}: {}",
        response.text().await.unwrap_or_default()
    );
    let retry_after = response
        .headers()
        .get("retry-after")
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<u64>().ok());
    assert!(retry_after.is_some_and(|s| s > 0), "{what}: Retry-After missing");
    let suffix = if status == StatusCode::INSUFFICIENT_STORAGE {
        "/storage-full"
    } else {
        "/storage-unavailable"
    };
    let problem = assert_problem(response, status, suffix).await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(
        ["SQLITE_FULL", "ENOSPC", "I/O error"]
            .iter()
            .any(|cause| detail.contains(cause)),
        "{what}: the problem names its cause: {detail}"
    );
    Outcome::Refused
}

/// The value of a counter line of `/metrics` summed over the label sets that match.
async fn failed_writes(app: &TestApp, during: &str) -> f64 {
    let text = app.get("/metrics").await.text().await.unwrap();
    text.lines()
        .filter(|line| {
            line.starts_with("chocmodal_failed_writes_total{")
                && line.contains(&format!("during=\"{during}\""))
        })
        .filter_map(|line| line.rsplit(' ').next()?.parse::<f64>().ok())
        .sum()
}

async fn ids_of(app: &TestApp, path: &str, member: &str, id: &str) -> BTreeSet<String> {
    let list = app.get_json(path).await;
    list[member]
        .as_array()
        .unwrap()
        .iter()
        .map(|item| item[id].as_str().unwrap().to_owned())
        .collect()
}

/// The test process's results: `sum` = n(n+1)/2.
fn expected_sum(steps: u64) -> u64 {
    steps * (steps + 1) / 2
}

#[tokio::test]
async fn a_full_tmpfs_refuses_writes_clearly_and_loses_nothing_once_freed() {
    // As root this mounts a tmpfs; elsewhere it falls back to SQLite's page limit.
    survives_a_full_disk(Disk::new(true)).await;
}

#[tokio::test]
async fn a_full_database_under_its_page_limit_refuses_writes_clearly_and_loses_nothing() {
    survives_a_full_disk(Disk::new(false)).await;
}

async fn survives_a_full_disk(disk: Disk) {
    let limit = disk.max_database_bytes();
    let configure = move |config: &mut chocmodal::service::ServiceConfig| {
        config.max_database_bytes = limit;
    };
    let app = spawn_app_in(disk.store(), configure).await;

    // Before: a signal to keep, one to delete while full, a finished job.
    let kept = app.upload_signal(noise_csv(500, 1), "text/csv", "").await["id"]
        .as_str()
        .unwrap()
        .to_owned();
    let doomed = app.upload_signal(noise_csv(500, 2), "text/csv", "").await["id"]
        .as_str()
        .unwrap()
        .to_owned();
    let early_job = app.submit(json!({"steps": 3})).await;
    app.wait_until_finished(&early_job).await;
    // A job whose results (a 20 000-row history) are written while the disk is full.
    let long_steps = 20_000;
    let long_job = app.submit(json!({"steps": long_steps, "step_ms": 0.5})).await;
    app.wait_for(&long_job, &["running"], Duration::from_secs(10))
        .await;

    let filler = disk.fill(&app).await;

    // While full: uploads, submissions and a deletion, each accepted or clearly refused.
    let mut accepted_signals = Vec::new();
    let mut accepted_jobs = Vec::new();
    let mut refused = 0;
    for seed in 0..4 {
        let response = app
            .post_signal(noise_csv(20_000, 100 + seed), "text/csv", "")
            .await;
        match outcome(response, StatusCode::CREATED, "signal upload").await {
            Outcome::Accepted(id) => accepted_signals.push(id.unwrap()),
            Outcome::Refused => refused += 1,
        }
        let response = app
            .post_execution(crate::counting::ID, &json!({"inputs": {"steps": 1 + seed}}))
            .await;
        match outcome(response, StatusCode::CREATED, "job submission").await {
            Outcome::Accepted(id) => accepted_jobs.push(id.unwrap()),
            Outcome::Refused => refused += 1,
        }
    }
    let deleted = matches!(
        outcome(
            app.delete(&format!("/signals/{doomed}")).await,
            StatusCode::NO_CONTENT,
            "signal deletion"
        )
        .await,
        Outcome::Accepted(_)
    );
    assert!(
        refused > 0,
        "the full disk refused no write: the test did not fill it"
    );

    // Reads keep working, and the service says it cannot write.
    assert_eq!(
        app.get(&format!("/signals/{kept}")).await.status(),
        StatusCode::OK
    );
    assert_eq!(
        app.get(&format!("/jobs/{early_job}/results")).await.status(),
        StatusCode::OK
    );
    let readiness = app.get("/readyz").await;
    assert!(
        matches!(
            readiness.status(),
            StatusCode::INSUFFICIENT_STORAGE | StatusCode::SERVICE_UNAVAILABLE
        ),
        "/readyz while writes are refused: {}",
        readiness.status()
    );
    assert!(readiness.headers().contains_key("retry-after"));
    let health = app.get_json("/healthz").await;
    assert_eq!(
        health["status"], "ok",
        "a full disk is no reason to restart: {health}"
    );
    assert_eq!(health["writable"], false, "{health}");
    assert!(health["storage_fault"].is_string(), "{health}");
    assert!(failed_writes(&app, "request").await >= 1.0);

    // The long job finishes while the disk is full: its results write is refused, held
    // and retried (never dropped); the job still reads as running meanwhile.
    let deadline = Instant::now() + Duration::from_secs(30);
    while failed_writes(&app, "results").await < 1.0 {
        assert!(Instant::now() < deadline, "the results write was never refused");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert_eq!(app.status(&long_job).await["status"], "running");

    disk.free(&app, filler).await;

    // Writable again on its own, at once: no connection holds the write lock.
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let status = app.get("/readyz").await.status();
        if status == StatusCode::OK {
            break;
        }
        assert!(Instant::now() < deadline, "/readyz did not come back: {status}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let started = Instant::now();
    let after_signal = app.upload_signal(noise_csv(500, 3), "text/csv", "").await["id"]
        .as_str()
        .unwrap()
        .to_owned();
    let after_job = app.submit(json!({"steps": 2})).await;
    assert!(
        started.elapsed() < Duration::from_secs(3),
        "writes after freeing space waited {:?} (a connection stuck in a transaction?)",
        started.elapsed()
    );
    assert_eq!(app.get_json("/healthz").await["writable"], true);
    let long = app
        .wait_for(&long_job, &["successful", "failed"], Duration::from_secs(30))
        .await;
    assert_eq!(long["status"], "successful", "{long}");
    for job in accepted_jobs.iter().chain([&after_job]) {
        app.wait_until_finished(job).await;
    }
    // Every accepted job reads the same from every pooled connection, again and again.
    for _ in 0..10 {
        for job in accepted_jobs.iter().chain([&after_job, &long_job]) {
            assert_eq!(
                app.get(&format!("/jobs/{job}")).await.status(),
                StatusCode::OK,
                "job {job}"
            );
        }
    }

    // A restart on the same data: everything answered 201/204 is there, nothing else.
    let store = app.stop().await;
    let app = spawn_app_in(store, configure).await;
    let mut signals: BTreeSet<String> = [kept.clone(), after_signal].into_iter().collect();
    signals.extend(accepted_signals);
    if !deleted {
        signals.insert(doomed.clone());
    }
    assert_eq!(
        ids_of(&app, "/signals?limit=1000", "signals", "id").await,
        signals,
        "stored signals after the restart"
    );
    if deleted {
        assert_eq!(
            app.get(&format!("/signals/{doomed}")).await.status(),
            StatusCode::NOT_FOUND
        );
    }
    let mut jobs: BTreeSet<String> = [early_job, long_job.clone(), after_job].into_iter().collect();
    jobs.extend(accepted_jobs);
    assert_eq!(
        ids_of(&app, "/jobs?limit=1000", "jobs", "jobID").await,
        jobs,
        "jobs after the restart"
    );
    let results = app.get_json(&format!("/jobs/{long_job}/results")).await;
    assert_eq!(results["sum"], expected_sum(long_steps), "{results}");
    let history = app
        .get(&format!("/jobs/{long_job}/results/signal?format=csv"))
        .await;
    assert_eq!(history.status(), StatusCode::OK);
    assert_eq!(
        history.text().await.unwrap().lines().count(),
        long_steps as usize + 1,
        "the held history landed whole"
    );
    app.stop().await;
}

/// On either backend, the writes that return rows (a signal's `INSERT ... RETURNING`,
/// a deletion's `DELETE ... RETURNING`, a claim's `UPDATE ... RETURNING`) run in explicit
/// transactions: what was answered `201`/`204` (and a claimed job's run) is there after
/// a restart, what was refused is not, and pooled connections come back usable.
async fn answers_of_201_and_204_are_durable_across_a_restart(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let kept = app.upload_signal(noise_csv(200, 7), "text/csv", "").await["id"]
        .as_str()
        .unwrap()
        .to_owned();
    let deleted = app.upload_signal(noise_csv(200, 8), "text/csv", "").await["id"]
        .as_str()
        .unwrap()
        .to_owned();
    assert_eq!(
        app.delete(&format!("/signals/{deleted}")).await.status(),
        StatusCode::NO_CONTENT
    );
    // A refused upload (a 422) leaves nothing behind, and the connection it used is
    // clean: the next writes go through at once.
    let refused = app
        .post_signal("time,acceleration\n0,1\n0,2\n", "text/csv", "")
        .await;
    assert_eq!(refused.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let job = app.submit(json!({"steps": 5})).await;
    let finished = app.wait_until_finished(&job).await;
    assert_eq!(finished["status"], "successful", "{finished}");
    let store = app.stop().await;
    let app = crate::helpers::spawn_app_in(store, |_| {}).await;
    assert_eq!(
        ids_of(&app, "/signals", "signals", "id").await,
        [kept].into_iter().collect::<BTreeSet<_>>()
    );
    assert_eq!(
        app.get(&format!("/signals/{deleted}")).await.status(),
        StatusCode::NOT_FOUND
    );
    let results = app.get_json(&format!("/jobs/{job}/results")).await;
    assert_eq!(results["sum"], expected_sum(5));
    app.stop().await;
}
