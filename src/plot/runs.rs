//! The standard charts of a results folder (one run, or a batch with run_NNNN/ folders and a
//! summary.csv): yaw rate, front and rear slip angle, speed, steering, lateral acceleration,
//! contact temperature, roll angle and wheel loads where present, each overlaid for every run
//! (the dissertation's Fig. 6.7–6.9 form), and the trajectory with the ISO 3888-2 cone layout,
//! vehicle outlines every second and cone strikes marked. Written as PNG and SVG to `plots/`.

use std::path::{Path, PathBuf};

use super::{xy_chart, Series, XyChart};
use crate::error::{read_input, Error, Result};
use crate::output::Staged;
use crate::output::table::Table;

/// Above this many runs a batch is not overlaid automatically (`vehsim plot` still does it).
pub const MAX_OVERLAID_RUNS: usize = 24;

/// One run to draw: its legend label and its folder.
struct RunData {
    label: String,
    table: Table,
    layout: Option<serde_json::Value>,
    strikes: Vec<f64>,
}

/// Legend label: the swept values, or for a single run the name in its summary.json.
fn run_label(summary: Option<&serde_json::Value>, params: &[(String, String)]) -> String {
    if params.is_empty() {
        summary.and_then(|s| s.get("name")).and_then(|n| n.as_str()).unwrap_or("run").to_string()
    } else {
        params.iter().map(|(k, v)| format!("{}={v}", k.rsplit('.').next().unwrap_or(k))).collect::<Vec<_>>().join(", ")
    }
}

fn load_run(dir: &Path, params: &[(String, String)]) -> Result<Option<RunData>> {
    let ts = dir.join("timeseries.csv");
    if !ts.exists() {
        return Ok(None);
    }
    let table = Table::read(&ts)?;
    let layout = match std::fs::read_to_string(dir.join("layout.json")) {
        Ok(t) => serde_json::from_str(&t).ok(),
        Err(_) => None,
    };
    let summary = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok());
    let strikes = summary
        .as_ref()
        .and_then(|v| v.get("events").and_then(|e| e.as_array()).cloned())
        .unwrap_or_default()
        .iter()
        .filter(|e| e.get("kind").and_then(|k| k.as_str()) == Some("cone_strike"))
        .filter_map(|e| e.get("t_s").and_then(|t| t.as_f64()))
        .collect();
    Ok(Some(RunData { label: run_label(summary.as_ref(), params), table, layout, strikes }))
}

/// The runs of a results folder, in order, with their swept parameters.
fn load_runs(dir: &Path) -> Result<Vec<RunData>> {
    let summary = dir.join("summary.csv");
    if !summary.exists() {
        return Ok(load_run(dir, &[])?.into_iter().collect());
    }
    let text = read_input(&summary)?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let pstart = 2;
    let pend = header.iter().position(|c| *c == "passed").unwrap_or(pstart);
    let mut runs = Vec::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let Some(name) = f.first() else { continue };
        let params: Vec<(String, String)> =
            (pstart..pend.min(f.len())).map(|i| (header[i].to_string(), f[i].to_string())).collect();
        if let Some(r) = load_run(&dir.join(name), &params)? {
            runs.push(r);
        }
    }
    Ok(runs)
}

fn series(runs: &[RunData], x: &str, y: &str, scale: f64, suffix: &str) -> Vec<Series> {
    runs.iter()
        .filter_map(|r| {
            let (xs, ys) = (r.table.column(x)?, r.table.column(y)?);
            Some(Series {
                label: format!("{}{suffix}", r.label),
                points: xs.iter().zip(ys).map(|(a, b)| (*a, b * scale)).collect(),
            })
        })
        .collect()
}

