//! `/sweeps/{sweepId}/statistics...`: a sweep's statistics for design, as long tables
//! (JSON or CSV): the run-wide figures, each contact's and each pin's figures, and how a
//! figure's quantile and Wilks bound converge as runs are added; each at the coverage
//! and confidence the query asks for ([`crate::sweep::figures`], [`crate::sweep::items`]).

use axum::extract::{Extension, Path, Query, State};
use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use super::negotiation::Format;
use super::sweep_models::{RankRuns, RunsNeeded, SweepStatistics, SweepStatisticsKind};
use super::sweeps::{find, run_record, sweep_status};
use crate::problem::Problem;
use crate::service::auth::Tenant;
use crate::sweep::figures::{self, BoundRequest, ParameterFault, StatisticsTable};
use crate::sweep::items::{DEFAULT_CEILING, ItemList, ItemValues, TooManyValues};
use crate::sweep::table::RunRecord;
use crate::sweep::{Design, SweepDefinition};

/// Runs read per page from the store: their results documents are in memory together.
const PAGE: i64 = 8;

/// What the statistics routes take from their query.
#[derive(Debug, Default)]
struct StatisticsQuery {
    coverage: Option<String>,
    confidence: Option<String>,
    figures: Vec<String>,
}

/// The most ranks `/sweeps/runs-needed` lists.
const MAX_RANKS: usize = 100;

type QueryResult = Result<Query<Vec<(String, String)>>, axum::extract::rejection::QueryRejection>;

/// The query's parameters; `figure` only where `takes_figure`; `f`/`format` are the
/// negotiator's; anything else refused, named.
fn parse_query(query: QueryResult, takes_figure: bool) -> Result<(StatisticsQuery, BoundRequest), Problem> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let mut parsed = StatisticsQuery::default();
    for (key, value) in pairs {
        match key.as_str() {
            "coverage" => parsed.coverage = Some(value),
            "confidence" => parsed.confidence = Some(value),
            "figure" if takes_figure => {
                if value.is_empty() {
                    return Err(Problem::invalid_query(
                        "`figure` must name a figure, not be empty",
                    ));
                }
                parsed.figures.push(value)
            }
            "f" | "format" => {}
            other => {
                let expected = if takes_figure {
                    "coverage, confidence, figure, format"
                } else {
                    "coverage, confidence, format"
                };
                return Err(Problem::invalid_query(format!(
                    "unknown query parameter `{other}` (expected {expected})"
                )));
            }
        }
    }
    let request =
        BoundRequest::parse(parsed.coverage.as_deref(), parsed.confidence.as_deref()).map_err(fault)?;
    Ok((parsed, request))
}

fn fault(fault: ParameterFault) -> Problem {
    Problem::invalid_query(fault.to_string())
}

/// A statistics table as computed, to serve.
struct Computed {
    kind: SweepStatisticsKind,
    request: BoundRequest,
    table: StatisticsTable,
}

/// The document or CSV of a statistics table, with an `ETag`.
async fn respond(
    state: &AppState,
    tenant: &Tenant,
    sweep_id: &str,
    Computed { kind, request, table }: Computed,
    headers: &HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let body = if format == Format::Csv {
        table.to_csv().into_bytes()
    } else {
        let record = find(state, tenant, sweep_id).await?;
        let status = sweep_status(state, tenant, &record).await?;
        let document = SweepStatistics::new(&record, status.status, kind, request, table);
        serde_json::to_vec(&document).map_err(|e| ApiError::Internal(e.to_string()))?
    };
    let mut extra = HeaderMap::new();
    extra.insert(header::VARY, HeaderValue::from_static("accept"));
    Ok(tagged(headers, format.content_type(), body, extra))
}

/// The sweep's definition and its results table (every ended run), read off the runtime.
async fn definition_and_table(
    state: &AppState,
    tenant: &Tenant,
    sweep_id: &str,
) -> Result<(SweepDefinition, crate::sweep::table::Table), ApiError> {
    let record = find(state, tenant, sweep_id).await?;
    let runs = state.queue.ended_sweep_runs(tenant.as_str(), sweep_id).await?;
    let process = state.registry.get(&record.process_id);
    tokio::task::spawn_blocking(move || {
        let definition = SweepDefinition::from_stored(&record.definition).map_err(|e| {
            ApiError::Internal(format!("sweep {}: stored definition unreadable: {e}", record.id))
        })?;
        let records: Vec<RunRecord> = runs
            .into_iter()
            .map(|run| run_record(run, process.as_deref()))
            .collect();
        let table = definition.table(&records);
        Ok::<_, ApiError>((definition, table))
    })
    .await
    .map_err(|e| ApiError::Internal(format!("reading sweep results panicked: {e}")))?
}

