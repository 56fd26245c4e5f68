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
}

/// A results document: the process's summary figures plus `outputs` links to its
/// histories, `{"outputs": {"tip_displacement": {"href": "/jobs/{id}/results/tip_displacement"}}}`.
#[derive(Debug, Serialize, ToSchema)]
pub struct Results {
    /// Links to the time histories, by output name.
    #[schema(value_type = Object)]
    pub outputs: serde_json::Value,
    /// How right the result is (every process; see docs/accuracy.md).
    pub quality: QualityReport,
}

/// The `quality` section of every results document: how right the result is.
#[derive(Debug, Serialize, ToSchema)]
pub struct QualityReport {
    /// |kinetic + strain + contact + dissipated − external work − initial| over the largest
    /// energy involved, at the end of the run (dimensionless).
    pub energy_residual: f64,
    /// Time step over the critical step with every contact closed (dimensionless).
    pub time_step_over_critical: f64,
    /// 2π / (ω_max Δt): steps per period of the fastest motion with the contacts closed,
    /// the shortest contact period resolved. `auto` uses 50 at the default tolerance.
    pub steps_per_contact_period: f64,
    /// The relative tolerance the verdict was judged against (`solver.tolerance`).
    pub tolerance: f64,
    /// What set the step: `given` (a fixed step), or for `auto` `fastest_motion`,
    /// `excitation` or `stability`.
    #[schema(pattern = "^(given|fastest_motion|excitation|stability)$")]
    pub time_step_limited_by: String,
    /// The run repeated at Δt/2 (`solver.check: "step_halving"`); null with `"none"`.
    pub step_halving: Option<StepHalvingReport>,
    /// `good`: within the tolerance by every measure; `doubtful`: some measure outside it,
    /// none by far; `poor`: do not use the numbers (energy residual > 10 × tolerance, an
    /// estimated peak error > 20 × tolerance, or fewer than 8 steps per contact period).
    #[schema(pattern = "^(good|doubtful|poor)$")]
    pub verdict: String,
    /// One sentence per measure outside the tolerance (empty when `good`).
    pub reasons: Vec<String>,
}

/// The step-halving check: the whole run repeated at half the step.
#[derive(Debug, Serialize, ToSchema)]
pub struct StepHalvingReport {
    /// Step of the repeated run (s).
    pub time_step: f64,
    /// |F(Δt) − F(Δt/2)| / F(Δt/2) of the peak contact force over all contacts and steps.
    pub peak_force_change: f64,
    /// The same for the peak |deflection| at the output heights.
    pub peak_displacement_change: f64,
    /// |n(Δt) − n(Δt/2)| / max(n(Δt/2), 1) of the total impact count.
    pub impact_count_change: f64,
    /// Estimated relative error of the reported peak force: 2ᵖ/(2ᵖ − 1) × its change (4/3
    /// for central difference, Richardson).
    pub estimated_peak_force_error: f64,
    /// Estimated relative error of the reported peak deflection.
    pub estimated_peak_displacement_error: f64,
    /// Steps taken by the check.
    pub steps: u64,
    /// Wall time of the check (s).
    pub seconds: f64,
    /// Steps of the check over steps of the run (2).
    pub relative_cost: f64,
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
}
