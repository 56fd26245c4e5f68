//! The JSON documents of the API (OGC API – Processes shapes), with their OpenAPI schemas.

use serde::Serialize;
use utoipa::ToSchema;

use crate::service::clock::rfc3339;
use crate::service::queue::{JobRecord, JobStatus};

/// A link to a related resource.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct Link {
    /// Target, relative to the service root (e.g. `/jobs/7f3c...`).
    pub href: String,
    /// Relation type: `self`, `next`, `results`, `status`, `service-desc`, ...
    pub rel: String,
    /// Media type of the target.
    #[serde(rename = "type", skip_serializing_if = "Option::is_none")]
    pub media_type: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub title: Option<String>,
}

impl Link {
    pub fn new(href: impl Into<String>, rel: &str, media_type: &str) -> Self {
        Self {
            href: href.into(),
            rel: rel.to_owned(),
            media_type: Some(media_type.to_owned()),
            title: None,
        }
    }

    pub fn titled(mut self, title: &str) -> Self {
        self.title = Some(title.to_owned());
        self
    }
}

/// The relation of a job's link to its calculation note (`/jobs/{jobId}/report`).
pub const REPORT_RELATION: &str = "https://chocmodal.dev/rel/report";

/// When running `job` should finish (ms since the epoch), extrapolating its progress
/// at the pace of its run so far: `None` unless running with 1 to 99 % done.
fn estimated_finish(job: &JobRecord) -> Option<i64> {
    let started = job.started_at?;
    let done = i64::from(job.progress);
    (job.status == JobStatus::Running && (1..100).contains(&done))
        .then(|| started + (job.updated_at - started).max(0) * 100 / done)
}

/// The state of one job (OGC `statusInfo`).
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct StatusInfo {
    #[serde(rename = "jobID")]
    pub job_id: String,
    #[serde(rename = "processID")]
    pub process_id: String,
    /// Always `process`.
    #[serde(rename = "type")]
    pub kind: &'static str,
    pub status: JobStatus,
    /// The sweep this job is a run of (absent for single jobs).
    #[serde(rename = "sweepID", skip_serializing_if = "Option::is_none")]
    pub sweep_id: Option<String>,
    /// Human-readable state, e.g. `queued`, `running`, `failed: <reason>`, `finished`;
    /// a successful job whose results' `quality.verdict` is `doubtful` or `poor` says so
    /// with the reasons: `finished; quality poor: <reason>; <reason>`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// Percent done (0–100).
    #[schema(minimum = 0, maximum = 100)]
    pub progress: u8,
    /// When the job was submitted (RFC 3339, UTC).
    pub created: String,
    /// When its current (or last) run started (RFC 3339, UTC).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub started: Option<String>,
    /// When it finished (RFC 3339, UTC).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finished: Option<String>,
    /// Last change of status, progress or message (RFC 3339, UTC).
    pub updated: String,
    /// When a running job should finish at the pace of its run so far (RFC 3339, UTC):
    /// started + (updated − started) × 100 / progress, from its last progress report.
    /// Absent until 1 % is done, and once it ends.
    #[serde(rename = "estimatedFinish", skip_serializing_if = "Option::is_none")]
    pub estimated_finish: Option<String>,
    /// Plausibility warnings about the inputs, found when the job was submitted: valid
    /// inputs that look like a mistake (a unit slip, nothing exciting the model, ...).
    /// Empty with `"warnings": "off"` among the inputs.
    pub warnings: Vec<crate::processes::Warning>,
    /// The labels given at submission (empty when none): `GET /jobs?label=` filters on them.
    pub labels: Vec<String>,
    /// The note given at submission.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// `quality.verdict` of the results of a successful job: `good`, `doubtful` or
    /// `poor` (absent until it succeeds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<String>,
    pub links: Vec<Link>,
}

