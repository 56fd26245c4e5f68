//! Line plots as inline SVG: axes with round ticks, one polyline per series, a legend,
//! and an optional marked point (a reported peak). Drawn on the server so that a printed
//! or saved note shows its plots without running a script, in vector form (sharp in a
//! PDF at any zoom).
//!
//! A long history is drawn from its min/max per horizontal pixel ([`decimate`]): every
//! extreme of the series is on the curve, so a peak shown is a peak of the data.

use std::fmt::Write;

use super::html::escape;

/// Width and height of a plot's view box (CSS pixels at 100 %).
pub const WIDTH: f64 = 680.0;
pub const HEIGHT: f64 = 300.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 16.0;
const TOP: f64 = 14.0;
const BOTTOM: f64 = 46.0;
/// Line colours, one per series (colour-blind safe, distinct in grey print).
const COLOURS: [&str; 4] = ["#1f4e9a", "#d95f02", "#1b9e77", "#7570b3"];
const DASHES: [&str; 4] = ["", "6 3", "2 2", "8 3 2 3"];

/// One curve: its legend and its points (x, y), in drawing order.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    pub legend: String,
    pub points: Vec<(f64, f64)>,
}

/// A plot to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot<'a> {
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub curves: &'a [Curve],
    /// A point to mark, with its label (the reported peak).
    pub mark: Option<((f64, f64), String)>,
    /// Which axis holds the values, drawn from zero (an envelope's is x).
    pub values_along: Axis,
}

/// An axis of a plot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
}

/// The points of a series of `x` (increasing) kept for `buckets` horizontal buckets:
/// in each, the first and last point and the points of the minimum and maximum, in
/// order; every point when there are few.
pub fn decimate(x: &[f64], y: &[f64], buckets: usize) -> Vec<(f64, f64)> {
    let n = x.len().min(y.len());
    let buckets = buckets.max(1);
    if n <= 4 * buckets {
        return x.iter().copied().zip(y.iter().copied()).take(n).collect();
    }
    let mut kept = Vec::with_capacity(4 * buckets);
    let per = n.div_ceil(buckets);
    for start in (0..n).step_by(per) {
        let end = (start + per).min(n);
        let slice = &y[start..end];
        let (mut low, mut high) = (0, 0);
        for (i, v) in slice.iter().enumerate() {
            if v.total_cmp(&slice[low]).is_lt() {
                low = i;
            }
            if v.total_cmp(&slice[high]).is_gt() {
                high = i;
            }
        }
        let mut picks = [0, low, high, end - start - 1];
        picks.sort_unstable();
        let mut last = None;
        for i in picks {
            if last != Some(i) {
                kept.push((x[start + i], y[start + i]));
                last = Some(i);
            }
        }
    }
    kept
}

/// Round tick values covering `[low, high]`: about `count` of them, at 1, 2 or 5 × 10ⁿ.
pub fn ticks(low: f64, high: f64, count: usize) -> Vec<f64> {
    if !(low.is_finite() && high.is_finite()) || high <= low {
        return vec![low];
    }
    let raw = (high - low) / count.max(1) as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    let first = (low / step).ceil() as i64;
    let last = (high / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick's text: round values without the noise of their binary form.
fn tick_text(value: f64) -> String {
    if value == 0.0 {
        return "0".into();
    }
    crate::physics::number(value)
}

/// The range of a set of values, widened to be drawable (a flat curve, a single point).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (low, high) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    if !low.is_finite() {
        return (0.0, 1.0);
    }
    if high > low {
        return (low, high);
    }
    let pad = if low == 0.0 { 1.0 } else { low.abs() * 0.1 };
    (low - pad, high + pad)
}

