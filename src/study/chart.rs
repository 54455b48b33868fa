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
    if chart.log_y {
        let keys = ticks(yr.clone(), true);
        plot(root, chart, series, xs, yr.clone(), yr.log_scale().with_key_points(keys))
    } else {
        // A linear axis: plotters' own ticks are round steps, at least three over any range.
        plot(root, chart, series, xs, yr.clone(), yr)
    }
}

fn plot<DB, Y>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart,
    series: &[Series],
    xs: Range<f64>,
    yr: Range<f64>,
    y: Y,
) -> DrawResult<DB>
where
    DB: DrawingBackend,
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let x_ticks = ticks(xs.clone(), true);
    let y_ticks = ticks(yr.clone(), chart.log_y);
    // (On a linear y axis plotters picks the ticks: one more digit than ours need.)
    let (x_digits, y_digits) = (digits_for(&x_ticks), digits_for(&y_ticks) + usize::from(!chart.log_y));
    let mut c = ChartBuilder::on(root)
        .caption(&chart.title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d(xs.clone().log_scale().with_key_points(x_ticks), y)?;
    c.configure_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 18))
        .x_label_formatter(&|v| label(*v, x_digits))
        .y_label_formatter(&|v| label(*v, y_digits))
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
        .position(legend_spot(&where_points(series, &xs, &yr, chart.log_y), series.len(), chart.legend_middle))
        .draw()?;
    Ok(())
}

/// Where each point (min, median and max) lies in the plot, as fractions of its width
/// (x, logarithmic) and height (y, from the bottom).
fn where_points(series: &[Series], xs: &Range<f64>, ys: &Range<f64>, log_y: bool) -> Vec<(f64, f64)> {
    let frac = |v: f64, r: &Range<f64>, log: bool| {
        if log { (v.ln() - r.start.ln()) / (r.end.ln() - r.start.ln()) } else { (v - r.start) / (r.end - r.start) }
    };
    let mut out = Vec::new();
    for s in series {
        for p in &s.points {
            for y in [p.1, p.2, p.3] {
                let (fx, fy) = (frac(p.0, xs, true), frac(y, ys, log_y));
                if fx.is_finite() && fy.is_finite() {
                    out.push((fx, fy));
                }
            }
        }
    }
    out
}

/// The legend's place: the candidate box (a corner or the middle of the right edge, about
/// 40% of the plot wide and 6% high per series) with the fewest points in it, the
/// preferred one (upper right, or middle right with `middle`) on a tie.
fn legend_spot(points: &[(f64, f64)], n: usize, middle: bool) -> SeriesLabelPosition {
    use SeriesLabelPosition::*;
    let (w, h) = (0.4, (0.06 * n as f64 + 0.04).min(0.9));
    let boxes = [
        (UpperRight, 1.0 - w, 1.0 - h),
        (MiddleRight, 1.0 - w, 0.5 - h / 2.0),
        (UpperLeft, 0.0, 1.0 - h),
        (LowerRight, 1.0 - w, 0.0),
        (LowerLeft, 0.0, 0.0),
    ];
    let order: &[usize] = if middle { &[1, 0, 2, 3, 4] } else { &[0, 2, 3, 4, 1] };
    let inside = |x0: f64, y0: f64| {
        points.iter().filter(|&&(x, y)| (x0..=x0 + w).contains(&x) && (y0..=y0 + h).contains(&y)).count()
    };
    let best = order.iter().min_by_key(|&&i| inside(boxes[i].1, boxes[i].2)).copied().unwrap_or(0);
    boxes[best].0.clone()
}

/// At least three tick values inside `r`, round in the axis's terms: on a log axis the
/// powers of ten when there are three or more, else 1-2-5 times a power of ten, else
/// evenly spaced round values (a span of less than a factor 2.5); on a linear axis
/// evenly spaced round values (a step of 1, 2 or 5 times a power of ten).
pub fn ticks(r: Range<f64>, log: bool) -> Vec<f64> {
    let (lo, hi) = (r.start.min(r.end), r.start.max(r.end));
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return vec![lo, hi];
    }
    if log && lo > 0.0 {
        let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        for mantissas in [&[1.0][..], &[1.0, 2.0, 5.0][..]] {
            let mut t: Vec<f64> = (k0..=k1)
                .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
                .filter(|v| (lo..=hi).contains(v))
                .collect();
            if t.len() >= 3 {
                // At most about 10 labels: every second or third value of a long run.
                let every = t.len().div_ceil(10);
                t = t.into_iter().step_by(every).collect();
                return t;
            }
        }
    }
    // Evenly spaced: the largest round step that gives three values or more.
    let mut step = 10f64.powf((hi - lo).log10().ceil());
    loop {
        let t: Vec<f64> = ((lo / step).ceil() as i64..=(hi / step).floor() as i64).map(|i| i as f64 * step).collect();
        if t.len() >= 3 || step < (hi - lo) * 1e-9 {
            return t;
        }
        // 1 -> 0.5 -> 0.2 -> 0.1 (times a power of ten).
        let m = step / 10f64.powf(step.log10().floor());
        step *= if (m - 2.0).abs() < 1e-9 {
            0.5
        } else if (m - 5.0).abs() < 1e-9 {
            0.4
        } else {
            0.5
        };
    }
}

