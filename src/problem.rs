//! RFC 9457 problem details: the one error format of the HTTP API and the CLI.
//!
//! Type URIs follow OGC API – Processes where it defines one (`no-such-process`,
//! `no-such-job`, `result-not-ready`); chocmodal's own types live under
//! `https://chocmodal.dev/problems/`.

use crate::processes::cost::Excess;
use crate::processes::{FieldError, InvalidInputs, TooCostly};

/// OGC exception type prefix.
pub const OGC_EXCEPTIONS: &str = "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0";
/// chocmodal's own problem type prefix.
pub const CHOCMODAL_PROBLEMS: &str = "https://chocmodal.dev/problems";

/// A problem details document.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Problem {
    /// URI identifying the problem type.
    #[serde(rename = "type")]
    pub kind: String,
    /// Short summary of the problem type.
    pub title: String,
    /// HTTP status code.
    pub status: u16,
    /// Explanation specific to this occurrence.
    pub detail: String,
    /// For invalid inputs: every field at fault, by JSON pointer into the request body.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<FieldError>,
    /// For runs over a cost ceiling: each ceiling exceeded, with the estimate and the
    /// limit (boxed: most problems have none, and problems travel in `Result`s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exceeded: Option<Box<Vec<Excess>>>,
}

impl Problem {
    pub fn new(
        kind: impl Into<String>,
        title: impl Into<String>,
        status: u16,
        detail: impl Into<String>,
    ) -> Self {
        Self {
            kind: kind.into(),
            title: title.into(),
            status,
            detail: detail.into(),
            errors: Vec::new(),
            exceeded: None,
        }
    }

    /// 422: the request parsed as JSON but its inputs are not acceptable.
    pub fn invalid_inputs(invalid: &InvalidInputs) -> Self {
        let count = invalid.0.len();
        let detail = if count == 1 {
            format!("{}: {}", invalid.0[0].pointer, invalid.0[0].detail)
        } else {
            format!("{count} inputs are invalid; see `errors`")
        };
        Self {
            errors: invalid.0.clone(),
            ..Self::new(
                format!("{CHOCMODAL_PROBLEMS}/invalid-inputs"),
                "Invalid inputs",
                422,
                detail,
            )
        }
    }

