//! Baseline correction: an accelerogram whose velocity and displacement end at zero.
//!
//! A record sampled every h and linear between samples (the table convention) integrates
//! exactly to v_{k+1} = v_k + h (a_k + a_{k+1})/2 and
//! d_{k+1} = d_k + h v_k + h² (2a_k + a_{k+1})/6 from rest. The end velocity V[a] and end
//! displacement D[a] are linear in a, so subtracting c₁p₁ + c₂p₂ with two smooth shapes
//! (the envelope e(t) and e(t)·t/T, which vanish where the record is quiet) and (c₁, c₂)
//! solving [V[p₁] V[p₂]; D[p₁] D[p₂]] c = [V[a]; D[a]] makes both exactly zero (to
//! rounding). The correction is a low-frequency adjustment spread over the strong motion
//! (a least-change choice among such shapes is not needed: the spectrum iteration that
//! calls this sees the corrected signal).

/// (end velocity, end displacement) of `samples` (m/s², every `interval` s, from rest).
pub fn end_motion(samples: &[f64], interval: f64) -> (f64, f64) {
    let (mut v, mut d) = (0.0, 0.0);
    for pair in samples.windows(2) {
        d += interval * v + interval * interval * (2.0 * pair[0] + pair[1]) / 6.0;
        v += interval * (pair[0] + pair[1]) / 2.0;
    }
    (v, d)
}

/// Removes the end velocity and displacement of `samples` with the shapes `envelope`
/// and `envelope`·t/T (module doc). Returns false, leaving the samples unchanged, when
/// the two shapes cannot be told apart (a degenerate envelope).
pub fn correct(samples: &mut [f64], interval: f64, envelope: &[f64]) -> bool {
    let n = samples.len();
    let ramp: Vec<f64> = envelope
        .iter()
        .enumerate()
        .map(|(k, e)| e * k as f64 / (n.max(2) - 1) as f64)
        .collect();
    let (v1, d1) = end_motion(envelope, interval);
    let (v2, d2) = end_motion(&ramp, interval);
    let (v, d) = end_motion(samples, interval);
    let determinant = v1 * d2 - v2 * d1;
    if !(determinant.is_finite() && determinant.abs() > 1e-12 * (v1 * d2).abs().max((v2 * d1).abs())) {
        return false;
    }
    let c1 = (v * d2 - v2 * d) / determinant;
    let c2 = (v1 * d - v * d1) / determinant;
    for (k, sample) in samples.iter_mut().enumerate() {
        *sample -= c1 * envelope[k] + c2 * ramp[k];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    // A constant acceleration of 1 over [0, 1] ends at v = 1, d = 1/2: exact for the
    // piecewise-linear integration.
    #[test]
    fn end_motion_integrates_linear_pieces_exactly() {
        let (v, d) = end_motion(&[1.0; 11], 0.1);
        assert!((v - 1.0).abs() < 1e-14 && (d - 0.5).abs() < 1e-14, "v {v}, d {d}");
        // a = t on [0, 1]: v = 1/2, d = 1/6.
        let ramp: Vec<f64> = (0..=10).map(|k| k as f64 * 0.1).collect();
        let (v, d) = end_motion(&ramp, 0.1);
        assert!(
            (v - 0.5).abs() < 1e-14 && (d - 1.0 / 6.0).abs() < 1e-14,
            "v {v}, d {d}"
        );
    }

    #[test]
    fn a_drifting_record_ends_at_rest_after_correction() {
        let n = 2001;
        let envelope: Vec<f64> = (0..n)
            .map(|k| {
                let s = k as f64 / (n - 1) as f64;
                (std::f64::consts::PI * s).sin().powi(2)
            })
            .collect();
        let mut samples: Vec<f64> = (0..n)
            .map(|k| envelope[k] * ((k as f64 * 0.05).sin() + 0.3))
            .collect();
        let (v, d) = end_motion(&samples, 0.01);
        assert!(
            v.abs() > 1.0 && d.abs() > 1.0,
            "the test record drifts: v {v}, d {d}"
        );
        assert!(correct(&mut samples, 0.01, &envelope));
        let (v, d) = end_motion(&samples, 0.01);
        assert!(
            v.abs() < 1e-12 && d.abs() < 1e-10,
            "after correction: v {v}, d {d}"
        );
    }
}
