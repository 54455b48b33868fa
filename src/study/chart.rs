//! Line charts of convergence studies, drawn with `plotters` to PNG and SVG.
//!
//! `rust-v converge` draws its charts itself so that a study needs nothing but the
//! binary. A chart has a title (with the scene name), axis labels with units, a
//! legend, one line per series and, where a series has a spread (several seeds),
//! a translucent band from its minimum to its maximum. The x axis is logarithmic;
//! the y axis is logarithmic or linear.
//!
//! Text in PNGs is drawn with DejaVu Sans, compiled into the binary
//! (`assets/fonts/`, Bitstream Vera licence), so no system font library is needed;
//! SVGs name the font and let the viewer draw the text.

use std::ops::Range;
use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::error::{Error, Result};

/// Pixel size of the PNG charts (the SVGs have the same size in user units).
pub const CHART_SIZE: (u32, u32) = (900, 600);

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// One line of a chart: points `(x, min, median, max)`; the line goes through the medians.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// The points, in increasing x.
    pub points: Vec<(f64, f64, f64, f64)>,
}

/// What a chart shows.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Title (put the scene name in it).
    pub title: String,
    /// The x axis label, with its unit.
    pub x_label: String,
    /// The y axis label, with its unit.
    pub y_label: String,
    /// A logarithmic y axis (the x axis is always logarithmic).
    pub log_y: bool,
    /// A horizontal reference line (e.g. 1 for ratios).
    pub y_line: Option<f64>,
    /// Put the legend at the middle of the right edge instead of the upper right corner.
    pub legend_middle: bool,
}

/// The colour of the `i`-th series.
fn colour(i: usize) -> RGBColor {
    const C: [RGBColor; 8] = [
        RGBColor(0, 0, 0),
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(255, 127, 14),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
    ];
    C[i % C.len()]
}

/// Draws `chart` to `stem.png` and `stem.svg`.
pub fn draw(stem: &Path, chart: &Chart, series: &[Series]) -> Result<()> {
    REGISTER.call_once(|| {
        // The font is compiled in and known to be valid; an error would only lose the PNG's text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    let fail = |path: &Path, e: &dyn std::fmt::Display| Error::Image {
        path: path.to_path_buf(),
        message: format!("chart: {e}"),
    };
    {
        let root = BitMapBackend::new(&png, CHART_SIZE).into_drawing_area();
        draw_on(&root, chart, series).map_err(|e| fail(&png, &e))?;
        root.present().map_err(|e| fail(&png, &e))?;
    }
    {
        let root = SVGBackend::new(&svg, CHART_SIZE).into_drawing_area();
        draw_on(&root, chart, series).map_err(|e| fail(&svg, &e))?;
        root.present().map_err(|e| fail(&svg, &e))?;
    }
    Ok(())
}

/// The range of the finite (and, for a log axis, positive) values, padded.
fn range(values: impl Iterator<Item = f64>, log: bool) -> Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { 0.1..10.0 } else { 0.0..1.0 };
    }
    if log {
        let (lo, hi) = if hi / lo < 1.5 { (lo / 1.25, hi * 1.25) } else { (lo, hi) };
        lo / 1.1..hi * 1.1
    } else {
        let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.05 * hi.abs().max(1e-3) };
        lo - pad..hi + pad
    }
}

/// What drawing on backend `DB` can fail with.
type DrawResult<DB> = std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw_on<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &Chart, series: &[Series]) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let xs = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)), true);
    let ys = series.iter().flat_map(|s| s.points.iter().flat_map(|p| [p.1, p.2, p.3])).chain(chart.y_line);
    let yr = range(ys, chart.log_y);
    if chart.log_y { plot(root, chart, series, xs, yr.log_scale()) } else { plot(root, chart, series, xs, yr) }
}

fn plot<DB, Y>(root: &DrawingArea<DB, Shift>, chart: &Chart, series: &[Series], xs: Range<f64>, y: Y) -> DrawResult<DB>
where
    DB: DrawingBackend,
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut c = ChartBuilder::on(root)
        .caption(&chart.title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d(xs.log_scale(), y)?;
    c.configure_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 18))
        .x_label_formatter(&|v| short(*v))
        .y_label_formatter(&|v| short(*v))
        .draw()?;
    let ok = |v: f64| v.is_finite();
    for (i, s) in series.iter().enumerate() {
        let col = colour(i);
        let pts: Vec<_> = s.points.iter().filter(|p| ok(p.0) && ok(p.1) && ok(p.3)).collect();
        if pts.iter().any(|p| p.1 != p.3) {
            let band: Vec<(f64, f64)> =
                pts.iter().map(|p| (p.0, p.1)).chain(pts.iter().rev().map(|p| (p.0, p.3))).collect();
            c.draw_series(std::iter::once(Polygon::new(band, col.mix(0.18).filled())))?;
        }
        let line: Vec<(f64, f64)> = s.points.iter().filter(|p| ok(p.0) && ok(p.2)).map(|p| (p.0, p.2)).collect();
        c.draw_series(LineSeries::new(line.clone(), col.stroke_width(2)))?
            .label(s.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], col.stroke_width(3)));
        c.draw_series(line.into_iter().map(|p| Circle::new(p, 3, col.filled())))?;
    }
    if let Some(v) = chart.y_line {
        let (x0, x1) = (c.x_range().start, c.x_range().end);
        c.draw_series(std::iter::once(PathElement::new(vec![(x0, v), (x1, v)], BLACK.mix(0.5))))?;
    }
    c.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", 16))
        .position(if chart.legend_middle { SeriesLabelPosition::MiddleRight } else { SeriesLabelPosition::UpperRight })
        .draw()?;
    Ok(())
}

/// A compact tick label: `1e-3`, `0.25`, `100`, `1.5e5`.
fn short(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.1e}");
        s.replace(".0e", "e")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(1000.0), "1000");
        assert_eq!(short(1e7), "1e7");
        assert_eq!(short(2.5e-5), "2.5e-5");
    }
}
