//! Shutdown in the right order: on the first signal the workers claim nothing more,
//! running jobs get the grace period and are then handed back to the queue (their
//! attempt not counted) while the API keeps answering reads and refuses writes with 503;
//! a second signal hands the running jobs back at once. Handed-back jobs complete on the
//! next start.

use std::time::Duration;

use chocmodal::service::shutdown::Phase;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::counting;
use crate::helpers::{Backend, TestApp, assert_problem, on_both_backends, spawn_app_in, spawn_app_on};
use crate::scale_out::Process;

on_both_backends!(jobs_outliving_the_grace_are_handed_back_and_complete_on_the_next_start);

/// The draining test on each backend. A claim that began before the signal and returns
/// a job after it hands that job straight back, so no job starts after the signal.
mod draining {
    use crate::helpers::Backend;

    #[tokio::test]
    async fn sqlite_while_draining_reads_are_answered_writes_get_503_and_a_second_signal_hands_back_at_once()
    {
        super::while_draining_reads_are_answered_writes_get_503_and_a_second_signal_hands_back_at_once(
            Backend::Sqlite,
        )
        .await
    }

    #[tokio::test]
    #[cfg_attr(
        chocmodal_skip_postgres_tests,
        ignore = "needs PostgreSQL: none found at build time, or CHOCMODAL_SKIP_POSTGRES_TESTS=1 (build.rs)"
    )]
    async fn postgres_while_draining_reads_are_answered_writes_get_503_and_a_second_signal_hands_back_at_once()
     {
        crate::postgres::refuse_skip_under_ci(concat!(
            module_path!(),
            "::postgres_while_draining_reads_are_answered_writes_get_503_and_a_second_signal_hands_back_at_once"
        ));
        super::while_draining_reads_are_answered_writes_get_503_and_a_second_signal_hands_back_at_once(
            Backend::Postgres,
        )
        .await
    }
}

/// A `count-steps` job that runs about `seconds` (1 ms per step).
fn job_of_seconds(seconds: u64) -> Value {
    json!({"steps": seconds * 1000, "step_ms": 1})
}

async fn wait_until_running(app: &TestApp, jobs: &[String]) {
    for job in jobs {
        app.wait_for(job, &["running"], Duration::from_secs(10)).await;
    }
}

async fn assert_queued_unclaimed_by_this_run(app: &TestApp, job: &str, why: &str) {
    let record = app.queue.get("default", job).await.unwrap().unwrap();
    assert_eq!(record.status.as_str(), "accepted", "{why}: {record:?}");
    assert_eq!(record.attempt, 0, "{why}: its attempt is not counted: {record:?}");
    assert_eq!(record.started_at, None, "{why}: {record:?}");
}

