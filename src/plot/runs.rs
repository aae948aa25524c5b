//! The standard charts of a results folder (one run, or a batch with run_NNNN/ folders and a
//! summary.csv): yaw rate, front and rear slip angle, speed, steering, lateral acceleration (with
//! the friction limit ±μg), contact temperature, roll angle and wheel loads where present, the
//! trajectory at equal scale (with the ISO 3888-2 cones, vehicle outlines and cone strikes when the
//! manoeuvre has a course), and for constant-radius runs the steer angle against lateral
//! acceleration with the fitted understeer gradient and its 95 % interval (ISO 4138).
//!
//! How many runs a chart shows decides its form ([`plan`]):
//! - up to [`MAX_LINES`] runs (or up to twice that when two swept factors can be told apart by
//!   colour and line style): one chart, a line per run; colour for one swept factor, line style
//!   for a second; legend labels are the swept values (file stems for paths);
//! - more runs, with a swept factor of at most [`MAX_PANELS`] values: small multiples, a panel per
//!   value of that factor, its runs as lines (if few) or as percentile bands;
//! - otherwise one chart of percentile bands (median, 25–75 %, 5–95 %) over all runs.
//!
//! Channels with several columns (front/rear, four wheels) get a panel per column when there is
//! more than one run. Every chart that leaves something out says so in a note under it.

use std::path::{Path, PathBuf};

use super::{
    coincidence_note, figure, xy_chart, Band, Figure, LineStyle, RefLine, Series, XyChart, PALETTE_LEN, STYLES,
};
use crate::output::num::sig;
use crate::output::table::Table;
use crate::output::write_atomic;
use crate::output::Staged;
use vehsim_core::error::{Error, Result};
use vehsim_spec::files::read_input;

/// Above this many runs a batch gets no charts automatically (a note in plots/NOTE.txt says how
/// to draw them; `vehsim plot` draws them at any size).
pub const MAX_OVERLAID_RUNS: usize = 200;

/// Most lines told apart in one chart (the palette's size).
pub const MAX_LINES: usize = PALETTE_LEN;

/// Most panels of a small-multiples figure.
pub const MAX_PANELS: usize = 12;

/// Standard gravity for the μg line, m/s².
const G: f64 = 9.80665;

/// One run to draw.
struct RunData {
    /// Swept (key, value) pairs as in summary.csv.
    params: Vec<(String, String)>,
    /// Name of a single run (its summary.json), used when nothing is swept.
    name: String,
    table: Table,
    layout: Option<serde_json::Value>,
    strikes: Vec<f64>,
    /// Surface friction of the run (summary.json `mu`).
    mu: Option<f64>,
    /// Steady states (a_y in m/s², road-wheel steer in rad) and the fitted gradient, if any.
    steady: Vec<(f64, f64)>,
    gradient: Option<Gradient>,
}

/// The understeer gradient as summary.json gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Gradient {
    rad_per_mps2: f64,
    ci95: [f64; 2],
    intercept_rad: f64,
}

/// A swept value as shown in legends: the file stem for a path, the value otherwise.
pub fn short_value(v: &str) -> String {
    let v = v.trim().trim_matches('"');
    if v.contains('/') || v.contains('\\') || v.ends_with(".toml") || v.ends_with(".tir") || v.ends_with(".csv") {
        let name = v.rsplit(['/', '\\']).next().unwrap_or(v);
        name.split_once('.').map_or(name, |(stem, _)| stem).to_string()
    } else {
        v.to_string()
    }
}

/// A swept key as shown: its last dotted part (`maneuver.speed_mps` -> `speed_mps`).
pub fn short_key(k: &str) -> String {
    k.trim_matches('"').rsplit('.').next().unwrap_or(k).to_string()
}

/// A swept key whose value differs between runs, with its distinct values in first-seen order.
#[derive(Debug, Clone, PartialEq)]
pub struct Factor {
    pub key: String,
    pub values: Vec<String>,
}

/// The factors of a batch: the keys of `params` (one list per run) that take more than one value.
pub fn factors(params: &[Vec<(String, String)>]) -> Vec<Factor> {
    let Some(first) = params.first() else { return Vec::new() };
    let mut out = Vec::new();
    for (i, (key, _)) in first.iter().enumerate() {
        let mut values: Vec<String> = Vec::new();
        for p in params {
            if let Some((_, v)) = p.get(i) {
                let v = short_value(v);
                if !values.contains(&v) {
                    values.push(v);
                }
            }
        }
        if values.len() > 1 {
            out.push(Factor { key: key.clone(), values });
        }
    }
    out
}