impl StatusInfo {
    pub fn from_record(job: &JobRecord) -> Self {
        let href = format!("/jobs/{}", job.id);
        let mut links = vec![Link::new(&href, "self", "application/json").titled("Job status")];
        if job.status == JobStatus::Successful || job.status == JobStatus::Failed {
            links.push(
                Link::new(
                    format!("{href}/results"),
                    "http://www.opengis.net/def/rel/ogc/1.0/results",
                    "application/json",
                )
                .titled("Job results"),
            );
        }
        if job.status == JobStatus::Successful {
            links.push(
                Link::new(format!("{href}/report"), REPORT_RELATION, "text/html")
                    .titled("Calculation note (printable HTML)"),
            );
        }
        links.push(Link::new(
            format!("/processes/{}", job.process_id),
            "up",
            "application/json",
        ));
        if let Some(sweep_id) = &job.sweep_id {
            links.push(
                Link::new(format!("/sweeps/{sweep_id}"), "up", "application/json")
                    .titled("The sweep this job is a run of"),
            );
        }
        Self {
            job_id: job.id.clone(),
            process_id: job.process_id.clone(),
            kind: "process",
            status: job.status,
            sweep_id: job.sweep_id.clone(),
            message: job.message.clone(),
            progress: job.progress,
            created: rfc3339(job.created_at),
            started: job.started_at.map(rfc3339),
            finished: job.finished_at.map(rfc3339),
            updated: rfc3339(job.updated_at),
            estimated_finish: estimated_finish(job).map(rfc3339),
            warnings: job.warnings.clone(),
            labels: job.labels.clone(),
            note: job.note.clone(),
            verdict: job.verdict.clone(),
            links,
        }
    }
}

/// A page of jobs, newest first; follow the `next` link for older ones.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobList {
    pub jobs: Vec<StatusInfo>,
    pub links: Vec<Link>,
}

/// A process as listed by `GET /processes`.
#[derive(Debug, Serialize, ToSchema)]
pub struct ProcessSummary {
    /// Identifier used in URLs, e.g. `cantilever-impact`.
    pub id: String,
    pub title: String,
    pub description: String,
    pub version: &'static str,
    /// Always `["async-execute", "dismiss"]`: every execution is a job.
    #[serde(rename = "jobControlOptions")]
    pub job_control_options: Vec<&'static str>,
    pub links: Vec<Link>,
}

/// The processes this service offers.
#[derive(Debug, Serialize, ToSchema)]
pub struct ProcessList {
    pub processes: Vec<ProcessSummary>,
    pub links: Vec<Link>,
}

/// A process with its inputs and outputs (OGC process description).
#[derive(Debug, Serialize, ToSchema)]
pub struct ProcessDescription {
    #[serde(flatten)]
    pub summary: ProcessSummary,
    /// `{name: {title, description, schema}}` for each input (JSON Schema, SI units).
    #[schema(value_type = Object)]
    pub inputs: serde_json::Value,
    /// `{name: {title, description, schema}}` for each output.
    #[schema(value_type = Object)]
    pub outputs: serde_json::Value,
}

/// An execution request.
#[derive(Debug, Serialize, ToSchema)]
#[schema(example = json!({"inputs": {
    "beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
             "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009}},
    "contact": {"rk": 1.0}, "release": {"tip_displacement": 0.001},
    "solver": {"time_step": 1e-5, "duration": 0.02}}}))]
pub struct ExecuteRequest {
    /// The process inputs (see the process description): `CantileverInputs` for
    /// `cantilever-impact`, `BundleInputs` for `bundle-dynamics`.
    #[schema(value_type = Object)]
    pub inputs: serde_json::Value,
    /// Job callbacks (OGC API – Processes): the service POSTs the job's status document
    /// to these URIs, signed (`Chocmodal-Signature`, see docs/service.md "Job callbacks").
    /// Only hosts the operator allows (`--callback-allow`) are accepted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subscriber: Option<SubscriberDocument>,
    /// Labels to find the job by (`GET /jobs?label=`): at most 20, each text of 1 to 64
    /// characters without control characters or surrounding spaces, all different.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    #[schema(max_items = 20)]
    pub labels: Vec<String>,
    /// A free-text note (at most 2000 characters), returned with the job's status.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(max_length = 2000)]
    pub note: Option<String>,
}

