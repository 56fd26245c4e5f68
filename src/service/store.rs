//! Compact storage of time histories: binary f64 columns, byte-shuffled, deflated.
//!
//! A history of n samples and k series is stored as k + 1 columns (time first) of n
//! little-endian f64 values. Each column is "shuffled" (all first bytes, then all second
//! bytes, ...): neighbouring samples share sign, exponent and leading mantissa bytes, so
//! the shuffled planes compress far better than interleaved floats. The result is one
//! deflate stream per history, a few bytes per sample instead of ~25 characters of JSON.

use std::io::{Read, Write};

use flate2::Compression;
use flate2::read::DeflateDecoder;
use flate2::write::DeflateEncoder;

use crate::processes::History;

/// A history as stored in `job_histories`.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredHistory {
    /// Output name (`tip_displacement`).
    pub name: String,
    /// Series names in column order (without `time`).
    pub series: Vec<String>,
    /// Number of samples.
    pub samples: usize,
    /// Deflated, byte-shuffled f64 columns.
    pub data: Vec<u8>,
}

/// Why a history cannot be stored or read back.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HistoryError {
    #[error("history `{history}`: series `{series}` has {len} samples, time has {expected}")]
    Ragged {
        history: String,
        series: String,
        len: usize,
        expected: usize,
    },
    #[error("history `{0}`: stored data is corrupt")]
    Corrupt(String),
}

/// Encodes a history for storage.
pub fn encode(history: &History) -> Result<StoredHistory, HistoryError> {
    let samples = history.time.len();
    for (name, values) in &history.series {
        if values.len() != samples {
            return Err(HistoryError::Ragged {
                history: history.name.clone(),
                series: name.clone(),
                len: values.len(),
                expected: samples,
            });
        }
    }
    let mut raw = Vec::with_capacity(samples * 8 * (history.series.len() + 1));
    shuffle_into(&history.time, &mut raw);
    for (_, values) in &history.series {
        shuffle_into(values, &mut raw);
    }
    let mut encoder = DeflateEncoder::new(Vec::new(), Compression::fast());
    // Writing into a Vec cannot fail.
    encoder.write_all(&raw).expect("deflate into memory");
    let data = encoder.finish().expect("deflate into memory");
    Ok(StoredHistory {
        name: history.name.clone(),
        series: history.series.iter().map(|(name, _)| name.clone()).collect(),
        samples,
        data,
    })
}

/// Decodes a stored history.
pub fn decode(stored: &StoredHistory) -> Result<History, HistoryError> {
    let corrupt = || HistoryError::Corrupt(stored.name.clone());
    let columns = stored.series.len() + 1;
    let expected = stored.samples.checked_mul(8 * columns).ok_or_else(corrupt)?;
    let mut raw = Vec::with_capacity(expected);
    DeflateDecoder::new(stored.data.as_slice())
        .take(expected as u64 + 1)
        .read_to_end(&mut raw)
        .map_err(|_| corrupt())?;
    if raw.len() != expected {
        return Err(corrupt());
    }
    let column_bytes = stored.samples * 8;
    let mut chunks = raw.chunks_exact(column_bytes.max(1));
    let mut next_column = || {
        if column_bytes == 0 {
            Vec::new()
        } else {
            unshuffle(chunks.next().unwrap_or(&[]), stored.samples)
        }
    };
    let time = next_column();
    let series = stored
        .series
        .iter()
        .map(|name| (name.clone(), next_column()))
        .collect();
    Ok(History {
        name: stored.name.clone(),
        time,
        series,
    })
}

fn shuffle_into(values: &[f64], out: &mut Vec<u8>) {
    let start = out.len();
    out.resize(start + values.len() * 8, 0);
    let planes = &mut out[start..];
    for (i, value) in values.iter().enumerate() {
        for (k, byte) in value.to_le_bytes().into_iter().enumerate() {
            planes[k * values.len() + i] = byte;
        }
    }
}

fn unshuffle(planes: &[u8], samples: usize) -> Vec<f64> {
    (0..samples)
        .map(|i| {
            let mut bytes = [0u8; 8];
            for (k, byte) in bytes.iter_mut().enumerate() {
                *byte = planes[k * samples + i];
            }
            f64::from_le_bytes(bytes)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(samples: usize) -> History {
        let time: Vec<f64> = (0..samples).map(|i| i as f64 * 1e-4).collect();
        History {
            name: "tip_displacement".into(),
            series: vec![
                (
                    "numerical".into(),
                    time.iter().map(|t| (60.0 * t).sin() * 1e-3).collect(),
                ),
                (
                    "reference".into(),
                    time.iter().map(|t| (60.0 * t).cos() * -1e-3).collect(),
                ),
            ],
            time,
        }
    }

    #[test]
    fn a_history_survives_encoding_bit_for_bit() {
        let history = sample(5_000);
        let decoded = decode(&encode(&history).unwrap()).unwrap();
        assert_eq!(decoded, history);
    }

    #[test]
    fn an_empty_history_round_trips() {
        let history = sample(0);
        assert_eq!(decode(&encode(&history).unwrap()).unwrap(), history);
    }

    #[test]
    fn stored_histories_are_smaller_than_raw_floats() {
        let history = sample(20_000);
        let stored = encode(&history).unwrap();
        let raw = 20_000 * 8 * 3;
        assert!(
            stored.data.len() < raw,
            "stored {} bytes, raw {raw} bytes",
            stored.data.len()
        );
    }

    #[test]
    fn ragged_series_are_refused() {
        let mut history = sample(10);
        history.series[1].1.pop();
        assert!(matches!(encode(&history), Err(HistoryError::Ragged { .. })));
    }

    #[test]
    fn truncated_data_is_reported_corrupt() {
        let mut stored = encode(&sample(100)).unwrap();
        stored.data.truncate(stored.data.len() / 2);
        assert!(decode(&stored).is_err());
    }
}