/// A run's legend label: its values of the factors, comma-separated; a number carries its key
/// (`speed_mps=8.0`), a name or file stem stands alone (`class_a`).
fn label_of(params: &[(String, String)], factors: &[Factor]) -> String {
    factors
        .iter()
        .filter_map(|f| {
            let v = short_value(&params.iter().find(|(k, _)| *k == f.key)?.1);
            Some(if v.parse::<f64>().is_ok() { format!("{}={v}", short_key(&f.key)) } else { v })
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The index of a run's value of `f`.
fn value_index(params: &[(String, String)], f: &Factor) -> usize {
    params
        .iter()
        .find(|(k, _)| *k == f.key)
        .and_then(|(_, v)| f.values.iter().position(|x| *x == short_value(v)))
        .unwrap_or(0)
}

/// Line styles of `runs` in one chart: colour for the factor with more values, line style for
/// a second one when exactly two factors vary and both fit; otherwise a colour per run.
/// Returns the styles and a sentence naming the encoding.
pub fn styles(params: &[Vec<(String, String)>], factors: &[Factor]) -> (Vec<LineStyle>, String) {
    let by_run = || (0..params.len()).map(|i| LineStyle { colour: i, ..LineStyle::default() }).collect();
    match factors {
        [f] if f.values.len() <= PALETTE_LEN => (
            params.iter().map(|p| LineStyle { colour: value_index(p, f), ..LineStyle::default() }).collect(),
            format!("Colour: {}.", short_key(&f.key)),
        ),
        [a, b] => {
            let (c, s) = if a.values.len() >= b.values.len() { (a, b) } else { (b, a) };
            if c.values.len() <= PALETTE_LEN && s.values.len() <= STYLES.len() {
                let legend: Vec<String> =
                    s.values.iter().enumerate().map(|(i, v)| format!("{} {v}", STYLES[i])).collect();
                (
                    params
                        .iter()
                        .map(|p| LineStyle {
                            colour: value_index(p, c),
                            stroke: value_index(p, s),
                            ..LineStyle::default()
                        })
                        .collect(),
                    format!(
                        "Colour: {}; line style: {} ({}).",
                        short_key(&c.key),
                        short_key(&s.key),
                        legend.join(", ")
                    ),
                )
            } else {
                (by_run(), String::new())
            }
        }
        _ => (by_run(), String::new()),
    }
}

/// The form of the comparison charts of a batch.
#[derive(Debug, Clone, PartialEq)]
pub enum Plan {
    /// Every run a line in one chart.
    Overlay,
    /// A panel per value of factor `factor` (index into the factors); inside a panel, lines when
    /// it holds at most [`MAX_LINES`] runs, percentile bands otherwise.
    Panels { factor: usize },
    /// Percentile bands over all runs in one chart.
    Bands,
}

/// Choose the form for `n` runs with `factors`.
pub fn plan(n: usize, factors: &[Factor]) -> Plan {
    if n <= MAX_LINES {
        return Plan::Overlay;
    }
    if let [a, b] = factors {
        let (c, s) = if a.values.len() >= b.values.len() { (a, b) } else { (b, a) };
        if n <= 2 * MAX_LINES && c.values.len() <= PALETTE_LEN && s.values.len() <= STYLES.len() {
            return Plan::Overlay;
        }
    }
    // The factor of most values that still fits the panels: the smallest panels.
    let best = factors
        .iter()
        .enumerate()
        .filter(|(_, f)| f.values.len() <= MAX_PANELS)
        .max_by_key(|(i, f)| (f.values.len(), usize::MAX - i));
    match best {
        Some((factor, _)) => Plan::Panels { factor },
        None => Plan::Bands,
    }
}

fn load_run(dir: &Path, params: &[(String, String)]) -> Result<Option<RunData>> {
    let ts = dir.join("timeseries.csv");
    if !ts.exists() {
        return Ok(None);
    }
    let table = Table::read(&ts)?;
    // A time series the charts can use: a t_s column, at least one row, finite increasing times.
    let Some(t) = table.column("t_s") else {
        return Err(Error::input(&ts, "not a vehsim time series: its header has no t_s column"));
    };
    if t.is_empty() {
        return Err(Error::input(&ts, "no data rows (only a header): nothing to plot"));
    }
    if !t[0].is_finite() {
        return Err(Error::input(&ts, "line 2: t_s is not a number (a damaged time series)"));
    }
    if let Some(k) = t.windows(2).position(|w| !(w[1] > w[0]) || !w[1].is_finite() || !w[0].is_finite()) {
        return Err(Error::input(&ts, format!("line {}: t_s does not increase (a damaged time series)", k + 3)));
    }
    let layout = match std::fs::read_to_string(dir.join("layout.json")) {
        Ok(t) => serde_json::from_str(&t).ok(),
        Err(_) => None,
    };
    let summary = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .unwrap_or_default();
    let strikes = summary
        .get("events")
        .and_then(|e| e.as_array())
        .into_iter()
        .flatten()
        .filter(|e| e.get("kind").and_then(|k| k.as_str()) == Some("cone_strike"))
        .filter_map(|e| e.get("t_s").and_then(|t| t.as_f64()))
        .collect();
    let num = |v: &serde_json::Value, k: &str| v.get(k).and_then(|x| x.as_f64());
    let steady = summary
        .get("steady_states")
        .and_then(|s| s.as_array())
        .into_iter()
        .flatten()
        .filter_map(|s| Some((num(s, "ay_mps2")?, num(s, "steer_rad")?)))
        .collect();
    let gradient = summary.get("understeer_gradient").and_then(|g| {
        let ci = g.get("ci95_rad_per_mps2")?.as_array()?;
        Some(Gradient {
            rad_per_mps2: num(g, "rad_per_mps2")?,
            ci95: [ci.first()?.as_f64()?, ci.get(1)?.as_f64()?],
            intercept_rad: num(g, "intercept_rad")?,
        })
    });
    Ok(Some(RunData {
        params: params.to_vec(),
        name: summary.get("name").and_then(|n| n.as_str()).unwrap_or("run").to_string(),
        table,
        layout,
        strikes,
        mu: num(&summary, "mu"),
        steady,
        gradient,
    }))
}

/// A run's swept parameters: (key, value) in the batch's column order.
type Params = Vec<(String, String)>;

/// The run folders named in a batch's summary.csv, with their swept parameters.
fn batch_rows(dir: &Path) -> Result<Vec<(String, Params)>> {
    let text = read_input(&dir.join("summary.csv"))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let pstart = 2;
    let pend = header.iter().position(|c| *c == "passed").unwrap_or(pstart);
    Ok(lines
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let name = f.first()?.to_string();
            let params = (pstart..pend.min(f.len())).map(|i| (header[i].to_string(), f[i].to_string())).collect();
            Some((name, params))
        })
        .collect())
}

/// The runs of a results folder, in order, with their swept parameters.
fn load_runs(dir: &Path) -> Result<Vec<RunData>> {
    if !dir.join("summary.csv").exists() {
        return Ok(load_run(dir, &[])?.into_iter().collect());
    }
    let mut runs = Vec::new();
    for (name, params) in batch_rows(dir)? {
        if let Some(r) = load_run(&dir.join(name), &params)? {
            runs.push(r);
        }
    }
    Ok(runs)
}

/// The chart's runs and how each is labelled and styled.
struct Group<'a> {
    runs: Vec<&'a RunData>,
    labels: Vec<String>,
    styles: Vec<LineStyle>,
}

