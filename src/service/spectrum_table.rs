//! The spectrum of a stored history as a table: one frequency column and the power
//! spectral density Γ(f) of each series (the periodogram of `physics::spectrum`), for
//! `GET /jobs/{jobId}/results/{output}/spectrum`. Windowed and thinned like a history
//! (`thinning`), written as CSV with a `frequency,<series...>` header.

use crate::physics::spectrum::periodogram;
use crate::processes::History;
use crate::service::thinning;

/// The one-sided power spectral density of each series of a history.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumTable {
    /// Output name, e.g. `tip_displacement`.
    pub name: String,
    /// Bin frequencies f_k = k/(nΔt) (Hz), increasing.
    pub frequency: Vec<f64>,
    /// Γ(f) of each series, named as in the history (the output's unit² per Hz),
    /// each `frequency.len()` long.
    pub series: Vec<(String, Vec<f64>)>,
}

impl SpectrumTable {
    /// The periodogram of every series of `history`, sampled every `sample_interval`
    /// (s); `Err` names the series that has none (too short, not finite, ...).
    pub fn of(history: &History, sample_interval: f64) -> Result<Self, String> {
        let mut frequency = Vec::new();
        let mut series = Vec::with_capacity(history.series.len());
        for (name, values) in &history.series {
            let psd = periodogram(values, sample_interval)
                .map_err(|e| format!("`{}`, series `{name}`: {e}", history.name))?;
            // Every series has the same length, hence the same bins.
            frequency = psd.frequencies;
            series.push((name.clone(), psd.power_density));
        }
        Ok(Self {
            name: history.name.clone(),
            frequency,
            series,
        })
    }

    /// Frequency (Hz) of the bin where the first two series differ most, |Γ_a − Γ_b|
    /// largest; `None` with fewer than two series or no bin.
    pub fn largest_difference(&self) -> Option<f64> {
        let [(_, gamma_a), (_, gamma_b), ..] = self.series.as_slice() else {
            return None;
        };
        let difference = |i: usize| (gamma_a[i] - gamma_b[i]).abs();
        (0..gamma_a.len())
            .max_by(|&i, &j| difference(i).total_cmp(&difference(j)))
            .and_then(|worst| self.frequency.get(worst).copied())
    }

    /// The bins with `f_min <= f <= f_max` (Hz, either bound optional), thinned to
    /// about `max_points` rows keeping every series' peaks when there are more.
    pub fn select(&self, f_min: Option<f64>, f_max: Option<f64>, max_points: Option<usize>) -> Self {
        let rows = thinning::window_rows(&self.frequency, &self.series, f_min, f_max, max_points);
        Self {
            name: self.name.clone(),
            frequency: rows.iter().map(|&i| self.frequency[i]).collect(),
            series: thinning::pick_rows(&self.series, &rows),
        }
    }

    /// CSV text with a `frequency,<series...>` header, full precision (as histories).
    pub fn to_csv(&self) -> String {
        crate::processes::columns_csv("frequency", &self.frequency, &self.series)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn history() -> History {
        let time: Vec<f64> = (0..64).map(|i| i as f64 * 1e-3).collect();
        let sine = time
            .iter()
            .map(|t| (2.0 * std::f64::consts::PI * 125.0 * t).sin())
            .collect();
        History {
            name: "tip_displacement".into(),
            time,
            series: vec![("numerical".into(), sine), ("reference".into(), vec![0.25; 64])],
        }
    }

    #[test]
    fn the_csv_is_a_history_csv_with_a_frequency_column() {
        let spectrum = SpectrumTable::of(&history(), 1e-3).unwrap();
        // The same numbers written as a history's would be, under another first header.
        let as_history = History {
            name: spectrum.name.clone(),
            time: spectrum.frequency.clone(),
            series: spectrum.series.clone(),
        }
        .to_csv();
        let csv = spectrum.to_csv();
        assert_eq!(csv.lines().next(), Some("frequency,numerical,reference"));
        assert_eq!(
            csv.split_once('\n').unwrap().1,
            as_history.split_once('\n').unwrap().1
        );
    }

    #[test]
    fn bins_are_k_over_n_dt_and_the_peak_is_at_the_sine() {
        let spectrum = SpectrumTable::of(&history(), 1e-3).unwrap();
        assert_eq!(spectrum.frequency.len(), 33);
        let expected = 8.0 / (64.0 * 1e-3);
        assert!(
            (spectrum.frequency[8] - expected).abs() < 1e-9,
            "f_8 = {} Hz, expected {expected} Hz",
            spectrum.frequency[8]
        );
        let gamma = &spectrum.series[0].1;
        let peak = (0..gamma.len())
            .max_by(|&i, &j| gamma[i].total_cmp(&gamma[j]))
            .unwrap();
        assert_eq!(peak, 8, "peak at bin {peak}, expected the 125 Hz bin 8");
    }

    #[test]
    fn the_series_differ_most_at_the_sine() {
        let spectrum = SpectrumTable::of(&history(), 1e-3).unwrap();
        assert_eq!(spectrum.largest_difference(), Some(spectrum.frequency[8]));
        let single = SpectrumTable {
            series: spectrum.series[..1].to_vec(),
            ..spectrum
        };
        assert_eq!(single.largest_difference(), None);
    }

    #[test]
    fn a_window_keeps_its_bins_inclusive() {
        let spectrum = SpectrumTable::of(&history(), 1e-3).unwrap();
        let (low, high) = (spectrum.frequency[8], spectrum.frequency[16]);
        let window = spectrum.select(Some(low), Some(high), None);
        assert_eq!(window.frequency, spectrum.frequency[8..=16]);
        assert_eq!(window.series[1].1, spectrum.series[1].1[8..=16]);
    }

    #[test]
    fn a_series_without_a_spectrum_is_named() {
        let mut short = history();
        short.series[1].1 = vec![f64::NAN; 64];
        let error = SpectrumTable::of(&short, 1e-3).unwrap_err();
        assert!(error.contains("series `reference`"), "{error}");
    }
}
