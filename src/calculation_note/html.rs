//! The pieces of the note's HTML: escaping, the cells that carry a figure with the
//! pointer it comes from, and the style sheet (screen and A4 print).

use std::fmt::Write;

use crate::processes::note_facts::{Figure, Unit};

/// `text` safe inside HTML text and attribute values (double- or single-quoted).
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A figure as shown: six significant digits in its shown unit (`19.5754`, for Pa
/// shown in MPa).
pub fn shown(value: f64, unit: Unit) -> String {
    let (factor, _) = unit.shown();
    let value = value * factor;
    if value == 0.0 {
        return "0".into();
    }
    crate::physics::number(value)
}

/// The unit a figure is shown in (`MPa`), empty for counts and ratios.
pub fn unit_text(unit: Unit) -> &'static str {
    unit.shown().1
}

/// A table cell holding `figure`: shown rounded, with the exact value and the member
/// of the results document it comes from in `data-value` and `data-pointer` (and the
/// pointer as its tooltip).
pub fn figure_cell(figure: &Figure) -> String {
    format!(
        "<td class=\"num\" data-pointer=\"{pointer}\" data-value=\"{value}\" title=\"{pointer}\">{shown}</td>",
        pointer = escape(&figure.pointer),
        value = figure.value,
        shown = shown(figure.value, figure.unit),
    )
}

/// [`figure_cell`], or an empty cell (`–`) when there is none.
pub fn optional_cell(figure: Option<&Figure>) -> String {
    figure.map_or_else(|| "<td class=\"none\">–</td>".to_owned(), figure_cell)
}

/// A figure with its unit in running text (`5.33857 N`).
pub fn inline(figure: &Figure) -> String {
    let unit = unit_text(figure.unit);
    let mut out = format!(
        "<span class=\"num\" data-pointer=\"{}\" data-value=\"{}\">{}",
        escape(&figure.pointer),
        figure.value,
        shown(figure.value, figure.unit)
    );
    if !unit.is_empty() {
        let _ = write!(out, " {unit}");
    }
    out.push_str("</span>");
    out
}

/// The style sheet: a plain page on screen, A4 with 15 mm margins in print, where no
/// figure, small table or row is split between two pages and long tables repeat
/// their header.
pub const STYLE: &str = r#"
:root { color-scheme: light; }
* { box-sizing: border-box; }
body { font: 10.5pt/1.4 "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; color: #111;
       max-width: 190mm; margin: 12px auto; padding: 0 12px; }
h1 { font-size: 17pt; margin: 0 0 4px; }
h2 { font-size: 12.5pt; margin: 18px 0 6px; border-bottom: 1.5px solid #1f4e9a; padding-bottom: 2px;
     break-after: avoid; page-break-after: avoid; }
p.lead { margin: 0 0 10px; color: #333; }
table { border-collapse: collapse; width: 100%; margin: 4px 0 8px; }
th, td { border: 1px solid #bbb; padding: 2px 6px; text-align: left; vertical-align: top; }
th { background: #eef2f8; font-weight: 600; }
thead { display: table-header-group; }
tr { break-inside: avoid; page-break-inside: avoid; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.none { text-align: center; color: #888; }
td.key { width: 34%; font-weight: 600; background: #f7f7f7; }
td.what { width: 36%; }
table.compact { width: auto; min-width: 60%; }
.mono, code { font-family: "DejaVu Sans Mono", Menlo, Consolas, monospace; font-size: 9pt; word-break: break-all; }
.verdict { display: inline-block; padding: 2px 10px; border-radius: 10px; font-weight: 700; color: #fff;
           -webkit-print-color-adjust: exact; print-color-adjust: exact; }
.verdict-good { background: #1b7f3b; } .verdict-unchecked { background: #666; }
.verdict-doubtful { background: #b8860b; } .verdict-poor { background: #b00020; }
.band-green { color: #1b7f3b; } .band-amber { color: #a66300; } .band-red { color: #b00020; font-weight: 700; }
ul.reasons li, ul.warnings li { margin: 2px 0; }
figure.plot { margin: 8px 0 12px; break-inside: avoid; page-break-inside: avoid; }
figure.plot a.data { display: block; color: inherit; text-decoration: none; }
figure.plot svg { display: block; width: 100%; height: auto; max-height: 110mm; }
figure.plot figcaption { font-size: 9.5pt; color: #333; margin-top: 2px; }
table.compact, table.identity { break-inside: avoid; page-break-inside: avoid; }
.note-text { white-space: pre-wrap; }
.muted { color: #666; }
@page { size: A4; margin: 15mm; }
@media print {
  body { max-width: none; margin: 0; padding: 0; font-size: 9.5pt; }
  a { color: inherit; text-decoration: none; }
  h2 { margin-top: 12px; }
}
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_and_quotes_are_escaped() {
        assert_eq!(
            escape(r#"<script>alert('x') & "y"</script>"#),
            "&lt;script&gt;alert(&#39;x&#39;) &amp; &quot;y&quot;&lt;/script&gt;"
        );
        assert_eq!(escape("clad B — rev. C"), "clad B — rev. C");
    }

    #[test]
    fn a_cell_shows_the_rounded_figure_and_carries_the_exact_one() {
        let figure = Figure {
            value: 19575432.619041543,
            unit: Unit::Pascal,
            pointer: "/max_bending/stress".into(),
        };
        let cell = figure_cell(&figure);
        assert!(cell.contains("data-value=\"19575432.619041543\""), "{cell}");
        assert!(cell.contains(">19.5754</td>"), "{cell}");
        assert!(inline(&figure).ends_with("19.5754 MPa</span>"));
    }
}