/// `y` of `run` against time, scaled.
fn channel(run: &RunData, x: &str, y: &str, scale: f64) -> Option<Vec<(f64, f64)>> {
    let (xs, ys) = (run.table.column(x)?, run.table.column(y)?);
    Some(xs.iter().zip(ys).map(|(a, b)| (*a, b * scale)).collect())
}

/// Linear interpolation of `pts` (x ascending) at `x`; `None` outside their range.
fn interpolate(pts: &[(f64, f64)], x: f64) -> Option<f64> {
    let i = pts.partition_point(|p| p.0 < x);
    let b = *pts.get(i)?;
    if b.0 == x {
        return Some(b.1);
    }
    let a = *pts.get(i.checked_sub(1)?)?;
    let u = (x - a.0) / (b.0 - a.0);
    u.is_finite().then_some(a.1 + u * (b.1 - a.1))
}

/// The `p`-quantile (0–1) of sorted values, linear between order statistics.
pub fn quantile(sorted: &[f64], p: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        n => {
            let h = p.clamp(0.0, 1.0) * (n - 1) as f64;
            let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
            sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
        }
    }
}

/// Median and the 25–75 % and 5–95 % bands of `curves` on the x values of the longest one;
/// an x where fewer than three curves have data is left out.
pub fn percentile_bands(curves: &[Vec<(f64, f64)>], colour: usize, suffix: &str) -> (Series, Vec<Band>) {
    let grid: Vec<f64> = curves
        .iter()
        .max_by(|a, b| {
            a.last().map_or(f64::NEG_INFINITY, |p| p.0).total_cmp(&b.last().map_or(f64::NEG_INFINITY, |p| p.0))
        })
        .map(|c| c.iter().map(|p| p.0).collect())
        .unwrap_or_default();
    let (mut median, mut inner, mut outer) = (Vec::new(), Vec::new(), Vec::new());
    for x in grid {
        let mut v: Vec<f64> = curves.iter().filter_map(|c| interpolate(c, x)).filter(|v| v.is_finite()).collect();
        if v.len() < 3 {
            continue;
        }
        v.sort_by(f64::total_cmp);
        median.push((x, quantile(&v, 0.5)));
        inner.push((x, quantile(&v, 0.25), quantile(&v, 0.75)));
        outer.push((x, quantile(&v, 0.05), quantile(&v, 0.95)));
    }
    (
        Series { label: format!("median{suffix}"), points: median },
        vec![
            Band { label: format!("5–95 % of runs{suffix}"), colour, alpha: 0.18, points: outer },
            Band { label: format!("25–75 %{suffix}"), colour, alpha: 0.35, points: inner },
        ],
    )
}

/// The ±μg lines for the friction values of `runs` (one pair per value, at most four values;
/// beyond that the lowest and highest), on the sides (sign of a_y) that `chart`'s data reaches.
fn mu_g_for(chart: &XyChart, runs: &[&RunData]) -> Vec<RefLine> {
    let ys = || chart.series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).filter(|y| y.is_finite());
    let (neg, pos) = (ys().any(|y| y < 0.0), ys().any(|y| y > 0.0));
    let sign = if pos && neg {
        "±"
    } else if neg {
        "−"
    } else {
        ""
    };
    mu_g_lines(runs)
        .into_iter()
        .filter(|r| (r.y > 0.0 && pos) || (r.y < 0.0 && neg))
        .map(|r| RefLine { label: r.label.replacen("±", sign, 1), ..r })
        .collect()
}

/// The ±μg lines for the friction values of `runs` (one pair per value, at most four values;
/// beyond that the lowest and highest).
fn mu_g_lines(runs: &[&RunData]) -> Vec<RefLine> {
    let mut mus: Vec<f64> = runs.iter().filter_map(|r| r.mu).filter(|m| m.is_finite() && *m > 0.0).collect();
    mus.sort_by(f64::total_cmp);
    mus.dedup();
    if mus.len() > 4 {
        mus = vec![mus[0], mus[mus.len() - 1]];
    }
    mus.iter()
        .flat_map(|&mu| {
            let label = format!("±μg = {} m/s² (μ = {})", sig(mu * G, 3), sig(mu, 3));
            [RefLine { label: label.clone(), y: mu * G }, RefLine { label, y: -mu * G }]
        })
        .collect()
}