/// The random axes whose values are figures: a grid's axes are its cells.
fn numeric_axes(definition: &SweepDefinition) -> Vec<String> {
    match definition.design {
        Design::Grid => Vec::new(),
        Design::MonteCarlo | Design::LatinHypercube => definition.random_pointers(),
    }
}

/// A sweep's run-wide statistics
///
/// One row per grid cell of the list axes and figure: every numeric column of the
/// results table (random axes and metrics, seeds left out) over the cell's successful
/// runs: `runs` (in the cell), `count` (with a value), `mean`, `std`, `min`, `max`,
/// `q05`, `q50`, `q95`, the empirical `quantile` at `coverage`, the one-sided upper
/// `bound` of Wilks at `coverage`/`confidence` (the `bound_rank`-th largest value; null
/// with too few runs) and `runs_needed` (the fewest runs for that rank, rank 1 while
/// there is none). The same rows in CSV (`format=csv` or `Accept: text/csv`).
#[utoipa::path(get, path = "/sweeps/{sweepId}/statistics", operation_id = "getSweepStatistics", tag = "Sweeps",
    params(("sweepId" = String, Path, description = "Sweep id"),
        ("coverage" = Option<f64>, Query, description = "The quantile bounded, p in (0, 1) (default 0.95)"),
        ("confidence" = Option<f64>, Query, description = "The confidence of the bound, γ in (0, 1) (default 0.95)"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON); `f` is an alias")),
    responses(
        (status = 200, description = "The statistics table",
            content((SweepStatistics = "application/json"), (String = "text/csv")), headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "An invalid query parameter, named (`invalid-query`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such sweep (`no-such-sweep`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes both JSON and CSV (`not-acceptable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn statistics(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(sweep_id): Path<String>,
    query: QueryResult,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let (_, request) = parse_query(query, false)?;
    let (definition, table) = definition_and_table(&state, &tenant, &sweep_id).await?;
    let statistics = tokio::task::spawn_blocking(move || {
        figures::run_statistics(
            &table,
            &definition.list_pointers(),
            &numeric_axes(&definition),
            request,
        )
    })
    .await
    .map_err(|e| ApiError::Internal(format!("sweep statistics panicked: {e}")))?;
    respond(
        &state,
        &tenant,
        &sweep_id,
        Computed {
            kind: SweepStatisticsKind::Runs,
            request,
            table: statistics,
        },
        &headers,
        format,
    )
    .await
}

/// How a figure converges as runs are added
///
/// For the run-wide `figure` (a numeric column of the results table), one row per
/// successful run of each grid cell, in the order the runs were drawn (`sample` 0, 1,
/// ...; `run` its number in the sweep): its `value`, and over the cell's first `runs`
/// values the empirical `quantile` at `coverage` and the upper `bound` of Wilks at
/// `coverage`/`confidence` with its `bound_rank` (null until enough runs). A campaign has
/// converged when both level off.
#[utoipa::path(get, path = "/sweeps/{sweepId}/statistics/convergence", operation_id = "getSweepConvergence", tag = "Sweeps",
    params(("sweepId" = String, Path, description = "Sweep id"),
        ("figure" = String, Query, description = "A numeric column of the sweep's results table, e.g. `max_contact_force.force`"),
        ("coverage" = Option<f64>, Query, description = "The quantile followed, p in (0, 1) (default 0.95)"),
        ("confidence" = Option<f64>, Query, description = "The confidence of the bound, γ in (0, 1) (default 0.95)"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON); `f` is an alias")),
    responses(
        (status = 200, description = "The convergence table",
            content((SweepStatistics = "application/json"), (String = "text/csv")), headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "A missing or unknown `figure`, or another invalid query parameter, named (`invalid-query`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such sweep (`no-such-sweep`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes both JSON and CSV (`not-acceptable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn convergence(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(sweep_id): Path<String>,
    query: QueryResult,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let (query, request) = parse_query(query, true)?;
    let figure = match query.figures.as_slice() {
        [figure] => figure.clone(),
        [] => {
            return Err(Problem::invalid_query(
                "`figure` is required: a numeric column of the results table",
            )
            .into());
        }
        _ => return Err(Problem::invalid_query("`figure` names one column, given more than once").into()),
    };
    let (definition, table) = definition_and_table(&state, &tenant, &sweep_id).await?;
    let track = tokio::task::spawn_blocking(move || {
        figures::convergence(&table, &definition.list_pointers(), &figure, request)
    })
    .await
    .map_err(|e| ApiError::Internal(format!("sweep convergence panicked: {e}")))?
    .map_err(fault)?;
    respond(
        &state,
        &tenant,
        &sweep_id,
        Computed {
            kind: SweepStatisticsKind::Convergence,
            request,
            table: track,
        },
        &headers,
        format,
    )
    .await
}

/// Each contact's (or pin's) figures over the sweep's successful runs, read a page of
/// runs at a time.
async fn item_statistics(
    state: &AppState,
    tenant: &Tenant,
    sweep_id: &str,
    list: ItemList,
    query: QueryResult,
) -> Result<(BoundRequest, StatisticsTable), ApiError> {
    let (query, request) = parse_query(query, true)?;
    let record = find(state, tenant, sweep_id).await?;
    let definition = SweepDefinition::from_stored(&record.definition)
        .map_err(|e| ApiError::Internal(format!("sweep {}: stored definition unreadable: {e}", record.id)))?;
    let wanted = (!query.figures.is_empty()).then_some(query.figures);
    let mut values = ItemValues::new(list, definition.list_pointers(), wanted, DEFAULT_CEILING);
    let mut after = -1;
    loop {
        let page = state
            .queue
            .successful_sweep_runs_after(tenant.as_str(), sweep_id, after, PAGE)
            .await?;
        let Some(last) = page.last() else { break };
        after = last.run;
        // Parsing results documents (megabytes for a big bundle) is CPU work.
        values = tokio::task::spawn_blocking(move || {
            for run in page {
                let inputs: serde_json::Value = serde_json::from_str(&run.inputs).unwrap_or_default();
                let Some(document) = run
                    .results
                    .as_deref()
                    .and_then(|text| serde_json::from_str::<serde_json::Value>(text).ok())
                else {
                    continue;
                };
                values.add(&inputs, &document)?;
            }
            Ok::<_, TooManyValues>(values)
        })
        .await
        .map_err(|e| ApiError::Internal(format!("sweep item statistics panicked: {e}")))?
        .map_err(|refused| {
            Problem::invalid_query(format!(
                "the {} statistics of this sweep would keep more than {} values (reached {}); \
                 name the figures wanted with `figure` (repeatable), e.g. `figure={}`; its figures: {}",
                list.key(),
                refused.ceiling,
                refused.values,
                refused.figures.first().map_or("max_force", String::as_str),
                refused.figures.join(", ")
            ))
        })?;
    }
    if let Some((unknown, seen)) = values.unknown_figures() {
        return Err(Problem::invalid_query(format!(
            "`figure` {} is no numeric member of this sweep's {}; its figures: {}",
            unknown.join(", "),
            list.member(),
            seen.join(", ")
        ))
        .into());
    }
    let table = tokio::task::spawn_blocking(move || values.table(request))
        .await
        .map_err(|e| ApiError::Internal(format!("sweep item statistics panicked: {e}")))?;
    Ok((request, table))
}

/// Each contact's statistics over a sweep
///
/// For bundles (`bundle-dynamics`, `hex-bundle-dynamics`): one row per grid cell of the
/// list axes, contact (`contact`: the index k of `c<k>` and of the results' `contacts`)
/// and figure (each numeric member of the contact's entry, dotted as in
/// `/jobs/{jobId}/results/contacts`: `max_force` (N), `impacts`, `contact_time` (s),
/// `impulse` (N·s), `utilisation` where allowables are set, `impact_statistics.*`, `gap`
/// (m); members naming bodies left out) over the cell's successful runs, with the same
/// statistics as `/sweeps/{sweepId}/statistics`. The runs' documents are read a few at a
/// time; at most 8 Mi values are kept (64 MiB): beyond, 400 asking for fewer `figure`s.
/// A process without contacts: no rows.
#[utoipa::path(get, path = "/sweeps/{sweepId}/statistics/contacts", operation_id = "getSweepContactStatistics", tag = "Sweeps",
    params(("sweepId" = String, Path, description = "Sweep id"),
        ("figure" = Option<Vec<String>>, Query, explode = true, description = "Only this figure (repeatable), e.g. `max_force`; default every figure"),
        ("coverage" = Option<f64>, Query, description = "The quantile bounded, p in (0, 1) (default 0.95)"),
        ("confidence" = Option<f64>, Query, description = "The confidence of the bound, γ in (0, 1) (default 0.95)"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON); `f` is an alias")),
    responses(
        (status = 200, description = "The per-contact statistics table",
            content((SweepStatistics = "application/json"), (String = "text/csv")), headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "An invalid or unknown query parameter or figure, or more values than kept (`invalid-query`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such sweep (`no-such-sweep`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes both JSON and CSV (`not-acceptable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn contacts(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(sweep_id): Path<String>,
    query: QueryResult,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let (request, table) = item_statistics(&state, &tenant, &sweep_id, ItemList::Contacts, query).await?;
    respond(
        &state,
        &tenant,
        &sweep_id,
        Computed {
            kind: SweepStatisticsKind::Contacts,
            request,
            table,
        },
        &headers,
        format,
    )
    .await
}

/// Each pin's statistics over a sweep
///
/// As `/sweeps/{sweepId}/statistics/contacts`, for the results' `pins`: one row per grid
/// cell, pin (`pin`, the p of `p<p>`) and figure (each numeric member of the pin's entry:
/// `max_abs_deflection` (m) in the row, `deflection.max_deflection` (m) and
/// `x.max_abs_deflection`, `y.max_abs_deflection` in the hexagonal bundle,
/// `bending.moment` (N·m), `bending.stress` (Pa), `bending.strain`, `utilisation`,
/// `stress_utilisation`, `contact_utilisation` where allowables are set; the heights and
/// times where they occurred).
#[utoipa::path(get, path = "/sweeps/{sweepId}/statistics/pins", operation_id = "getSweepPinStatistics", tag = "Sweeps",
    params(("sweepId" = String, Path, description = "Sweep id"),
        ("figure" = Option<Vec<String>>, Query, explode = true, description = "Only this figure (repeatable), e.g. `bending.stress`; default every figure"),
        ("coverage" = Option<f64>, Query, description = "The quantile bounded, p in (0, 1) (default 0.95)"),
        ("confidence" = Option<f64>, Query, description = "The confidence of the bound, γ in (0, 1) (default 0.95)"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON); `f` is an alias")),
    responses(
        (status = 200, description = "The per-pin statistics table",
            content((SweepStatistics = "application/json"), (String = "text/csv")), headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "An invalid or unknown query parameter or figure, or more values than kept (`invalid-query`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such sweep (`no-such-sweep`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes both JSON and CSV (`not-acceptable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn pins(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(sweep_id): Path<String>,
    query: QueryResult,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let (request, table) = item_statistics(&state, &tenant, &sweep_id, ItemList::Pins, query).await?;
    respond(
        &state,
        &tenant,
        &sweep_id,
        Computed {
            kind: SweepStatisticsKind::Pins,
            request,
            table,
        },
        &headers,
        format,
    )
    .await
}

/// The query of `/sweeps/runs-needed`: `coverage`, `confidence` and `ranks`.
fn parse_planning(query: QueryResult) -> Result<(BoundRequest, usize), Problem> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let (mut coverage, mut confidence, mut ranks) = (None, None, 3);
    for (key, value) in pairs {
        match key.as_str() {
            "coverage" => coverage = Some(value),
            "confidence" => confidence = Some(value),
            "ranks" => {
                ranks = value
                    .parse()
                    .ok()
                    .filter(|r| (1..=MAX_RANKS).contains(r))
                    .ok_or_else(|| {
                        Problem::invalid_query(format!(
                            "`ranks` must be a whole number from 1 to {MAX_RANKS}, not `{value}`"
                        ))
                    })?
            }
            "f" | "format" => {}
            other => {
                return Err(Problem::invalid_query(format!(
                    "unknown query parameter `{other}` (expected coverage, confidence, ranks)"
                )));
            }
        }
    }
    let request = BoundRequest::parse(coverage.as_deref(), confidence.as_deref()).map_err(fault)?;
    Ok((request, ranks))
}

/// How many runs a bound needs
///
/// Planning a Monte Carlo campaign before any run: for the one-sided upper bound of
/// Wilks on the `coverage`-quantile with `confidence`, the fewest independent runs whose
/// largest value is the bound (rank 1: ⌈ln(1 − γ) / ln p⌉, 59 at 95 %/95 %), whose
/// second largest is (93), and so on for `ranks` ranks. A bound of a higher rank is
/// tighter (nearer the quantile) and needs more runs.
#[utoipa::path(get, path = "/sweeps/runs-needed", operation_id = "getRunsNeeded", tag = "Sweeps",
    params(
        ("coverage" = Option<f64>, Query, description = "The quantile bounded, p in (0, 1) (default 0.95)"),
        ("confidence" = Option<f64>, Query, description = "The confidence of the bound, γ in (0, 1) (default 0.95)"),
        ("ranks" = Option<usize>, Query, description = "How many ranks from the top to list, 1 to 100 (default 3)", minimum = 1, maximum = 100)),
    responses(
        (status = 200, description = "The runs each rank needs", body = RunsNeeded),
        (status = 400, description = "An invalid query parameter, named (`invalid-query`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn runs_needed(query: QueryResult) -> Result<Response, ApiError> {
    let (request, ranks) = parse_planning(query)?;
    let document = RunsNeeded {
        coverage: request.coverage,
        confidence: request.confidence,
        runs_needed: (1..=ranks)
            .map(|rank| RankRuns {
                rank,
                runs: request.runs_needed(rank),
            })
            .collect(),
    };
    Ok(axum::Json(document).into_response())
}