/// The plot as an `<svg>` element.
pub fn draw(plot: &Plot<'_>) -> String {
    let all = || {
        plot.curves
            .iter()
            .flat_map(|c| c.points.iter())
            .chain(plot.mark.iter().map(|(p, _)| p))
    };
    // The values' axis starts from zero and leaves room above the largest.
    let zero = |axis| (plot.values_along == axis).then_some(0.0);
    let padded = |(low, high): (f64, f64), axis| {
        if plot.values_along != axis {
            return (low, high);
        }
        let pad = 0.05 * (high - low);
        (if low < 0.0 { low - pad } else { low }, high + pad)
    };
    let (x_low, x_high) = padded(range(all().map(|p| p.0).chain(zero(Axis::X))), Axis::X);
    let (y_low, y_high) = padded(range(all().map(|p| p.1).chain(zero(Axis::Y))), Axis::Y);
    let (inner_width, inner_height) = (WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM);
    let sx = |x: f64| LEFT + (x - x_low) / (x_high - x_low) * inner_width;
    let sy = |y: f64| TOP + (y_high - y) / (y_high - y_low) * inner_height;
    let mut svg = String::new();
    let _ = write!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {WIDTH} {HEIGHT}\" role=\"img\" \
         font-family=\"sans-serif\" font-size=\"11\">"
    );
    for y in ticks(y_low, y_high, 6) {
        let at = sy(y);
        let _ = write!(
            svg,
            "<line x1=\"{LEFT}\" x2=\"{:.1}\" y1=\"{at:.1}\" y2=\"{at:.1}\" stroke=\"#ddd\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
            WIDTH - RIGHT,
            LEFT - 5.0,
            at + 4.0,
            tick_text(y)
        );
    }
    for x in ticks(x_low, x_high, 8) {
        let at = sx(x);
        let _ = write!(
            svg,
            "<line x1=\"{at:.1}\" x2=\"{at:.1}\" y1=\"{TOP}\" y2=\"{:.1}\" stroke=\"#eee\"/>\
             <text x=\"{at:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
            TOP + inner_height,
            TOP + inner_height + 15.0,
            tick_text(x)
        );
    }
    let _ = write!(
        svg,
        "<rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{inner_width}\" height=\"{inner_height}\" fill=\"none\" stroke=\"#444\"/>\
         <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\
         <text transform=\"translate(14 {:.1}) rotate(-90)\" text-anchor=\"middle\">{}</text>",
        LEFT + inner_width / 2.0,
        HEIGHT - 8.0,
        escape(plot.x_label),
        TOP + inner_height / 2.0,
        escape(plot.y_label)
    );
    for (k, curve) in plot.curves.iter().enumerate() {
        let mut points = String::with_capacity(curve.points.len() * 14);
        for (x, y) in curve
            .points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
        {
            let _ = write!(points, "{:.2},{:.2} ", sx(*x), sy(*y));
        }
        let _ = write!(
            svg,
            "<polyline data-curve=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\" stroke-dasharray=\"{}\" points=\"{}\"/>",
            escape(&curve.legend),
            COLOURS[k % COLOURS.len()],
            DASHES[k % DASHES.len()],
            points.trim_end()
        );
        // The legend in the top right corner, its text ending at the sample line.
        let legend_y = TOP + 14.0 + 14.0 * k as f64;
        let line_end = LEFT + inner_width - 8.0;
        let _ = write!(
            svg,
            "<line x1=\"{:.1}\" x2=\"{line_end:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\" stroke-width=\"2\" \
             stroke-dasharray=\"{}\"/><text x=\"{:.1}\" y=\"{legend_y:.1}\" text-anchor=\"end\">{}</text>",
            line_end - 20.0,
            legend_y - 4.0,
            legend_y - 4.0,
            COLOURS[k % COLOURS.len()],
            DASHES[k % DASHES.len()],
            line_end - 25.0,
            escape(&curve.legend)
        );
    }
    if let Some(((x, y), label)) = &plot.mark {
        let (px, py) = (sx(*x), sy(*y));
        let anchor = if px > LEFT + inner_width * 0.7 {
            "end"
        } else {
            "start"
        };
        let dx = if anchor == "end" { -7.0 } else { 7.0 };
        let _ = write!(
            svg,
            "<circle data-mark=\"peak\" cx=\"{px:.2}\" cy=\"{py:.2}\" r=\"3.5\" fill=\"none\" stroke=\"#c00\" stroke-width=\"1.5\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" fill=\"#c00\" text-anchor=\"{anchor}\">{}</text>",
            px + dx,
            (py - 6.0).max(TOP + 10.0),
            escape(label)
        );
    }
    svg.push_str("</svg>");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside_the_range() {
        let text = |t: Vec<f64>| t.into_iter().map(tick_text).collect::<Vec<_>>();
        assert_eq!(text(ticks(0.0, 1.0, 5)), ["0", "0.2", "0.4", "0.6", "0.8", "1"]);
        assert_eq!(text(ticks(-3.0, 7.0, 5)), ["-2", "0", "2", "4", "6"]);
        let small = ticks(0.0, 0.0714, 6);
        assert!(small.iter().all(|t| (0.0..=0.0714).contains(t)), "{small:?}");
        assert!(small.len() >= 4, "{small:?}");
    }

    #[test]
    fn decimation_keeps_every_extreme_in_time_order() {
        let x: Vec<f64> = (0..10_000).map(f64::from).collect();
        let y: Vec<f64> = x.iter().map(|t| (t * 0.37).sin() * t).collect();
        let kept = decimate(&x, &y, 100);
        assert!(kept.len() <= 400, "{} points kept", kept.len());
        assert!(kept.windows(2).all(|w| w[0].0 < w[1].0), "in time order");
        let max = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = y.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(kept.iter().any(|p| p.1 == max), "the maximum {max} is kept");
        assert!(kept.iter().any(|p| p.1 == min), "the minimum {min} is kept");
        assert_eq!(decimate(&x[..10], &y[..10], 100).len(), 10, "few points: all");
    }

    #[test]
    fn a_plot_escapes_its_labels_and_marks_its_point() {
        let curves = [Curve {
            legend: "c<1>".into(),
            points: vec![(0.0, 0.0), (1.0, 2.0)],
        }];
        let svg = draw(&Plot {
            x_label: "time (s)",
            y_label: "force & co",
            curves: &curves,
            mark: Some(((1.0, 2.0), "2 N".into())),
            values_along: Axis::Y,
        });
        assert!(
            svg.contains("c&lt;1&gt;") && svg.contains("force &amp; co"),
            "{svg}"
        );
        assert!(svg.contains("data-mark=\"peak\""));
        assert!(!svg.contains("NaN"));
    }
}