/// One time chart (`cols` of each run) for `group`: lines per run, or bands when `bands`.
fn time_panel(group: &Group, title: &str, ylabel: &str, cols: &[(&str, &str)], scale: f64, bands: bool) -> XyChart {
    let mut chart =
        XyChart { title: title.into(), x_label: "time t (s)".into(), y_label: ylabel.into(), ..XyChart::default() };
    for (j, (col, suffix)) in cols.iter().enumerate() {
        let curves: Vec<(usize, Vec<(f64, f64)>)> =
            group.runs.iter().enumerate().filter_map(|(i, r)| Some((i, channel(r, "t_s", col, scale)?))).collect();
        if bands && curves.len() >= 3 {
            let all: Vec<Vec<(f64, f64)>> = curves.into_iter().map(|c| c.1).collect();
            let (median, b) = percentile_bands(&all, j, suffix);
            chart.styles.push(LineStyle { colour: j, ..LineStyle::default() });
            chart.series.push(median);
            chart.bands.extend(b);
        } else {
            for (i, points) in curves {
                let label = format!("{}{suffix}", group.labels[i]);
                let mut st = group.styles[i];
                if cols.len() > 1 && group.runs.len() == 1 {
                    st = LineStyle { colour: j, ..LineStyle::default() };
                }
                chart.styles.push(st);
                chart.series.push(Series { label, points });
            }
        }
    }
    chart
}

/// The runs of a batch split by `plan`: (panel title, group) pairs; one untitled group unless
/// panels. `note` receives the encoding of styles.
fn groups<'a>(runs: &'a [RunData], factors: &[Factor], plan: &Plan, note: &mut String) -> Vec<(String, Group<'a>)> {
    let params: Vec<Vec<(String, String)>> = runs.iter().map(|r| r.params.clone()).collect();
    let labels: Vec<String> =
        runs.iter().map(|r| if factors.is_empty() { r.name.clone() } else { label_of(&r.params, factors) }).collect();
    let make = |idx: Vec<usize>, inner: &[Factor], note: &mut String| {
        let p: Vec<Vec<(String, String)>> = idx.iter().map(|&i| params[i].clone()).collect();
        let (styles, how) = styles(&p, inner);
        if note.is_empty() {
            *note = how;
        }
        Group {
            runs: idx.iter().map(|&i| &runs[i]).collect(),
            labels: idx
                .iter()
                .map(|&i| if inner.is_empty() { labels[i].clone() } else { label_of(&params[i], inner) })
                .collect(),
            styles,
        }
    };
    match plan {
        Plan::Panels { factor } => {
            let f = &factors[*factor];
            let inner: Vec<Factor> =
                factors.iter().enumerate().filter(|(i, _)| i != factor).map(|(_, f)| f.clone()).collect();
            f.values
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    let idx: Vec<usize> = (0..runs.len()).filter(|&i| value_index(&params[i], f) == k).collect();
                    (format!("{} = {v}", short_key(&f.key)), make(idx, &inner, note))
                })
                .collect()
        }
        _ => vec![(String::new(), make((0..runs.len()).collect(), factors, note))],
    }
}

/// Draw one time channel for every run: a chart, or a figure of panels.
#[allow(clippy::too_many_arguments)]
fn time_chart(
    dir: &Path,
    runs: &[RunData],
    factors: &[Factor],
    stem: &str,
    title: &str,
    ylabel: &str,
    cols: &[(&str, &str)],
    scale: f64,
) -> Result<bool> {
    let present: Vec<(&str, &str)> =
        cols.iter().copied().filter(|(c, _)| runs.iter().any(|r| r.table.column(c).is_some())).collect();
    if present.is_empty() {
        return Ok(false);
    }
    let plan = plan(runs.len(), factors);
    let mut note = String::new();
    let is_ay = present.iter().any(|(c, _)| *c == "ay_mps2");
    let many = runs.len() > 1;
    if present.len() > 1 && many {
        // A panel per column (front/rear, wheels), all runs in each.
        let bands = plan != Plan::Overlay;
        let g = groups(runs, factors, &if bands { Plan::Bands } else { Plan::Overlay }, &mut note);
        let panels =
            present.iter().map(|c| time_panel(&g[0].1, c.1.trim(), ylabel, &[(c.0, "")], scale, bands)).collect();
        if bands {
            note = format!("{} runs: median and percentile bands. {note}", runs.len());
        }
        figure(&dir.join(stem), &Figure { title: title.into(), panels, note: note.trim().into() })?;
        return Ok(true);
    }
    let panels = groups(runs, factors, &plan, &mut note);
    let band_note = |n: usize| format!("{n} runs: median and percentile bands; each run is in its run folder. ");
    match plan {
        Plan::Panels { .. } => {
            let mut charts = Vec::new();
            let mut banded = false;
            for (ptitle, g) in &panels {
                let bands = g.runs.len() > MAX_LINES;
                banded |= bands;
                let mut c = time_panel(g, ptitle, ylabel, &present, scale, bands);
                if is_ay {
                    c.ref_lines = mu_g_for(&c, &g.runs);
                }
                charts.push(c);
            }
            if banded {
                note = format!("{}{note}", band_note(runs.len()));
            } else if charts.iter().any(|c| c.series.len() > 1)
                && charts.iter().all(|c| c.series.len() < 2 || !coincidence_note(&c.series, "").is_empty())
            {
                note = format!(
                    "{note} In each panel the runs coincide: {title} does not depend on the value told by colour here."
                );
            }
            figure(&dir.join(stem), &Figure { title: title.into(), panels: charts, note: note.trim().into() })?;
        }
        _ => {
            let g = &panels[0].1;
            let bands = plan == Plan::Bands;
            let mut c = time_panel(g, title, ylabel, &present, scale, bands);
            if is_ay {
                c.ref_lines = mu_g_for(&c, &g.runs);
            }
            c.note = if bands { format!("{}{note}", band_note(runs.len())) } else { note };
            if !bands && c.series.len() > 1 && !coincidence_note(&c.series, "").is_empty() {
                c.note = format!(
                    "{} All {} runs coincide: {title} does not depend on the swept values here.",
                    c.note,
                    c.series.len()
                );
            }
            c.note = c.note.trim().to_string();
            xy_chart(&dir.join(stem), &c)?;
        }
    }
    Ok(true)
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}