/// Where a job's outcome and progress are POSTed (each URI optional; absolute `http` or
/// `https` URIs of hosts the operator allows).
#[derive(Debug, Serialize, ToSchema)]
#[schema(as = Subscriber)]
pub struct SubscriberDocument {
    /// Receives the status document once the job is `successful`.
    #[serde(rename = "successUri", skip_serializing_if = "Option::is_none")]
    #[schema(format = "uri", example = "https://hooks.example.com/chocmodal/done")]
    pub success_uri: Option<String>,
    /// Receives it once the job is `failed` or `dismissed`.
    #[serde(rename = "failedUri", skip_serializing_if = "Option::is_none")]
    #[schema(format = "uri")]
    pub failed_uri: Option<String>,
    /// Receives it while the job runs, when its progress changed, at most once per
    /// progress interval (`--callback-progress-seconds`, default 5 s).
    #[serde(rename = "inProgressUri", skip_serializing_if = "Option::is_none")]
    #[schema(format = "uri")]
    pub in_progress_uri: Option<String>,
}

/// A results document: the process's summary figures plus `outputs` links to its
/// histories, `{"outputs": {"tip_displacement": {"href": "/jobs/{id}/results/tip_displacement"}}}`.
#[derive(Debug, Serialize, ToSchema)]
pub struct Results {
    /// Links to the time histories, by output name.
    #[schema(value_type = Object)]
    pub outputs: serde_json::Value,
    /// How right the result is (every process; see docs/accuracy.md).
    pub quality: crate::processes::report::QualityReport,
    /// Where the result comes from: solver version, build, and the SHA-256 of the
    /// canonical JSON of the submitted inputs (docs/service.md "Provenance").
    pub provenance: crate::provenance::Provenance,
}

/// One named column of a history.
#[derive(Debug, Serialize, ToSchema)]
pub struct Series {
    /// Column name, e.g. `numerical`, `reference`, `c0`, `p1`.
    pub name: String,
    /// One value per sample, in the output's unit (m for displacements, N for forces).
    pub values: Vec<f64>,
}

impl Series {
    /// The named columns of a [`History`](crate::processes::History), in order.
    pub fn from_columns(columns: Vec<(String, Vec<f64>)>) -> Vec<Series> {
        columns
            .into_iter()
            .map(|(name, values)| Series { name, values })
            .collect()
    }
}

/// A time history (or a window of it, thinned on request) as JSON.
#[derive(Debug, Serialize, ToSchema)]
pub struct HistoryDocument {
    /// Output name, e.g. `tip_displacement`.
    pub output: String,
    /// Samples in this document.
    pub points: usize,
    /// Samples in the whole history.
    pub total_points: usize,
    /// Whether min/max thinning was applied (`max_points`).
    pub thinned: bool,
    /// What each column is, in the CSV's order: `time` (s), then each series with its
    /// unit and what it measures (`c12`: N, `contact wall–p0 at 0.18 m`).
    pub columns: Vec<crate::processes::Column>,
    /// Sample times (s), increasing.
    pub time: Vec<f64>,
    pub series: Vec<Series>,
}

/// The landing page.
#[derive(Debug, Serialize, ToSchema)]
pub struct LandingPage {
    pub title: &'static str,
    pub description: &'static str,
    pub links: Vec<Link>,
}

/// The conformance classes this service claims.
#[derive(Debug, Serialize, ToSchema)]
pub struct Conformance {
    #[serde(rename = "conformsTo")]
    pub conforms_to: Vec<&'static str>,
}

/// Liveness.
#[derive(Debug, Serialize, ToSchema)]
pub struct Health {
    /// `ok` when the service answers and its database responds.
    pub status: &'static str,
    /// `false` while the storage refuses writes (a write was refused in the last 5 s);
    /// the service stays alive and keeps serving reads.
    pub writable: bool,
    /// Why writes are refused: `SQLITE_FULL`, `disk_full` (PostgreSQL 53100), `ENOSPC`
    /// or `io_error`; absent while writable.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub storage_fault: Option<&'static str>,
}

/// Readiness.
#[derive(Debug, Serialize, ToSchema)]
pub struct Readiness {
    /// `ready`: the database answers and takes writes.
    pub status: &'static str,
}
