//! Conversion of the Stanford race-lap data set (one ASCII column per channel, 100 Hz; see the
//! data set's README) into the measured-run format, cut into segments.
//!
//! Channels used: `t.txt` (s), `delta.txt` (road-wheel angle, rad), `vx.txt` (m/s), `yawRate.txt`
//! (rad/s; the filtered `yawRateFilt.txt` is in deg/s and is not used), `ayCG.txt` (m/s^2, raw),
//! `vy.txt` (m/s), `axCG.txt` (m/s^2). The upstream sign conventions are mutually consistent
//! (yaw rate, ay and steer agree in sign); they are taken as ISO 8855 (left positive). The track
//! surface is taken as dry (mu = 1.0 in the sidecar); nothing in the data says otherwise.

use std::path::Path;

use vehsim_spec::files::read_input;

use vehsim_core::error::{Error, Result};

fn column(dir: &Path, name: &str) -> Result<Vec<f64>> {
    let p = dir.join(name);
    let text = read_input(&p)?;
    text.split_whitespace()
        .enumerate()
        .map(|(i, s)| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| Error::input(&p, format!("line {}: '{s}' is not a finite number", i + 1)))
        })
        .collect()
}

/// Convert the data set in `dir` into runs of `segment_s` seconds (the first `max_segments`),
/// written as `out/stanford_NN.csv` with a sidecar. Returns the files written.
pub fn convert(dir: &Path, out: &Path, segment_s: f64, max_segments: usize) -> Result<Vec<std::path::PathBuf>> {
    let names = ["t.txt", "delta.txt", "vx.txt", "yawRate.txt", "ayCG.txt", "vy.txt", "axCG.txt"];
    let cols: Vec<Vec<f64>> = names.iter().map(|n| column(dir, n)).collect::<Result<_>>()?;
    let n = cols[0].len();
    if let Some((i, c)) = cols.iter().enumerate().find(|(_, c)| c.len() != n) {
        return Err(Error::input(&dir.join(names[i]), format!("{} rows, but t.txt has {n}", c.len())));
    }
    std::fs::create_dir_all(out).map_err(|e| Error::Io { path: out.to_path_buf(), source: e })?;
    let per = ((segment_s / 0.01).round() as usize).max(101);
    let mut files = Vec::new();
    for (s, start) in (0..n).step_by(per).enumerate().take(max_segments) {
        let end = (start + per).min(n);
        if end - start < 101 {
            break;
        }
        let mut text = String::from("t,steer,vx,yaw_rate,ay,vy,ax\n");
        for k in start..end {
            let row: Vec<String> = cols.iter().map(|c| c[k].to_string()).collect();
            text.push_str(&row.join(","));
            text.push('\n');
        }
        let p = out.join(format!("stanford_{:02}.csv", s + 1));
        crate::output::write_atomic(&p, text.as_bytes())?;
        let side = p.with_extension("toml");
        crate::output::write_atomic(
            &side,
            b"# Dry race track (assumed; the data set does not say).\n[surface]\nmu = 1.0\n",
        )?;
        files.push(p);
    }
    Ok(files)
}