/// Sample the row nearest to time `t` of a run.
fn row_at(t: &Table, time: f64) -> Option<usize> {
    let ts = t.column("t_s")?;
    let i = ts.partition_point(|v| *v < time);
    if i >= ts.len() {
        return None;
    }
    Some(i)
}

/// The trajectory chart (equal scale): every run's path; with a course, the cones, the reference
/// path, outlines of the first run every second and every run's cone strikes. Titles name only
/// what is drawn.
fn trajectory_xy(runs: &[RunData], factors: &[Factor]) -> Option<XyChart> {
    let mut note = String::new();
    let overlay = plan(runs.len(), factors) == Plan::Overlay;
    let g = &groups(runs, factors, &Plan::Overlay, &mut note)[0].1;
    let mut chart =
        XyChart { x_label: "x (m)".into(), y_label: "y (m)".into(), equal_aspect: true, ..XyChart::default() };
    for (i, r) in g.runs.iter().enumerate() {
        if let Some(points) = channel(r, "x_m", "y_m", 1.0) {
            let (label, style) = if overlay {
                (g.labels[i].clone(), g.styles[i])
            } else {
                (String::new(), LineStyle { colour: 0, faint: true, ..LineStyle::default() })
            };
            chart.series.push(Series { label, points });
            chart.styles.push(style);
        }
    }
    if chart.series.is_empty() {
        return None;
    }
    if !overlay {
        note = format!(
            "{} runs drawn alike (too many to tell apart); cone strikes are not marked. Each run's path and events are in its run folder.",
            runs.len()
        );
    }
    let title = if runs.len() > 1 { format!("Trajectories of {} runs", runs.len()) } else { "Trajectory".to_string() };
    let mut parts: Vec<String> = Vec::new();
    if let Some(layout) = runs.iter().find_map(|r| r.layout.clone()) {
        let gates = layout.get("gates").and_then(|g| g.as_array()).cloned().unwrap_or_default();
        for g in &gates {
            let f = |k: &str| g.get(k).and_then(|v| v.as_f64()).unwrap_or(0.0);
            let (x0, x1) = (f("x0_m"), f("x1_m"));
            let n = ((x1 - x0) / 3.0).ceil().max(1.0) as usize;
            for i in 0..=n {
                let x = x0 + (x1 - x0) * i as f64 / n as f64;
                chart.markers.push((x, f("y_right_m")));
                chart.markers.push((x, f("y_left_m")));
            }
        }
        if !gates.is_empty() {
            parts.push("orange triangles: ISO 3888-2 cones".into());
        }
        if let Some(path) = layout.get("reference_path").and_then(|p| p.as_array()) {
            let pts: Vec<(f64, f64)> =
                path.iter().filter_map(|p| Some((p.get(0)?.as_f64()?, p.get(1)?.as_f64()?))).collect();
            if !pts.is_empty() {
                chart.ref_paths.push(Series { label: "reference path".into(), points: pts });
            }
        }
        if let Some(body) = layout.get("body") {
            let b = |k: &str| body.get(k).and_then(|v| v.as_f64()).unwrap_or(0.0);
            let (front, rear, hw) = (b("front_m"), b("rear_m"), 0.5 * b("width_m"));
            // Outlines of the first run only (one set keeps the chart readable).
            let r = &runs[0];
            if let (Some(xs), Some(ys), Some(yaw), Some(ts)) =
                (r.table.column("x_m"), r.table.column("y_m"), r.table.column("yaw_rad"), r.table.column("t_s"))
            {
                let t_end = ts.last().copied().unwrap_or(0.0);
                let mut t = 0.0;
                while t <= t_end {
                    if let Some(i) = row_at(&r.table, t) {
                        let (s, c) = yaw[i].sin_cos();
                        let at = |px: f64, py: f64| (xs[i] + px * c - py * s, ys[i] + px * s + py * c);
                        chart.outlines.push(vec![at(front, hw), at(front, -hw), at(-rear, -hw), at(-rear, hw)]);
                    }
                    t += 1.0;
                }
            }
            if !chart.outlines.is_empty() {
                parts.push(
                    if runs.len() > 1 {
                        "grey boxes: outline of the first run every 1 s"
                    } else {
                        "grey boxes: outline every 1 s"
                    }
                    .into(),
                );
            }
        }
    }
    for r in runs.iter().filter(|_| overlay) {
        let (Some(xs), Some(ys)) = (r.table.column("x_m"), r.table.column("y_m")) else { continue };
        for &t_hit in &r.strikes {
            if let Some(i) = row_at(&r.table, t_hit) {
                chart.highlights.push((xs[i], ys[i]));
            }
        }
    }
    if !chart.highlights.is_empty() {
        parts.push("red crosses: cone strikes".into());
    }
    chart.title = title;
    if !parts.is_empty() {
        note = format!("{}. {note}", capitalise(&parts.join("; ")));
    }
    chart.note = note.trim().to_string();
    Some(chart)
}