/// The fewest significant digits (1 to 6) that give each of `ticks` a different label.
fn digits_for(ticks: &[f64]) -> usize {
    (1..=6)
        .find(|&d| {
            let labels: Vec<String> = ticks.iter().map(|&v| label(v, d)).collect();
            labels.iter().enumerate().all(|(i, a)| labels[..i].iter().all(|b| a != b))
        })
        .unwrap_or(6)
}

/// A tick label with `digits` significant digits, trailing zeros dropped: `0.0012`,
/// `25`, `1e-5`, `1.5e5`.
fn label(v: f64, digits: usize) -> String {
    let a = v.abs();
    if v == 0.0 {
        return "0".into();
    }
    let trim = |s: String| if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s };
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{:.*e}", digits.saturating_sub(1), v);
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{e}", trim(m.to_string()))
    } else {
        let decimals = (digits as i32 - 1 - a.log10().floor() as i32).max(0) as usize;
        trim(format!("{v:.decimals$}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every axis gets at least three labelled ticks inside its range, all different
    /// (issue 34 item 14: a short `converge` run labelled 0.01-0.06 over data from
    /// 0.0012 s, two y values, and "10" twice on the spp axis).
    #[test]
    fn every_axis_gets_three_distinct_ticks() {
        let cases = [
            (0.0012..0.06, true),
            (0.9..8.8, true),
            (1.0..16.0, true),
            (0.8..1.2, true),
            (9.0..11.0, true),
            (1e-4..1e3, true),
            (0.31..0.33, false),
            (-0.05..1.05, false),
            (0.0..1e6, false),
            (0.0021..0.0023, true),
        ];
        for (r, log) in cases {
            let t = ticks(r.clone(), log);
            assert!(t.len() >= 3 && t.len() <= 12, "{r:?} {log}: {t:?}");
            assert!(t.iter().all(|v| r.contains(v) || *v == r.end), "{r:?}: {t:?}");
            assert!(t.windows(2).all(|w| w[0] < w[1]), "{r:?}: {t:?}");
            let d = digits_for(&t);
            let labels: Vec<String> = t.iter().map(|&v| label(v, d)).collect();
            let mut unique = labels.clone();
            unique.dedup();
            assert_eq!(unique.len(), labels.len(), "{r:?}: {labels:?}");
        }
        assert_eq!(ticks(1e-4..1e3, true), [1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1000.0]);
        assert_eq!(ticks(0.9..8.8, true), [1.0, 2.0, 5.0]);
        let t = ticks(0.0012..0.06, true);
        assert_eq!(t, [0.002, 0.005, 0.01, 0.02, 0.05]);
        let d = digits_for(&t);
        assert_eq!(t.iter().map(|&v| label(v, d)).collect::<Vec<_>>(), ["0.002", "0.005", "0.01", "0.02", "0.05"]);
    }

    /// The legend goes where no point is: the upper right unless points are there.
    #[test]
    fn the_legend_avoids_the_data() {
        use SeriesLabelPosition::*;
        let pos = |p: &[(f64, f64)], middle| format!("{:?}", legend_spot(p, 2, middle));
        assert_eq!(pos(&[(0.1, 0.1), (0.5, 0.5)], false), format!("{UpperRight:?}"));
        assert_eq!(pos(&[(0.9, 0.95), (0.1, 0.1)], false), format!("{UpperLeft:?}"));
        assert_eq!(pos(&[(0.9, 0.95), (0.1, 0.95), (0.9, 0.05)], false), format!("{LowerLeft:?}"));
        assert_eq!(pos(&[(0.9, 0.5)], true), format!("{UpperRight:?}"));
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(label(0.25, 2), "0.25");
        assert_eq!(label(1000.0, 1), "1000");
        assert_eq!(label(1e7, 1), "1e7");
        assert_eq!(label(2.5e-5, 2), "2.5e-5");
        assert_eq!(label(0.0012, 2), "0.0012");
        assert_eq!(label(10.0, 3), "10");
    }
}