async fn jobs_outliving_the_grace_are_handed_back_and_complete_on_the_next_start(backend: Backend) {
    let grace = Duration::from_millis(300);
    let app = spawn_app_on(backend, |config| {
        config.workers = 2;
        config.shutdown_grace = grace;
    })
    .await;
    let mut jobs = Vec::new();
    for _ in 0..4 {
        jobs.push(app.submit(job_of_seconds(2)).await);
    }
    wait_until_running(&app, &jobs[..2]).await;
    // Running in the database comes with the claim; the run itself starts a moment later.
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    while app.probe.started() < 2 && std::time::Instant::now() < deadline {
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    assert_eq!(app.probe.started(), 2);

    // One request to stop (as one SIGTERM): the 300 ms grace, then the hand-back.
    let probe = app.probe.clone();
    let store = app.stop().await;
    assert_eq!(probe.started(), 2, "no job started after the signal");

    // A run of 2 s that was still running when the 300 ms grace ended was handed back:
    // had the shutdown waited for it, it would be successful.
    let after = spawn_app_in(store, |config| config.workers = 0).await;
    for job in &jobs[..2] {
        assert_queued_unclaimed_by_this_run(&after, job, "running at the signal, handed back").await;
    }
    for job in &jobs[2..] {
        assert_queued_unclaimed_by_this_run(&after, job, "queued at the signal, never claimed").await;
    }
    let store = after.stop().await;

    let restarted = spawn_app_in(store, |config| config.workers = 2).await;
    for job in &jobs {
        let status = restarted.wait_until_finished(job).await;
        assert_eq!(status["status"], "successful", "{status}");
        let results = restarted.get_json(&format!("/jobs/{job}/results")).await;
        assert_eq!(results["sum"], 2000 * 2001 / 2);
    }
}

async fn while_draining_reads_are_answered_writes_get_503_and_a_second_signal_hands_back_at_once(
    backend: Backend,
) {
    // A grace period no test waits out: only the second signal can end the shutdown.
    let app = spawn_app_on(backend, |config| {
        config.workers = 3;
        config.shutdown_grace = Duration::from_secs(3600);
    })
    .await;
    let running = vec![
        app.submit(job_of_seconds(1000)).await,
        app.submit(job_of_seconds(1000)).await,
    ];
    wait_until_running(&app, &running).await;

    app.shutdown.request();
    assert_eq!(app.shutdown.phase(), Phase::Draining);
    // Queued after the signal with a worker slot free: nothing claims it.
    let late = app
        .queue
        .enqueue(
            "default",
            counting::ID,
            &job_of_seconds(1),
            &[],
            None,
            None,
            None,
            &Default::default(),
        )
        .await
        .unwrap();
    let late = match late {
        chocmodal::service::queue::Admission::Admitted(record) => record.id,
        other => panic!("the queue refused a job: {other:?}"),
    };
    // Reads are answered while the running jobs drain.
    let status = app.status(&running[0]).await;
    assert_eq!(status["status"], "running", "{status}");
    let listing = app.get("/jobs").await;
    assert_eq!(listing.status(), StatusCode::OK);
    // Writes are refused with a reason and a time to come back.
    let refused = app
        .post_execution(counting::ID, &json!({"inputs": job_of_seconds(1)}))
        .await;
    let retry_after = refused.headers().get("retry-after").cloned();
    let problem = assert_problem(refused, StatusCode::SERVICE_UNAVAILABLE, "/shutting-down").await;
    assert!(
        retry_after.is_some_and(|seconds| seconds.to_str().unwrap().parse::<u64>().unwrap() > 0),
        "503 without a Retry-After: {problem}"
    );
    let dismissal = app.delete(&format!("/jobs/{}", running[1])).await;
    assert_problem(dismissal, StatusCode::SERVICE_UNAVAILABLE, "/shutting-down").await;

    // The second signal: the jobs are handed back without waiting for the hour of grace.
    app.shutdown.request();
    let probe = app.probe.clone();
    let store = app.stop().await;
    assert_eq!(probe.started(), 2, "only the jobs running before the signal ran");

    let after = spawn_app_in(store, |config| config.workers = 0).await;
    for job in &running {
        assert_queued_unclaimed_by_this_run(&after, job, "running at the second signal, handed back").await;
    }
    assert_queued_unclaimed_by_this_run(&after, &late, "queued after the signal").await;
}

/// The signal path of the real binary: the first SIGTERM drains (reads answered, writes
/// 503), the second hands the running job back and the process exits successfully; the
/// next start finds the job queued again.
#[tokio::test]
async fn two_sigterms_make_the_binary_hand_its_running_job_back_and_exit() {
    let dir = tempfile::TempDir::new().unwrap();
    let data = dir.path().to_str().unwrap().to_owned();
    let serve = |workers: &'static str| {
        vec![
            "serve".to_owned(),
            "--workers".to_owned(),
            workers.to_owned(),
            "--bind".to_owned(),
            "127.0.0.1:0".to_owned(),
            "--data-dir".to_owned(),
            data.clone(),
            // Only the second signal can end this shutdown while the job runs.
            "--shutdown-grace-seconds".to_owned(),
            "3600".to_owned(),
        ]
    };
    let args = serve("1");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut server = Process::start(dir.path(), "serve", &args);
    let ready = server.wait_for_log("chocmodal is ready").await;
    let address = format!("http://{}", ready["address"].as_str().unwrap());
    let client = reqwest::Client::new();
    // About 10⁷ steps: far longer than this test.
    let long = json!({"inputs": {
        "beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                 "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                 "elements": 40, "modes": 10},
        "contact": {"rk": 1.0},
        "release": {"tip_displacement": 0.001},
        "solver": {"time_step": 1e-5, "duration": 100.0},
        "reference": {"modes": 30},
        "output": {"interval": 1e-2}
    }});
    let created = client
        .post(format!("{address}/processes/cantilever-impact/execution"))
        .json(&long)
        .send()
        .await
        .unwrap();
    assert_eq!(created.status(), StatusCode::CREATED);
    let job = created.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    let status_of = |job: &str| {
        let request = client.get(format!("{address}/jobs/{job}"));
        async move { request.send().await.unwrap().json::<Value>().await.unwrap() }
    };
    let mut waited = 0;
    while status_of(&job).await["status"] != "running" {
        assert!(waited < 600, "the job never started");
        waited += 1;
        tokio::time::sleep(Duration::from_millis(50)).await;
    }

    server.send_sigterm();
    server.wait_for_log("stopping: no new jobs are claimed, running jobs get the grace period; a second signal hands them back at once").await;
    assert_eq!(
        status_of(&job).await["status"],
        "running",
        "reads are answered while draining"
    );
    let refused = client
        .post(format!("{address}/processes/cantilever-impact/execution"))
        .json(&long)
        .send()
        .await
        .unwrap();
    assert_eq!(refused.status(), StatusCode::SERVICE_UNAVAILABLE);
    assert!(refused.headers().contains_key("retry-after"));

    server.send_sigterm();
    let exit = server.wait();
    assert!(exit.success(), "exit status after two signals: {exit}");

    let args = serve("0");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut restarted = Process::start(dir.path(), "restarted", &args);
    let ready = restarted.wait_for_log("chocmodal is ready").await;
    let address = format!("http://{}", ready["address"].as_str().unwrap());
    let status = reqwest::get(format!("{address}/jobs/{job}"))
        .await
        .unwrap()
        .json::<Value>()
        .await
        .unwrap();
    assert_eq!(status["status"], "accepted", "handed back: {status}");
}