fn time_chart(
    dir: &Path,
    runs: &[RunData],
    stem: &str,
    title: &str,
    ylabel: &str,
    cols: &[(&str, &str)],
    scale: f64,
) -> Result<bool> {
    let mut s = Vec::new();
    for (col, suffix) in cols {
        s.extend(series(runs, "t_s", col, scale, suffix));
    }
    if s.is_empty() {
        return Ok(false);
    }
    let chart = XyChart {
        title: title.into(),
        x_label: "time t (s)".into(),
        y_label: ylabel.into(),
        series: s,
        ..XyChart::default()
    };
    xy_chart(&dir.join(stem), &chart)?;
    Ok(true)
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

fn trajectory_chart(dir: &Path, runs: &[RunData]) -> Result<bool> {
    let mut chart = XyChart {
        title: "Trajectory (outline of the first run every 1 s; red crosses: cone strikes)".into(),
        x_label: "x (m)".into(),
        y_label: "y (m)".into(),
        series: series(runs, "x_m", "y_m", 1.0, ""),
        ..XyChart::default()
    };
    if chart.series.is_empty() {
        return Ok(false);
    }
    if let Some(layout) = runs.iter().find_map(|r| r.layout.clone()) {
        for g in layout.get("gates").and_then(|g| g.as_array()).cloned().unwrap_or_default() {
            let f = |k: &str| g.get(k).and_then(|v| v.as_f64()).unwrap_or(0.0);
            let (x0, x1) = (f("x0_m"), f("x1_m"));
            let n = ((x1 - x0) / 3.0).ceil().max(1.0) as usize;
            for i in 0..=n {
                let x = x0 + (x1 - x0) * i as f64 / n as f64;
                chart.markers.push((x, f("y_right_m")));
                chart.markers.push((x, f("y_left_m")));
            }
        }
        if let Some(path) = layout.get("reference_path").and_then(|p| p.as_array()) {
            let pts: Vec<(f64, f64)> =
                path.iter().filter_map(|p| Some((p.get(0)?.as_f64()?, p.get(1)?.as_f64()?))).collect();
            chart.series.push(Series { label: "reference path".into(), points: pts });
        }
        let body = layout.get("body").cloned().unwrap_or_default();
        let b = |k: &str| body.get(k).and_then(|v| v.as_f64()).unwrap_or(0.0);
        let (front, rear, hw) = (b("front_m"), b("rear_m"), 0.5 * b("width_m"));
        // Outlines of the first run only (one set keeps the chart readable); strikes of every run.
        for (n, r) in runs.iter().enumerate() {
            let (Some(xs), Some(ys), Some(yaw), Some(ts)) =
                (r.table.column("x_m"), r.table.column("y_m"), r.table.column("yaw_rad"), r.table.column("t_s"))
            else {
                continue;
            };
            let t_end = ts.last().copied().unwrap_or(0.0);
            let mut t = if n == 0 { 0.0 } else { f64::INFINITY };
            while t <= t_end {
                if let Some(i) = row_at(&r.table, t) {
                    let (s, c) = yaw[i].sin_cos();
                    let at = |px: f64, py: f64| (xs[i] + px * c - py * s, ys[i] + px * s + py * c);
                    chart.outlines.push(vec![at(front, hw), at(front, -hw), at(-rear, -hw), at(-rear, hw)]);
                }
                t += 1.0;
            }
            for &ts_hit in &r.strikes {
                if let Some(i) = row_at(&r.table, ts_hit) {
                    chart.highlights.push((xs[i], ys[i]));
                }
            }
        }
    }
    xy_chart(&dir.join("trajectory"), &chart)?;
    Ok(true)
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
    // A fresh plots/ folder swapped in whole: a symlink named plots is refused, never followed.
    let dest = out.join("plots");
    let staged = Staged::new(&dest)?;
    let dir = staged.path().to_path_buf();
    let mut written = Vec::new();
    let deg = 180.0 / std::f64::consts::PI;
    // (file stem, title, y label, (column, legend suffix) per curve, scale to the plotted unit)
    type ChartDef<'a> = (&'a str, &'a str, &'a str, &'a [(&'a str, &'a str)], f64);
    let charts: [ChartDef; 9] = [
        ("yaw_rate", "Yaw rate", "yaw rate (rad/s)", &[("yaw_rate_radps", "")], 1.0),
        ("slip_front", "Front slip angle", "front slip angle (deg)", &[("alpha_front_rad", "")], deg),
        ("slip_rear", "Rear slip angle", "rear slip angle (deg)", &[("alpha_rear_rad", "")], deg),
        ("speed", "Speed", "forward speed vx (m/s)", &[("vx_mps", "")], 1.0),
        ("steer", "Road-wheel steer angle", "steer angle (deg)", &[("steer_rad", "")], deg),
        ("lateral_acceleration", "Lateral acceleration", "ay (m/s^2)", &[("ay_mps2", "")], 1.0),
        (
            "contact_temperature",
            "Contact temperature",
            "contact temperature (degC)",
            &[("contact_temp_front_c", " front"), ("contact_temp_rear_c", " rear")],
            1.0,
        ),
        ("roll", "Roll angle", "roll angle (deg)", &[("roll_rad", "")], deg),
        (
            "wheel_loads",
            "Wheel loads",
            "normal load (N)",
            &[("fz_fl_n", " FL"), ("fz_fr_n", " FR"), ("fz_rl_n", " RL"), ("fz_rr_n", " RR")],
            1.0,
        ),
    ];
    for (stem, title, ylabel, cols, scale) in charts {
        if time_chart(&dir, &runs, stem, title, ylabel, cols, scale)? {
            written.push(dest.join(stem));
        }
    }
    if trajectory_chart(&dir, &runs)? {
        written.push(dest.join("trajectory"));
    }
    staged.commit()?;
    Ok(written)
}
