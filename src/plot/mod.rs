//! Charts with plotters: line charts (optionally with outlines, markers and shaded spans) and heat
//! maps, each written as PNG and SVG. [`runs`] draws the standard charts of a results folder.
//!
//! The font (DejaVu Sans) comes from the `dejavu` crate as bytes, so no system font library is
//! needed. Files are written under a temporary name and renamed (see [`crate::output`]).

pub mod envelope;
pub mod runs;

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::error::{Error, Result};
use crate::output::{rename, temp_path, write_atomic};

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bytes are a valid TTF shipped by the dejavu crate; registration cannot fail on them,
        // and if it did the charts would only lack text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}

/// One labelled curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (x, y) points in drawing order; non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
}

/// A line chart: title, axis labels with units, and curves.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

/// A line chart with extra elements: closed outlines (vehicle bodies), point markers (cones),
/// highlighted points (cone strikes) and shaded x-spans (time windows).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct XyChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub outlines: Vec<Vec<(f64, f64)>>,
    pub markers: Vec<(f64, f64)>,
    pub highlights: Vec<(f64, f64)>,
    pub spans: Vec<(f64, f64)>,
}

/// A heat map of a grid: `values[row][col]`, rows along the vertical axis.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Label of the colour scale, with unit.
    pub value_label: String,
    /// Physical extent: x from `x_range.0` to `x_range.1` across columns, y likewise across rows.
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub values: Vec<Vec<f64>>,
}

const SIZE: (u32, u32) = (1000, 640);

fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Io { path: path.to_path_buf(), source: std::io::Error::other(e.to_string()) }
}

fn palette(i: usize) -> RGBColor {
    const C: [RGBColor; 8] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(23, 190, 207),
    ];
    C[i % C.len()]
}

fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 {
        let pad = if lo.abs() > 0.0 { lo.abs() * 0.1 } else { 1.0 };
        return (lo - pad, hi + pad);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

fn draw_lines<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, c: &XyChart) -> std::result::Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let pts = || {
        c.series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .chain(c.outlines.iter().flatten().copied())
            .chain(c.markers.iter().copied())
    };
    let (x0, x1) = bounds(pts().map(|p| p.0));
    let (y0, y1) = bounds(pts().map(|p| p.1));
    let mut chart = ChartBuilder::on(&root)
        .caption(&c.title, ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(&c.x_label)
        .y_desc(&c.y_label)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(|e| e.to_string())?;
    for &(a, b) in &c.spans {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a, y0), (b, y1)],
                RGBColor(255, 200, 120).mix(0.35).filled(),
            )))
            .map_err(|e| e.to_string())?;
    }
    for o in &c.outlines {
        let mut closed = o.clone();
        if let Some(first) = o.first() {
            closed.push(*first);
        }
        chart.draw_series(std::iter::once(PathElement::new(closed, BLACK.mix(0.5)))).map_err(|e| e.to_string())?;
    }
    chart
        .draw_series(c.markers.iter().map(|&(x, y)| TriangleMarker::new((x, y), 4, RGBColor(255, 120, 0).filled())))
        .map_err(|e| e.to_string())?;
    for (i, s) in c.series.iter().enumerate() {
        let color = palette(i);
        let line: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()).collect();
        chart
            .draw_series(LineSeries::new(line, color.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label(&s.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    chart
        .draw_series(c.highlights.iter().map(|&(x, y)| Cross::new((x, y), 7, RED.stroke_width(3))))
        .map_err(|e| e.to_string())?;
    if c.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

/// Colour for a value in [0, 1] on a blue–cyan–yellow–red scale.
fn heat_colour(t: f64) -> RGBColor {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let stops = [
        (0.0, (20.0, 30.0, 140.0)),
        (0.35, (40.0, 180.0, 220.0)),
        (0.65, (250.0, 220.0, 40.0)),
        (1.0, (200.0, 20.0, 20.0)),
    ];
    for w in stops.windows(2) {
        let (a, ca) = w[0];
        let (b, cb) = w[1];
        if t <= b {
            let u = (t - a) / (b - a);
            let m = |p: f64, q: f64| (p + u * (q - p)).round() as u8;
            return RGBColor(m(ca.0, cb.0), m(ca.1, cb.1), m(ca.2, cb.2));
        }
    }
    RGBColor(200, 20, 20)
}

fn draw_heat<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, h: &HeatMap) -> std::result::Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (main, bar) = root.split_horizontally(SIZE.0 - 150);
    let (lo, hi) = bounds(h.values.iter().flatten().copied());
    let span = (hi - lo).max(1e-300);
    let rows = h.values.len();
    let cols = h.values.iter().map(|r| r.len()).max().unwrap_or(0);
    let mut chart = ChartBuilder::on(&main)
        .caption(&h.title, ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(h.x_range.0..h.x_range.1, h.y_range.0..h.y_range.1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(&h.x_label)
        .y_desc(&h.y_label)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(|e| e.to_string())?;
    if rows > 0 && cols > 0 {
        let dx = (h.x_range.1 - h.x_range.0) / cols as f64;
        let dy = (h.y_range.1 - h.y_range.0) / rows as f64;
        chart
            .draw_series(h.values.iter().enumerate().flat_map(|(r, row)| {
                row.iter().enumerate().map(move |(c, v)| {
                    let x = h.x_range.0 + c as f64 * dx;
                    let y = h.y_range.0 + r as f64 * dy;
                    Rectangle::new([(x, y), (x + dx, y + dy)], heat_colour((v - lo) / span).filled())
                })
            }))
            .map_err(|e| e.to_string())?;
    }
    // Colour bar with its scale.
    let mut cb = ChartBuilder::on(&bar)
        .margin_top(50)
        .margin_bottom(60)
        .margin_right(10)
        .y_label_area_size(70)
        .caption(&h.value_label, ("sans-serif", 14))
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(|e| e.to_string())?;
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    let n = 100;
    cb.draw_series((0..n).map(|i| {
        let a = lo + span * i as f64 / n as f64;
        let b = lo + span * (i + 1) as f64 / n as f64;
        Rectangle::new([(0.0, a), (1.0, b)], heat_colour(i as f64 / (n - 1) as f64).filled())
    }))
    .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

fn write_both(
    stem: &Path,
    draw_png: impl FnOnce(&Path) -> std::result::Result<(), String>,
    draw_svg: impl FnOnce(&mut String) -> std::result::Result<(), String>,
) -> Result<()> {
    register_font();
    let png = stem.with_extension("png");
    // plotters picks the encoder from the extension, so the temporary name keeps ".png".
    let tmp = temp_path(&png).with_extension("tmp.png");
    draw_png(&tmp).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        plot_err(&png, e)
    })?;
    rename(&tmp, &png)?;
    let svg_path = stem.with_extension("svg");
    let mut svg = String::new();
    draw_svg(&mut svg).map_err(|e| plot_err(&svg_path, e))?;
    write_atomic(&svg_path, svg.as_bytes())
}

/// Write `chart` to `<stem>.png` and `<stem>.svg`.
pub fn line_chart(stem: &Path, chart: &LineChart) -> Result<()> {
    let xy = XyChart {
        title: chart.title.clone(),
        x_label: chart.x_label.clone(),
        y_label: chart.y_label.clone(),
        series: chart.series.clone(),
        ..XyChart::default()
    };
    xy_chart(stem, &xy)
}

/// Write `chart` (with its outlines, markers and spans) to `<stem>.png` and `<stem>.svg`.
pub fn xy_chart(stem: &Path, chart: &XyChart) -> Result<()> {
    write_both(
        stem,
        |p| draw_lines(BitMapBackend::new(p, SIZE).into_drawing_area(), chart),
        |s| draw_lines(SVGBackend::with_string(s, SIZE).into_drawing_area(), chart),
    )
}

/// Write `map` to `<stem>.png` and `<stem>.svg`.
pub fn heat_map(stem: &Path, map: &HeatMap) -> Result<()> {
    write_both(
        stem,
        |p| draw_heat(BitMapBackend::new(p, SIZE).into_drawing_area(), map),
        |s| draw_heat(SVGBackend::with_string(s, SIZE).into_drawing_area(), map),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_chart_and_heat_map_write_valid_png_and_svg() {
        let dir = std::env::temp_dir().join(format!("vehsim-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let chart = LineChart {
            title: "sine".into(),
            x_label: "t (s)".into(),
            y_label: "y (m)".into(),
            series: vec![Series {
                label: "a".into(),
                points: (0..50).map(|i| (i as f64 * 0.1, (i as f64 * 0.1).sin())).collect(),
            }],
        };
        line_chart(&dir.join("lines"), &chart).unwrap();
        let map = HeatMap {
            title: "grid".into(),
            x_label: "x (mm)".into(),
            y_label: "y (mm)".into(),
            value_label: "p (kPa)".into(),
            x_range: (0.0, 4.0),
            y_range: (0.0, 3.0),
            values: vec![vec![1.0, 2.0, 3.0, 4.0], vec![2.0, 3.0, 4.0, 5.0], vec![3.0, 4.0, 5.0, 6.0]],
        };
        heat_map(&dir.join("heat"), &map).unwrap();
        for f in ["lines.png", "heat.png"] {
            let b = std::fs::read(dir.join(f)).unwrap();
            assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "{f} is not a PNG");
        }
        for f in ["lines.svg", "heat.svg"] {
            let s = std::fs::read_to_string(dir.join(f)).unwrap();
            assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"), "{f} is not an SVG");
            assert!(s.contains("<text"), "{f} has no text");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