/// Steer angle against lateral acceleration over the steady states of constant-radius runs, with
/// the fitted understeer gradient K (solid) and lines at the ends of its 95 % interval (dashed,
/// through the mean point, which the fit passes through).
fn steer_xy(runs: &[RunData], factors: &[Factor]) -> Option<XyChart> {
    let mut note = String::new();
    let g = &groups(runs, factors, &Plan::Overlay, &mut note)[0].1;
    let fitted: Vec<usize> =
        (0..g.runs.len()).filter(|&i| g.runs[i].gradient.is_some() && g.runs[i].steady.len() >= 3).collect();
    if fitted.is_empty() {
        return None;
    }
    let shown = &fitted[..fitted.len().min(MAX_LINES)];
    let deg_per_g = |k: f64| k.to_degrees() * G;
    let mut chart = XyChart {
        x_label: "lateral acceleration a_y (m/s²)".into(),
        y_label: "road-wheel steer angle δ (deg)".into(),
        ..XyChart::default()
    };
    for (n, &i) in shown.iter().enumerate() {
        let r = g.runs[i];
        let Some(k) = r.gradient else { continue };
        let colour = if shown.len() == g.runs.len() { g.styles[i].colour } else { n };
        let name = if runs.len() == 1 || g.labels[i].is_empty() { String::new() } else { format!("{}: ", g.labels[i]) };
        let pts: Vec<(f64, f64)> = r.steady.iter().map(|&(ay, d)| (ay, d.to_degrees())).collect();
        let (lo, hi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.0), b.max(p.0)));
        let mean_ay = pts.iter().map(|p| p.0).sum::<f64>() / pts.len() as f64;
        let line = |slope: f64| {
            let at = |ay: f64| (k.intercept_rad + k.rad_per_mps2 * mean_ay + slope * (ay - mean_ay)).to_degrees();
            vec![(lo, at(lo)), (hi, at(hi))]
        };
        chart.series.push(Series { label: format!("{name}steady states"), points: pts });
        chart.styles.push(LineStyle { colour, points_only: true, ..LineStyle::default() });
        chart.series.push(Series {
            label: format!(
                "{name}K = {} deg/g (95 %: {} to {})",
                sig(deg_per_g(k.rad_per_mps2), 3),
                sig(deg_per_g(k.ci95[0]), 3),
                sig(deg_per_g(k.ci95[1]), 3)
            ),
            points: line(k.rad_per_mps2),
        });
        chart.styles.push(LineStyle { colour, ..LineStyle::default() });
        for (j, s) in k.ci95.iter().enumerate() {
            chart.series.push(Series {
                label: if j == 0 { format!("{name}95 % interval of K") } else { String::new() },
                points: line(*s),
            });
            chart.styles.push(LineStyle { colour, stroke: 1, ..LineStyle::default() });
        }
    }
    chart.title = "Steer vs lateral acceleration (ISO 4138)".into();
    note = format!(
        "Points: steady-state means; solid: least-squares fit, slope K = understeer gradient; dashed: slopes at the ends \
         of its 95 % interval, through the mean point. {note}"
    );
    if fitted.len() > shown.len() {
        note = format!(
            "{note} Only the first {} of {} fitted runs are drawn; the rest are in their summary.json.",
            shown.len(),
            fitted.len()
        );
    }
    chart.note = note.trim().to_string();
    Some(chart)
}

/// Draw every standard chart of the results folder `results` into `out/plots/`; returns the
/// charts written (stems). A folder with no time series is an error.
pub fn plot_results(results: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let runs = load_runs(results)?;
    if runs.is_empty() {
        return Err(Error::input(
            results,
            "no timeseries.csv found here or in its run folders (was `timeseries = false`?)",
        ));
    }
    let params: Vec<Vec<(String, String)>> = runs.iter().map(|r| r.params.clone()).collect();
    let factors = factors(&params);
    // A fresh plots/ folder swapped in whole: a symlink named plots is refused, never followed.
    let dest = out.join("plots");
    let staged = Staged::new(&dest)?;
    let dir = staged.path().to_path_buf();
    let mut written = Vec::new();
    let deg = 180.0 / std::f64::consts::PI;
    // (file stem, title, y label, (column, legend suffix) per curve, scale to the plotted unit)
    type ChartDef<'a> = (&'a str, &'a str, &'a str, &'a [(&'a str, &'a str)], f64);
    let charts: [ChartDef; 9] = [
        ("yaw_rate", "Yaw rate", "yaw rate r (rad/s)", &[("yaw_rate_radps", "")], 1.0),
        ("slip_front", "Front slip angle", "front slip angle α_f (deg)", &[("alpha_front_rad", "")], deg),
        ("slip_rear", "Rear slip angle", "rear slip angle α_r (deg)", &[("alpha_rear_rad", "")], deg),
        ("speed", "Speed", "forward speed v_x (m/s)", &[("vx_mps", "")], 1.0),
        ("steer", "Road-wheel steer angle", "steer angle δ (deg)", &[("steer_rad", "")], deg),
        ("lateral_acceleration", "Lateral acceleration", "a_y (m/s²)", &[("ay_mps2", "")], 1.0),
        (
            "contact_temperature",
            "Contact temperature",
            "contact temperature (°C)",
            &[("contact_temp_front_c", " front"), ("contact_temp_rear_c", " rear")],
            1.0,
        ),
        ("roll", "Roll angle", "roll angle φ (deg)", &[("roll_rad", "")], deg),
        (
            "wheel_loads",
            "Wheel loads",
            "normal load F_z (N)",
            &[("fz_fl_n", " FL"), ("fz_fr_n", " FR"), ("fz_rl_n", " RL"), ("fz_rr_n", " RR")],
            1.0,
        ),
    ];
    for (stem, title, ylabel, cols, scale) in charts {
        if time_chart(&dir, &runs, &factors, stem, title, ylabel, cols, scale)? {
            written.push(dest.join(stem));
        }
    }
    for (stem, chart) in [("trajectory", trajectory_xy(&runs, &factors)), ("steer_vs_ay", steer_xy(&runs, &factors))] {
        if let Some(chart) = chart {
            xy_chart(&dir.join(stem), &chart)?;
            written.push(dest.join(stem));
        }
    }
    if written.is_empty() {
        // Nothing drawn: the staged folder is dropped and the old plots stay.
        return Err(Error::input(
            results,
            "none of the standard charts could be drawn: the time series hold none of their columns",
        ));
    }
    staged.commit()?;
    Ok(written)
}

