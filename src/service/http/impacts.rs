//! `/jobs/{jobId}/results/impacts`: the per-impact table of a run, one row per impact
//! sorted by start time, as CSV or JSON, filtered by contact and paged.

use axum::extract::{Extension, Path, State};
use axum::http::{HeaderMap, HeaderName, HeaderValue};
use axum::response::Response;

use super::AppState;
use super::error::ApiError;
use super::extract::ApiQuery;
use super::history_view::{Format, respond_with_headers};
use crate::physics::impacts::Impact;
use crate::problem::Problem;
use crate::processes::impact_report::{self, TABLE};
use crate::service::auth::Tenant;
use crate::service::store;

/// Query of `GET /jobs/{jobId}/results/impacts`.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct ImpactsQuery {
    /// Chosen by the service's negotiator (`f` is an alias): `csv` or `json`; without
    /// it, the one `Accept` prefers (q-values honoured), else JSON.
    #[param(pattern = "^(csv|json)$")]
    #[serde(alias = "f")]
    pub format: Option<String>,
    /// Only these contacts, comma-separated indices (e.g. `3,17`); default: all.
    pub contact: Option<String>,
    /// Rows to skip (after the filter); default 0.
    pub offset: Option<usize>,
    /// Rows to return at most (1 or more); default and ceiling: the service's
    /// `--max-history-points`.
    #[param(minimum = 1)]
    pub limit: Option<usize>,
}

/// One page of the per-impact table.
#[derive(Debug, serde::Serialize, utoipa::ToSchema)]
pub struct ImpactPage {
    /// `impacts`.
    pub output: String,
    /// Rows matching the filter, over every page.
    pub total_rows: usize,
    /// Index of this page's first row among them.
    pub offset: usize,
    /// The rows (contact, start s, peak_time s, peak_force N, impulse N·s, duration s,
    /// approach_velocity m/s, rebounds, dissipated J, energy J).
    pub rows: Vec<Impact>,
    /// Whether the table left impacts out (past `output.impacts.max_rows`): it then
    /// holds the largest by peak force, each contact's fair share first.
    pub truncated: bool,
    /// Every impact of the run, tabulated or not, and the rows of the whole table
    /// (whatever the filter); equal unless `truncated`.
    pub impacts: u64,
    pub tabulated: u64,
    /// The query of the next page, when there is one (`offset=…&limit=…`, plus the filter).
    pub next: Option<String>,
}

/// The per-impact table
///
/// Every impact of the run's contacts (as `output.impacts` counted them: force
/// threshold, rest time), sorted by start time then contact: CSV
/// `contact,start,peak_time,peak_force,impulse,duration,approach_velocity,rebounds,dissipated,energy`
/// or JSON pages. `contact` filters, `offset` and `limit` page. The table holds every
/// impact up to `output.impacts.max_rows`; past it, each contact's ⌊max_rows / contacts⌋
/// largest impacts by peak force, then the largest of the others, and it says so: the
/// `Impact-Table` header (`complete, impacts=6, tabulated=6` or `truncated,
/// impacts=2034117, tabulated=100000`), the page's `truncated`, `impacts` and
/// `tabulated`, and in CSV five more columns `truncated,impacts,tabulated,
/// contact_impacts,contact_tabulated` (the whole table's counts, the row's contact's).
#[utoipa::path(get, path = "/jobs/{jobId}/results/impacts", operation_id = "getResultImpacts", tag = "Results",
    params(("jobId" = String, Path, description = "Job id"), ImpactsQuery),
    responses(
        (status = 200, description = "Rows of the per-impact table",
            content((ImpactPage = "application/json"), (String = "text/csv")),
            headers(("ETag" = String),
                ("Impact-Table" = String, description = "`complete` or `truncated`, then the run's `impacts` and the table's \
                  `tabulated` rows: `truncated, impacts=2034117, tabulated=100000` (RFC 8941 dictionary)"))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such job, results not ready, or a job without a table",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn impacts(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    ApiQuery(query): ApiQuery<ImpactsQuery>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let contacts = parse_contacts(query.contact.as_deref())?;
    if query.limit == Some(0) {
        return Err(Problem::invalid_query("`limit` must be at least 1").into());
    }
    let limit = query.limit.unwrap_or(usize::MAX).min(state.max_history_points);
    let offset = query.offset.unwrap_or(0);
    let filter = query.contact.clone();
    respond_with_headers(
        &state,
        &tenant,
        &job_id,
        TABLE,
        &headers,
        format,
        "rendering the impacts",
        move |stored, _| {
            let history = store::decode(stored).map_err(|e| ApiError::Internal(e.to_string()))?;
            let table = impact_report::read_table(&history)
                .ok_or_else(|| ApiError::Internal("the stored impacts are not a table".into()))?;
            let mut extra = HeaderMap::new();
            let value = HeaderValue::from_str(&impact_report::header_value(&table))
                .map_err(|e| ApiError::Internal(e.to_string()))?;
            extra.insert(HeaderName::from_static(impact_report::HEADER), value);
            let selected: Vec<Impact> = table
                .rows
                .iter()
                .filter(|r| contacts.as_ref().is_none_or(|c| c.contains(&r.contact)))
                .copied()
                .collect();
            let page: Vec<Impact> = selected.iter().skip(offset).take(limit).copied().collect();
            if format == Format::Csv {
                return Ok((impact_report::table_csv(&table, &page).into_bytes(), extra));
            }
            let end = offset.saturating_add(page.len());
            let next = (end < selected.len()).then(|| {
                let filter = filter.map(|f| format!("&contact={f}")).unwrap_or_default();
                format!("offset={end}&limit={}{filter}", page.len().max(1))
            });
            let document = ImpactPage {
                output: TABLE.to_owned(),
                total_rows: selected.len(),
                offset,
                rows: page,
                truncated: table.truncation.is_some(),
                impacts: table.impacts(),
                tabulated: table.tabulated(),
                next,
            };
            let body = serde_json::to_vec(&document).map_err(|e| ApiError::Internal(e.to_string()))?;
            Ok((body, extra))
        },
    )
    .await
}

/// The `contact` filter: comma-separated indices; 400 on anything else.
fn parse_contacts(text: Option<&str>) -> Result<Option<Vec<usize>>, ApiError> {
    let Some(text) = text else {
        return Ok(None);
    };
    text.split(',')
        .map(|part| {
            part.trim().parse::<usize>().map_err(|_| {
                Problem::invalid_query(format!(
                    "`contact` must list contact indices separated by commas (0, 1, …), not `{part}`"
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
        .map_err(Into::into)
}
