//! Windows and peak-keeping thinning of time histories for `GET /jobs/{id}/results/{output}`.
//!
//! Thinning by taking every k-th sample would miss the short contact-force spikes that
//! matter most. Instead the window is cut into equal buckets of consecutive samples and
//! each bucket keeps, for every series, the samples holding its minimum and its maximum,
//! in time order (the "min/max" decimation used by plotting tools). Every extreme of every
//! series in the window therefore survives. With k series a bucket keeps at most 2k
//! samples, so `max_points / (2k)` buckets (at least one) give at most `max_points` rows
//! when `max_points >= 2k`.

use crate::processes::History;

/// The part of `history` with `t_start <= time <= t_end` (either bound optional),
/// thinned to about `max_points` rows when it has more.
pub fn select(
    history: &History,
    t_start: Option<f64>,
    t_end: Option<f64>,
    max_points: Option<usize>,
) -> History {
    let rows = window_rows(&history.time, &history.series, t_start, t_end, max_points);
    History {
        name: history.name.clone(),
        time: rows.iter().map(|&i| history.time[i]).collect(),
        series: pick_rows(&history.series, &rows),
    }
}

/// [`select`] taking `history`: the whole of it when the window holds every sample and
/// needs no thinning (no copy), else the selection.
pub fn select_owned(
    history: History,
    t_start: Option<f64>,
    t_end: Option<f64>,
    max_points: Option<usize>,
) -> History {
    let rows = window_rows(&history.time, &history.series, t_start, t_end, max_points);
    if rows.len() == history.time.len() {
        return history;
    }
    History {
        time: rows.iter().map(|&i| history.time[i]).collect(),
        series: pick_rows(&history.series, &rows),
        name: history.name,
    }
}

/// The rows of the samples at `axis` (times, or frequencies of a spectrum, increasing)
/// with `start <= x <= end` (either bound optional), thinned to about `max_points` rows
/// keeping the extremes of every one of `series` when there are more; ascending.
pub fn window_rows(
    axis: &[f64],
    series: &[(String, Vec<f64>)],
    start: Option<f64>,
    end: Option<f64>,
    max_points: Option<usize>,
) -> Vec<usize> {
    let first = start.map_or(0, |t| axis.partition_point(|&x| x < t));
    let end = end.map_or(axis.len(), |t| axis.partition_point(|&x| x <= t));
    let end = end.max(first);
    match max_points {
        Some(max) if end - first > max => peak_rows(series, first, end, max),
        _ => (first..end).collect(),
    }
}

/// Each of `columns` at `rows` only.
pub fn pick_rows(columns: &[(String, Vec<f64>)], rows: &[usize]) -> Vec<(String, Vec<f64>)> {
    columns
        .iter()
        .map(|(name, values)| (name.clone(), rows.iter().map(|&i| values[i]).collect()))
        .collect()
}

/// How many of the samples at `axis` (times, or frequencies of a spectrum) lie in
/// `start <= x <= end` (either bound optional): the rows of the window before thinning.
pub fn count_in_window(axis: &[f64], start: Option<f64>, end: Option<f64>) -> usize {
    let low = start.unwrap_or(f64::NEG_INFINITY);
    let high = end.unwrap_or(f64::INFINITY);
    axis.iter().filter(|x| (low..=high).contains(*x)).count()
}

/// The columns of `history` named in `names` (comma-separated, in the order given), or
/// all of them when `names` is `None`; `Err` names a column that does not exist.
pub fn pick_series(history: History, names: Option<&str>) -> Result<History, String> {
    let Some(names) = names else {
        return Ok(history);
    };
    let mut picked = Vec::new();
    for name in names.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        let (_, values) = history.series.iter().find(|(n, _)| n == name).ok_or_else(|| {
            let available: Vec<&str> = history.series.iter().map(|(n, _)| n.as_str()).collect();
            format!(
                "`series`: `{}` has no series `{name}` (it has {})",
                history.name,
                available.join(", ")
            )
        })?;
        picked.push((name.to_owned(), values.clone()));
    }
    if picked.is_empty() {
        return Err("`series` must name at least one series".into());
    }
    Ok(History {
        name: history.name,
        time: history.time,
        series: picked,
    })
}