/// The charts a finished batch draws by itself: all of [`plot_results`] up to
/// [`MAX_OVERLAID_RUNS`] runs; above that none, and `plots/NOTE.txt` says why and how to draw
/// them. Returns the charts written.
pub fn plot_batch(results: &Path, runs: usize, name: &str) -> Result<Vec<PathBuf>> {
    if runs <= MAX_OVERLAID_RUNS {
        return plot_results(results, results);
    }
    let dest = results.join("plots");
    let staged = Staged::new(&dest)?;
    let note = format!(
        "No charts were drawn for this batch: {runs} runs exceed the {MAX_OVERLAID_RUNS} drawn automatically.\n\
         Draw them (percentile bands and small multiples) with: vehsim plot <results>/{name}\n"
    );
    write_atomic(&staged.path().join("NOTE.txt"), note.as_bytes())?;
    staged.commit()?;
    Ok(Vec::new())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(kv: &[(&str, &str)]) -> Vec<(String, String)> {
        kv.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// The 10-run class batch: five vehicle files times two tyre models.
    fn classes() -> Vec<Vec<(String, String)>> {
        let mut out = Vec::new();
        for c in ["a", "b", "c", "d", "e"] {
            for t in ["pacejka", "atiim_pacejka"] {
                out.push(p(&[("vehicle", &format!("../../vehicles/classes/class_{c}.toml")), ("tyre_model", t)]));
            }
        }
        out
    }

    #[test]
    fn labels_are_file_stems_and_short_keys() {
        assert_eq!(short_value("../../vehicles/classes/class_a.toml"), "class_a");
        assert_eq!(short_value("\"vehicles\\\\sedan.toml\""), "sedan");
        assert_eq!(short_value("0.15"), "0.15");
        assert_eq!(short_key("maneuver.speed_mps"), "speed_mps");
        let params = classes();
        let f = factors(&params);
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].values, ["class_a", "class_b", "class_c", "class_d", "class_e"]);
        assert_eq!(label_of(&params[3], &f), "class_b, atiim_pacejka");
        assert!(params.iter().all(|q| !label_of(q, &f).contains('/')));
        let num = vec![
            p(&[("maneuver.speed_mps", "8.0"), ("surface.mu", "0.1")]),
            p(&[("maneuver.speed_mps", "12.0"), ("surface.mu", "0.2")]),
        ];
        assert_eq!(label_of(&num[1], &factors(&num)), "speed_mps=12.0, mu=0.2");
    }

    #[test]
    fn two_factors_get_colour_and_line_style_and_every_run_differs() {
        let params = classes();
        let f = factors(&params);
        let (st, how) = styles(&params, &f);
        assert_eq!(how, "Colour: vehicle; line style: tyre_model (solid pacejka, dashed atiim_pacejka).");
        // Same vehicle, same colour; same tyre, same stroke; no two runs drawn alike.
        assert_eq!(st[0].colour, st[1].colour);
        assert_ne!(st[0].stroke, st[1].stroke);
        assert_eq!(st[1].stroke, st[3].stroke);
        for i in 0..st.len() {
            for j in 0..i {
                assert_ne!(st[i], st[j], "runs {i} and {j} drawn alike");
            }
        }
        // Class A and class E no longer share a colour (the old eight-colour palette repeated).
        assert_ne!(super::super::palette(st[0].colour), super::super::palette(st[8].colour));
        assert_eq!(plan(params.len(), &f), Plan::Overlay);
    }

    #[test]
    fn large_batches_get_panels_or_bands() {
        // 10 speeds x 10 friction values: a panel per value of one factor, ten lines each.
        let mut params = Vec::new();
        for v in 0..10 {
            for m in 0..10 {
                params.push(p(&[
                    ("maneuver.speed_mps", &format!("{}", 8 + v)),
                    ("surface.mu", &format!("0.{}", 10 + m)),
                ]));
            }
        }
        let f = factors(&params);
        assert_eq!(plan(100, &f), Plan::Panels { factor: 0 });
        // 40 x 25 (no factor fits the panels): bands.
        let f = vec![
            Factor { key: "a".into(), values: (0..40).map(|i| i.to_string()).collect() },
            Factor { key: "b".into(), values: (0..25).map(|i| i.to_string()).collect() },
        ];
        assert_eq!(plan(1000, &f), Plan::Bands);
        // One factor of 30 values: too many colours, too many panels.
        let f = vec![Factor { key: "a".into(), values: (0..30).map(|i| i.to_string()).collect() }];
        assert_eq!(plan(30, &f), Plan::Bands);
        assert_eq!(plan(12, &f), Plan::Overlay);
    }

    #[test]
    fn percentile_bands_match_order_statistics() {
        // Curves y = k for k = 1..=9 on the same x: median 5, quartiles 3 and 7, 5-95 % 1.4 and 8.6.
        let curves: Vec<Vec<(f64, f64)>> = (1..=9).map(|k| (0..4).map(|i| (i as f64, k as f64)).collect()).collect();
        let (median, bands) = percentile_bands(&curves, 0, "");
        assert_eq!(median.points, vec![(0.0, 5.0), (1.0, 5.0), (2.0, 5.0), (3.0, 5.0)]);
        assert!(bands[1].points.iter().all(|b| b.1 == 3.0 && b.2 == 7.0));
        assert!(bands[0].points.iter().all(|b| (b.1 - 1.4).abs() < 1e-12 && (b.2 - 8.6).abs() < 1e-12));
        // A run that ended early only counts where it has data; x with fewer than 3 runs is left out.
        let short = vec![vec![(0.0, 0.0), (1.0, 0.0)], vec![(0.0, 1.0), (3.0, 1.0)], vec![(0.0, 2.0), (3.0, 2.0)]];
        let (m, _) = percentile_bands(&short, 0, "");
        assert_eq!(m.points.iter().map(|q| q.0).collect::<Vec<_>>(), vec![0.0]);
        assert!(quantile(&[], 0.5).is_nan());
    }

    fn run(mu: f64) -> RunData {
        RunData {
            params: Vec::new(),
            name: "circle".into(),
            table: Table::parse(Path::new("x.csv"), "t_s,x_m,y_m\n0,0,0\n1,40,40\n2,0,80\n").unwrap(),
            layout: None,
            strikes: Vec::new(),
            mu: Some(mu),
            steady: Vec::new(),
            gradient: None,
        }
    }

    #[test]
    fn trajectories_are_equal_aspect_and_titles_name_only_what_is_drawn() {
        let c = trajectory_xy(&[run(0.15)], &[]).unwrap();
        assert!(c.equal_aspect);
        assert_eq!(c.title, "Trajectory");
        // No course: no cones, outlines or strikes, and no text about them.
        assert!(c.markers.is_empty() && c.outlines.is_empty() && c.highlights.is_empty());
        assert!(!c.note.contains("cone") && !c.note.contains("outline"), "{}", c.note);
    }

    #[test]
    fn steer_chart_draws_the_fit_through_the_mean_point_and_its_interval() {
        let mut r = run(0.15);
        // delta = 0.07 + 0.004 a_y exactly (rad), K interval [0.003, 0.005] rad per m/s^2.
        r.steady = [0.5, 1.0, 1.5, 2.0].iter().map(|&ay| (ay, 0.07 + 0.004 * ay)).collect();
        r.gradient = Some(Gradient { rad_per_mps2: 0.004, ci95: [0.003, 0.005], intercept_rad: 0.07 });
        let c = steer_xy(&[r], &[]).unwrap();
        // Points, fit, two interval lines.
        assert_eq!(c.series.len(), 4);
        assert!(c.styles[0].points_only && !c.styles[1].points_only && c.styles[2].stroke != 0);
        let deg = 180.0 / std::f64::consts::PI;
        let fit = &c.series[1].points;
        assert!(
            (fit[0].1 - (0.07 + 0.004 * 0.5) * deg).abs() < 1e-12
                && (fit[1].1 - (0.07 + 0.004 * 2.0) * deg).abs() < 1e-12
        );
        // K in deg/g: 0.004 rad/(m/s^2) x 57.2958 x 9.80665 = 2.2475 deg/g.
        assert!(
            c.series[1].label.contains("K = 2.25 deg/g") && c.series[1].label.contains("1.69 to 2.81"),
            "{}",
            c.series[1].label
        );
        // The interval lines cross the fit at the mean a_y (1.25 m/s^2).
        for ci in &c.series[2..] {
            let at =
                |pts: &[(f64, f64)], x: f64| pts[0].1 + (pts[1].1 - pts[0].1) * (x - pts[0].0) / (pts[1].0 - pts[0].0);
            assert!((at(&ci.points, 1.25) - at(fit, 1.25)).abs() < 1e-12);
        }
        assert!(steer_xy(&[run(0.15)], &[]).is_none(), "no steady states, no chart");
    }

    #[test]
    fn a_batch_above_the_limit_gets_a_note_instead_of_charts() {
        let dir = std::env::temp_dir().join(format!("vehsim-plot-note-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert!(plot_batch(&dir, MAX_OVERLAID_RUNS + 1, "big").unwrap().is_empty());
        let note = std::fs::read_to_string(dir.join("plots/NOTE.txt")).unwrap();
        assert!(note.contains(&format!("{} runs", MAX_OVERLAID_RUNS + 1)) && note.contains("vehsim plot"), "{note}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn mu_g_lines_come_in_pairs_at_plus_minus_mu_g() {
        let runs = [run(0.15), run(0.15), run(0.3)];
        let refs: Vec<&RunData> = runs.iter().collect();
        let l = mu_g_lines(&refs);
        assert_eq!(l.len(), 4);
        assert!((l[0].y - 0.15 * 9.80665).abs() < 1e-12 && l[1].y == -l[0].y);
        assert!(l[0].label.contains("1.47 m/s²") && l[0].label.contains("μ = 0.150"), "{}", l[0].label);
    }
}