    /// 400: the body is not JSON, or not the expected envelope.
    pub fn malformed_body(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/malformed-body"),
            "Malformed request body",
            400,
            detail,
        )
    }

    /// 404: no process with this id.
    pub fn no_such_process(id: &str) -> Self {
        Self::new(
            format!("{OGC_EXCEPTIONS}/no-such-process"),
            "No such process",
            404,
            format!("there is no process `{id}`"),
        )
    }

    /// 404: no job with this id.
    pub fn no_such_job(id: &str) -> Self {
        Self::new(
            format!("{OGC_EXCEPTIONS}/no-such-job"),
            "No such job",
            404,
            format!("there is no job `{id}`"),
        )
    }

    /// 404: the job has not finished yet (poll `/jobs/{id}` and retry).
    pub fn result_not_ready(id: &str, status: &str) -> Self {
        Self::new(
            format!("{OGC_EXCEPTIONS}/result-not-ready"),
            "Result not ready",
            404,
            format!("job `{id}` is {status}; its results are not ready yet"),
        )
    }

    /// 404: the job finished without this output.
    pub fn no_such_output(id: &str, output: &str) -> Self {
        Self::new(
            format!("{OGC_EXCEPTIONS}/no-such-output"),
            "No such output",
            404,
            format!("job `{id}` has no output `{output}`"),
        )
    }

    /// 404: the job was dismissed; it has no results.
    pub fn job_dismissed(id: &str) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/job-dismissed"),
            "Job dismissed",
            404,
            format!("job `{id}` was dismissed; it has no results"),
        )
    }

    /// 422 (stored with a failed job): the computation failed deterministically
    /// (divergence, ...); running it again with the same inputs fails again.
    pub fn job_failed(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/job-failed"),
            "Job failed",
            422,
            detail,
        )
    }

    /// 404: no sweep with this id.
    pub fn no_such_sweep(id: &str) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/no-such-sweep"),
            "No such sweep",
            404,
            format!("there is no sweep `{id}`"),
        )
    }

    /// 404: the tenant has no signal with this id.
    pub fn no_such_signal(id: &str) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/no-such-signal"),
            "No such signal",
            404,
            format!("there is no signal `{id}`"),
        )
    }

    /// 422: an uploaded record is refused: `errors` at each sample or member at fault
    /// (`/acceleration/17`; a CSV record's details name the line).
    pub fn invalid_signal(errors: Vec<FieldError>) -> Self {
        let detail = match errors.as_slice() {
            [one] => format!("{}: {}", one.pointer, one.detail),
            many => format!("{} problems with the record; see `errors`", many.len()),
        };
        Self {
            errors,
            ..Self::new(
                format!("{CHOCMODAL_PROBLEMS}/invalid-signal"),
                "Invalid signal",
                422,
                detail,
            )
        }
    }

    /// 409: the signal cannot be deleted while queued or running jobs refer to it.
    pub fn signal_in_use(id: &str, jobs: i64) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/signal-in-use"),
            "Signal in use",
            409,
            format!(
                "signal `{id}` is referred to by {jobs} queued or running job(s); delete it once they \
                 have finished, or dismiss them"
            ),
        )
    }

    /// 422: the sweep would expand into more runs than this service accepts at once.
    pub fn sweep_too_large(runs: u128, limit: usize) -> Self {
        Self {
            errors: vec![FieldError::new(
                "/axes",
                format!(
                    "the axes and samples make {runs} runs; this service accepts at most {limit} per sweep"
                ),
            )],
            ..Self::new(
                format!("{CHOCMODAL_PROBLEMS}/sweep-too-large"),
                "Sweep too large",
                422,
                format!("the sweep has {runs} runs, more than the limit of {limit} (`--max-sweep-runs`)"),
            )
        }
    }

    /// 422: the run's estimated cost is above a ceiling of this service: `errors` points
    /// at the fields that drive the cost, `exceeded` gives the estimates and limits.
    pub fn too_costly(refused: &TooCostly) -> Self {
        let detail = refused
            .exceeded
            .iter()
            .map(|e| {
                format!(
                    "{} {:.3e} is above the limit of {:.3e}",
                    e.quantity, e.estimate, e.limit
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        Self {
            errors: refused.errors.clone(),
            exceeded: Some(Box::new(refused.exceeded.clone())),
            ..Self::new(
                format!("{CHOCMODAL_PROBLEMS}/too-costly"),
                "Run too costly",
                422,
                format!("the estimated cost of this run is above this service's limits: {detail}"),
            )
        }
    }

    /// 429: the tenant already has as many queued jobs as this service accepts.
    pub fn too_many_queued_jobs(queued: i64, adding: usize, limit: u64) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/too-many-queued-jobs"),
            "Too many queued jobs",
            429,
            format!(
                "you have {queued} queued jobs; {adding} more would exceed the limit of {limit} \
                 (`--max-queued-jobs`): retry once some have started, or dismiss some"
            ),
        )
    }

    /// 401: no valid bearer token.
    pub fn unauthorized(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/unauthorized"),
            "Unauthorized",
            401,
            detail,
        )
    }

    /// 503: this process is shutting down and takes no more writes (reads still work).
    pub fn shutting_down() -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/shutting-down"),
            "Shutting down",
            503,
            "this server is shutting down and accepts no more changes; retry after \
             `Retry-After` seconds (another instance, or this one restarted, takes it)",
        )
    }

    /// 503: the server's memory for large responses is in use; retry shortly.
    pub fn server_busy(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/server-busy"),
            "Server busy",
            503,
            detail,
        )
    }

    /// 422 (stored with a failed job): the run went over the wall-time limit and was stopped.
    pub fn job_time_limit(limit: std::time::Duration) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/job-time-limit"),
            "Job over its time limit",
            422,
            format!(
                "the run was stopped after {} s, this service's wall-time limit per job \
                 (`--max-job-seconds`): shorten the run or split it",
                limit.as_secs_f64()
            ),
        )
    }

    /// 400: a query parameter is missing, unknown or out of range.
    pub fn invalid_query(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/invalid-query"),
            "Invalid query parameter",
            400,
            detail,
        )
    }

    /// 406: `Accept` excludes every format of the resource; the detail lists them.
    pub fn not_acceptable(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/not-acceptable"),
            "Not Acceptable",
            406,
            detail,
        )
    }

    /// 413: the request body is larger than the configured limit.
    pub fn payload_too_large(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/payload-too-large"),
            "Request body too large",
            413,
            detail,
        )
    }

    /// 415: the request body is not declared as JSON.
    pub fn unsupported_media_type(detail: impl Into<String>) -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/unsupported-media-type"),
            "Unsupported media type",
            415,
            detail,
        )
    }

    /// 500: something went wrong on the server; the details are in its log, not here.
    pub fn internal() -> Self {
        Self::new(
            format!("{CHOCMODAL_PROBLEMS}/internal"),
            "Internal server error",
            500,
            "the server failed to handle this request; the incident is logged",
        )
    }

    /// Any other HTTP error status, with its standard reason as title.
    pub fn from_status(status: u16, title: &str, detail: impl Into<String>) -> Self {
        let slug: String = title
            .to_ascii_lowercase()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        Self::new(format!("{CHOCMODAL_PROBLEMS}/{slug}"), title, status, detail)
    }

    pub fn to_json_pretty(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|_| self.detail.clone())
    }
}