/// Row indices in `first..end` keeping each series' min and max per bucket, ascending.
fn peak_rows(series: &[(String, Vec<f64>)], first: usize, end: usize, max_points: usize) -> Vec<usize> {
    let per_bucket = 2 * series.len().max(1);
    let buckets = (max_points / per_bucket).max(1);
    let len = end - first;
    let mut rows = Vec::with_capacity(buckets * per_bucket);
    for b in 0..buckets {
        let lo = first + b * len / buckets;
        let hi = first + (b + 1) * len / buckets;
        if lo >= hi {
            continue;
        }
        let start = rows.len();
        if series.is_empty() {
            rows.extend([lo, hi - 1]);
        }
        for (_, values) in series {
            let (mut min_at, mut max_at) = (lo, lo);
            for i in lo..hi {
                // NaN never wins a comparison, so it is never picked as an extreme.
                if values[i] < values[min_at] || values[min_at].is_nan() {
                    min_at = i;
                }
                if values[i] > values[max_at] || values[max_at].is_nan() {
                    max_at = i;
                }
            }
            rows.extend([min_at, max_at]);
        }
        rows[start..].sort_unstable();
        let mut kept = start;
        for i in start..rows.len() {
            if i == start || rows[i] != rows[kept - 1] {
                rows[kept] = rows[i];
                kept += 1;
            }
        }
        rows.truncate(kept);
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spiky(samples: usize) -> History {
        let time: Vec<f64> = (0..samples).map(|i| i as f64).collect();
        let mut force: Vec<f64> = time.iter().map(|t| (t * 0.01).sin()).collect();
        // One-sample impact spikes, off any bucket boundary.
        force[samples * 43 / 100 + 1] = 50.0;
        force[samples * 7 / 100 + 3] = -20.0;
        History {
            name: "contact_force".into(),
            series: vec![("numerical".into(), force)],
            time,
        }
    }

    #[test]
    fn thinning_keeps_every_extreme_and_the_time_order() {
        let history = spiky(10_000);
        let thin = select(&history, None, None, Some(100));
        assert!(thin.time.len() <= 100, "{} rows", thin.time.len());
        assert!(thin.time.windows(2).all(|w| w[0] < w[1]));
        let values = &thin.series[0].1;
        assert!(values.contains(&50.0) && values.contains(&-20.0));
    }

    #[test]
    fn a_window_keeps_the_samples_between_its_bounds_inclusive() {
        let history = spiky(100);
        let window = select(&history, Some(10.0), Some(20.0), None);
        assert_eq!(window.time.first(), Some(&10.0));
        assert_eq!(window.time.last(), Some(&20.0));
        assert_eq!(window.time.len(), 11);
    }

    #[test]
    fn short_windows_are_not_thinned() {
        let history = spiky(1_000);
        let window = select(&history, Some(0.0), Some(49.0), Some(100));
        assert_eq!(window.time.len(), 50);
    }

    #[test]
    fn series_are_picked_by_name_in_the_order_given() {
        let mut history = spiky(10);
        history.series.push(("reference".into(), vec![1.0; 10]));
        let picked = pick_series(history.clone(), Some("reference,numerical")).unwrap();
        let names: Vec<&str> = picked.series.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["reference", "numerical"]);
        assert_eq!(picked.series[0].1, vec![1.0; 10]);
        assert_eq!(pick_series(history.clone(), None).unwrap().series.len(), 2);
        let error = pick_series(history.clone(), Some("c7")).unwrap_err();
        assert!(error.contains("numerical, reference"), "{error}");
        assert!(pick_series(history, Some(",")).is_err());
    }

    #[test]
    fn an_inverted_window_is_empty() {
        let history = spiky(100);
        assert!(select(&history, Some(50.0), Some(10.0), None).time.is_empty());
    }
}
