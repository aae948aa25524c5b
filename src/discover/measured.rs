//! Measured runs: the `RUN.csv` format (header row, SI units) and its optional `RUN.toml` sidecar,
//! read and validated into a [`MeasuredRun`].
//!
//! Required columns: `t` (s), `steer` (road-wheel angle, rad, ISO 8855 positive left), `vx` (m/s),
//! `yaw_rate` (rad/s, positive counter-clockwise), `ay` (m/s^2, positive left). Optional: `x`, `y`
//! (m), `psi` (rad), `vy` (m/s), `ax` (m/s^2), `roll` (rad). Any other column is ignored with a
//! notice. Time must increase strictly (sampling need not be uniform), every value must be finite,
//! the run must last at least 1 s and at most 3600 s, the median sample interval must lie in
//! 0.1 ms to 1 s (else `t` is not in seconds), a logged position within 1e8 m, heading within
//! 1e5 rad and lateral velocity within 100 m/s in magnitude, |steer| must stay at or below
//! 1.2 rad (a larger value almost certainly means degrees or a steering-wheel angle), vx must not
//! be negative (beyond 0.5 m/s of noise) and the yaw rate must stay below |vx| / 1 m + 0.05 rad/s
//! (a car does not turn on the spot). Each violation is one bad-input error that names the file
//! and the row or column (exit code 2). A column in another common unit says so in its header
//! cell (`yaw_rate [deg/s]`) or the sidecar's `[units]`, and is converted to SI first
//! ([`super::units`]).
//!
//! Sidecar `RUN.toml` (same stem): `[surface] mu` (peak friction, (0, 2], default 1.0 with a
//! notice), `[surface] ice_temp_c` (degC; when given the run is on ice, otherwise it is taken as a
//! non-ice surface at -3 degC for temperature-dependent tyres), `[initial] vx` (m/s, default the
//! first measured vx).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use vehsim_spec::files::{parse_toml, read_input};
use vehsim_spec::maneuver::{ground_regions, BandRegion, PatchRegion, StretchRegion};

use vehsim_core::error::{Checker, Error, Result};

/// Required columns, in the order of the format.
pub const REQUIRED: [&str; 5] = ["t", "steer", "vx", "yaw_rate", "ay"];
/// Optional columns that are read (others are ignored).
pub const OPTIONAL: [&str; 6] = ["x", "y", "psi", "vy", "ax", "roll"];
/// Largest plausible road-wheel angle, rad.
pub const STEER_MAX_RAD: f64 = 1.2;
/// Shortest accepted run, s.
pub const MIN_DURATION_S: f64 = 1.0;
/// Longest accepted run, s (the manoeuvre files' longest duration): it bounds the replay's work.
pub const MAX_DURATION_S: f64 = 3600.0;
/// Range of the median sample interval, s: vehicle data is logged at 1 Hz to 10 kHz. Outside it
/// the time column is almost certainly in other units (ms, us) or not time at all.
pub const SAMPLE_INTERVAL_S: (f64, f64) = (1e-4, 1.0);
/// Negative forward speed taken as sensor noise around standstill, m/s.
pub const VX_NOISE_MPS: f64 = 0.5;
/// Yaw rate taken as sensor noise at standstill, rad/s.
pub const YAW_NOISE_RADPS: f64 = 0.05;
/// Largest magnitude of a logged position `x`, `y`, m (more than twice round the Earth: a
/// projected coordinate such as UTM is well within it).
pub const POSITION_MAX_M: f64 = 1e8;
/// Largest magnitude of a logged heading `psi`, rad (an unwrapped heading of some 16 000 turns).
pub const HEADING_MAX_RAD: f64 = 1e5;
/// Largest magnitude of a logged lateral velocity `vy`, m/s (the manoeuvre files' largest speed).
pub const VY_MAX_MPS: f64 = 100.0;

/// One measured run, validated.
#[derive(Debug, Clone)]
pub struct MeasuredRun {
    /// The CSV file it was read from.
    pub path: PathBuf,
    /// Short name (file stem).
    pub name: String,
    /// Sample times, s (strictly increasing).
    pub t: Vec<f64>,
    /// Road-wheel steer angle, rad.
    pub steer: Vec<f64>,
    /// Forward speed, m/s.
    pub vx: Vec<f64>,
    /// Yaw rate, rad/s.
    pub yaw_rate: Vec<f64>,
    /// Lateral acceleration, m/s^2.
    pub ay: Vec<f64>,
    /// Optional channels present in the file: (name, values).
    pub optional: Vec<(String, Vec<f64>)>,
    /// Peak surface friction from the sidecar (default 1.0).
    pub mu: f64,
    /// Ice (surface) temperature, degC (-3 when the sidecar gives none).
    pub ice_temp_c: f64,
    /// True when the sidecar gives `[surface] ice_temp_c`: the run is on ice, and contact heating
    /// (the `thermal_friction` effect) can act. A run without it is taken as a non-ice surface.
    pub on_ice: bool,
    /// Initial forward speed, m/s.
    pub initial_vx: f64,
    /// Friction regions on the run's ground, from its sidecar (none by default).
    pub regions: Regions,
    /// The run's road: constant bank and grade from its sidecar's `[road]` (flat by default).
    pub road: vehsim_core::vehicle::road::Road,
    /// Notices for the user (ignored columns, defaults taken).
    pub notices: Vec<String>,
}

/// Friction regions on a run's ground (sidecar `[[surface.patch]]`, `[[surface.band]]`,
/// `[[surface.stretch]]`, at most one of each): the engine's, with the equations of the
/// discovery's friction forms (docs/discover.md): each a friction factor 1 + (s - 1) w with 1 m
/// logistic edges.
pub use vehsim_core::vehicle::ground::GroundRegions as Regions;

impl MeasuredRun {
    /// Duration, s.
    pub fn duration_s(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0) - self.t.first().copied().unwrap_or(0.0)
    }

    /// An optional channel by name.
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        self.optional.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_slice())
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Sidecar {
    #[serde(default)]
    surface: SurfaceSection,
    #[serde(default)]
    initial: InitialSection,
    /// Units of the run's columns when not SI (`yaw_rate = "deg/s"`; [`super::units`]).
    #[serde(default)]
    units: BTreeMap<String, String>,
    road: Option<vehsim_spec::maneuver::RoadSection>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct SurfaceSection {
    mu: Option<f64>,
    ice_temp_c: Option<f64>,
    #[serde(default)]
    patch: Vec<PatchRegion>,
    #[serde(default)]
    band: Vec<BandRegion>,
    #[serde(default)]
    stretch: Vec<StretchRegion>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct InitialSection {
    vx: Option<f64>,
}

/// Read and validate a measured run (and its sidecar, when present).
pub fn read_run(path: &Path) -> Result<MeasuredRun> {
    let text = read_input(path)?;
    parse_run(path, &text)
}

/// Parse and validate the text of a measured run read from `path` (the sidecar is looked up next
/// to it: its `[units]` apply to the CSV, the rest to the run).
pub fn parse_run(path: &Path, text: &str) -> Result<MeasuredRun> {
    let side = path.with_extension("toml");
    if !side.exists() {
        let mut run = parse_run_csv(path, text)?;
        run.notices.push(format!(
            "{}: no sidecar {}; surface mu = 1.0 assumed, not ice (no contact heating)",
            path.display(),
            side.display()
        ));
        return Ok(run);
    }
    let sidecar: Sidecar = parse_toml(&side, &read_input(&side)?)?;
    let mut run = parse_run_csv_with(path, text, &side, &sidecar.units)?;
    apply_parsed(&mut run, &side, sidecar)?;
    Ok(run)
}

/// Parse and validate the CSV text of a measured run alone: no sidecar is looked up, so the run
/// keeps the defaults (mu 1.0, -3 degC, the first measured vx). `path` names the file in messages.
pub fn parse_run_csv(path: &Path, text: &str) -> Result<MeasuredRun> {
    parse_run_csv_with(path, text, path, &BTreeMap::new())
}

/// [`parse_run_csv`] with the column units `units` of the sidecar `side` (named in messages).
fn parse_run_csv_with(path: &Path, text: &str, side: &Path, units: &BTreeMap<String, String>) -> Result<MeasuredRun> {
    let mut rdr = csv::ReaderBuilder::new().has_headers(true).trim(csv::Trim::All).from_reader(text.as_bytes());
    let cells: Vec<String> = rdr
        .headers()
        .map_err(|e| Error::input(path, format!("cannot read the header row: {e}")))?
        .iter()
        .map(|s| s.to_string())
        .collect();
    let split: Vec<(&str, Option<&str>)> = cells.iter().map(|c| super::units::split_header(c)).collect();
    let headers: Vec<String> = split.iter().map(|(n, _)| n.to_string()).collect();
    let (used, notices) = header_columns(path, &headers)?;
    let mut cols = read_columns(path, &mut rdr, &used)?;
    for ((ci, name), col) in used.iter().zip(&mut cols) {
        let f = column_factor(path, side, name, split[*ci].1, units.get(name))?;
        if f != 1.0 {
            col.iter_mut().for_each(|v| *v *= f);
        }
    }
    if let Some(k) = units.keys().find(|k| !headers.contains(k)) {
        let what = if super::units::units_of(k).is_empty() {
            format!("'{k}' is not a column of the run format ({}, {})", REQUIRED.join(", "), OPTIONAL.join(", "))
        } else {
            format!("the run {} has no column '{k}'", path.display())
        };
        return Err(Error::key(side, &format!("units.{k}"), what));
    }
    let get = |name: &str| -> Vec<f64> {
        used.iter().position(|(_, n)| n == name).map(|j| cols[j].clone()).unwrap_or_default()
    };
    let t = get("t");
    check_time(path, &t)?;
    let (steer, vx, yaw_rate) = (get("steer"), get("vx"), get("yaw_rate"));
    check_channels(path, &steer, &vx, &yaw_rate)?;
    let bounded = [
        ("x", POSITION_MAX_M, "m"),
        ("y", POSITION_MAX_M, "m"),
        ("psi", HEADING_MAX_RAD, "rad"),
        ("vy", VY_MAX_MPS, "m/s"),
    ];
    for (col, max, unit) in bounded {
        let Some(j) = used.iter().position(|(_, n)| n == col) else { continue };
        if let Some((k, v)) = cols[j].iter().enumerate().find(|(_, v)| v.abs() > max) {
            return Err(Error::input(
                path,
                format!(
                    "line {}, column '{col}': {} {unit}; it must be at most {max:e} {unit} in magnitude",
                    k + 2,
                    vehsim_core::error::short_num(*v)
                ),
            ));
        }
    }
    let name = path.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| "run".into());
    let run = MeasuredRun {
        path: path.to_path_buf(),
        name,
        optional: OPTIONAL
            .iter()
            .filter(|o| headers.iter().any(|h| h == *o))
            .map(|o| (o.to_string(), get(o)))
            .collect(),
        initial_vx: vx[0],
        regions: Default::default(),
        road: Default::default(),
        t,
        steer,
        vx,
        yaw_rate,
        ay: get("ay"),
        mu: 1.0,
        ice_temp_c: -3.0,
        on_ice: false,
        notices,
    };
    Ok(run)
}

/// Columns of the run format in a CSV header: (index, name).
type Columns = Vec<(usize, String)>;

/// The header's columns of the run format, (index, name), every required one present and none
/// twice; a notice for each other column (ignored).
fn header_columns(path: &Path, headers: &[String]) -> Result<(Columns, Vec<String>)> {
    let mut notices = Vec::new();
    for r in REQUIRED {
        if !headers.iter().any(|h| h == r) {
            return Err(Error::input(
                path,
                format!(
                    "missing required column '{r}' (required: {}; found: {})",
                    REQUIRED.join(", "),
                    headers.join(", ")
                ),
            ));
        }
    }
    for (i, h) in headers.iter().enumerate() {
        if headers[..i].contains(h) {
            return Err(Error::input(path, format!("column '{h}' appears twice in the header")));
        }
        if !REQUIRED.contains(&h.as_str()) && !OPTIONAL.contains(&h.as_str()) {
            notices.push(format!("{}: column '{h}' ignored (not part of the run format)", path.display()));
        }
    }
    let used: Vec<(usize, String)> = headers
        .iter()
        .enumerate()
        .filter(|(_, h)| REQUIRED.contains(&h.as_str()) || OPTIONAL.contains(&h.as_str()))
        .map(|(i, h)| (i, h.clone()))
        .collect();
    Ok((used, notices))
}

/// The cells of the `used` columns, row by row, each a finite number.
fn read_columns(path: &Path, rdr: &mut csv::Reader<&[u8]>, used: &[(usize, String)]) -> Result<Vec<Vec<f64>>> {
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); used.len()];
    for (k, rec) in rdr.records().enumerate() {
        // Row numbers count the header as line 1.
        let line = k + 2;
        let rec = rec.map_err(|e| match e.kind() {
            csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
                Error::input(path, format!("line {line}: {len} fields, the header has {expected_len}"))
            }
            csv::ErrorKind::Utf8 { .. } => Error::input(path, format!("line {line}: not valid UTF-8 text")),
            _ => Error::input(path, format!("line {line}: unreadable CSV row")),
        })?;
        for (j, (ci, name)) in used.iter().enumerate() {
            let cell = rec.get(*ci).unwrap_or("");
            let v: f64 = cell.parse().map_err(|_| {
                Error::input(
                    path,
                    format!("line {line}, column '{name}': {} is not a number", vehsim_core::error::shown(cell)),
                )
            })?;
            if !v.is_finite() {
                return Err(Error::input(
                    path,
                    format!("line {line}, column '{name}': {cell} is not a finite number (NaN or infinity)"),
                ));
            }
            cols[j].push(v);
        }
    }
    Ok(cols)
}

/// Time: at least two rows, strictly increasing, in seconds (the median interval within what
/// vehicle data is logged at) and of a replayable duration.
fn check_time(path: &Path, t: &[f64]) -> Result<()> {
    if t.len() < 2 {
        return Err(Error::input(path, format!("{} data rows; a run needs at least 2", t.len())));
    }
    for k in 1..t.len() {
        if t[k] <= t[k - 1] {
            return Err(Error::input(
                path,
                format!(
                    "line {}, column 't': time {} s does not increase (previous row {} s); time must be strictly increasing",
                    k + 2,
                    t[k],
                    t[k - 1]
                ),
            ));
        }
    }
    let dur = t[t.len() - 1] - t[0];
    if dur < MIN_DURATION_S {
        return Err(Error::input(
            path,
            format!("the run lasts {dur:.3} s; at least {MIN_DURATION_S} s of data is needed"),
        ));
    }
    // The typical (median) interval: vehicle data is logged every 0.1 ms to 1 s.
    let mut dts: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    dts.sort_by(f64::total_cmp);
    let median_dt = dts[dts.len() / 2];
    if !(SAMPLE_INTERVAL_S.0..=SAMPLE_INTERVAL_S.1).contains(&median_dt) {
        let hint =
            if median_dt > SAMPLE_INTERVAL_S.1 { "is t in milliseconds or microseconds?" } else { "is t in seconds?" };
        return Err(Error::input(
            path,
            format!(
                "column 't': the samples are {} s apart (median); vehicle data is sampled every {} to {} s: {hint} \
                 (t must be in seconds)",
                vehsim_core::error::short_num(median_dt),
                SAMPLE_INTERVAL_S.0,
                SAMPLE_INTERVAL_S.1
            ),
        ));
    }
    if dur > MAX_DURATION_S {
        return Err(Error::input(
            path,
            format!(
                "the run lasts {} s; at most {MAX_DURATION_S} s is replayed (is t in seconds?)",
                vehsim_core::error::short_num(dur)
            ),
        ));
    }
    Ok(())
}

/// The steer a road-wheel angle in radians, vx forwards, and a yaw rate a rolling car can have.
fn check_channels(path: &Path, steer: &[f64], vx: &[f64], yaw_rate: &[f64]) -> Result<()> {
    if let Some((k, v)) = steer.iter().enumerate().find(|(_, v)| v.abs() > STEER_MAX_RAD) {
        return Err(Error::input(
            path,
            format!(
                "line {}, column 'steer': {v} rad exceeds {STEER_MAX_RAD} rad; steer must be the road-wheel angle in radians (degrees or a steering-wheel angle?)",
                k + 2
            ),
        ));
    }
    if let Some(k) = vx.iter().position(|v| *v < -VX_NOISE_MPS) {
        return Err(Error::input(
            path,
            format!(
                "line {}, column 'vx': {} m/s; the models drive forwards, so vx must be >= 0 (a reversed sign \
                 convention, or a run in reverse, which is not supported)",
                k + 2,
                vehsim_core::error::short_num(vx[k])
            ),
        ));
    }
    // A car turns only while it rolls: |r| <= |vx| tan(steer_max) / wheelbase, about |vx| / 1 m,
    // plus sensor noise.
    if let Some(k) = (0..vx.len()).find(|&k| yaw_rate[k].abs() > YAW_NOISE_RADPS + vx[k].abs() / 1.0) {
        return Err(Error::input(
            path,
            format!(
                "line {}: yaw rate {:.3} rad/s at vx = {:.3} m/s; a car cannot turn that fast at that speed (at most \
                 about vx / 1 m + {YAW_NOISE_RADPS} rad/s): is vx in m/s and the right signal?",
                k + 2,
                yaw_rate[k],
                vx[k]
            ),
        ));
    }
    Ok(())
}

/// The factor to SI of column `name` of the run `path`: from the unit of its header cell
/// (`header`), else of the sidecar `side`'s `[units]` (`listed`); 1 without either. A unit not
/// allowed for the column, or a header and a sidecar that disagree, is bad input.
fn column_factor(path: &Path, side: &Path, name: &str, header: Option<&str>, listed: Option<&String>) -> Result<f64> {
    let key = format!("units.{name}");
    match (header, listed) {
        (Some(h), Some(l)) if h != l => Err(Error::key(
            side,
            &key,
            format!("'{l}', but the header of {} gives the column in '{h}'; give one unit", path.display()),
        )),
        (Some(h), _) => super::units::si_factor(name, h).map_err(|e| Error::input(path, format!("header: {e}"))),
        (None, Some(l)) => super::units::si_factor(name, l).map_err(|e| Error::key(side, &key, e)),
        (None, None) => Ok(1.0),
    }
}

/// The allowed ranges of the sidecar's keys: the surface friction is the manoeuvre file's own
/// `surface.mu`; the ice temperature spans the manoeuvre's surface temperatures up to melting;
/// the initial speed either way up to the manoeuvre's largest speed.
pub mod sidecar_bounds {
    use vehsim_core::contact::thermal::MELT_C;
    use vehsim_core::error::Bound;
    use vehsim_spec::maneuver::bounds as m;

    pub const MU: Bound = m::MU;
    pub const ICE_TEMP_C: Bound = Bound::closed("surface.ice_temp_c", m::TEMPERATURE_C.lo, MELT_C, "degC");
    pub const INITIAL_VX: Bound = Bound::closed("initial.vx", -m::SPEED_MPS.hi, m::SPEED_MPS.hi, "m/s");
    /// The friction regions' ranges (declared with the engine's regions).
    pub use vehsim_core::vehicle::ground::region_bounds::*;
    /// The road's bank and grade (declared with the engine's road).
    pub use vehsim_core::vehicle::road::road_bounds::{BANK_DEG, GRADE_DEG};
}

/// Apply the text of a sidecar (read from `side`, named in messages) to `run`: surface friction,
/// ice temperature and initial speed, each checked against its allowed range.
pub fn apply_sidecar(run: &mut MeasuredRun, side: &Path, text: &str) -> Result<()> {
    apply_parsed(run, side, parse_toml(side, text)?)
}

/// [`apply_sidecar`] of a sidecar already parsed (its `[units]` are the CSV reader's).
fn apply_parsed(run: &mut MeasuredRun, side: &Path, s: Sidecar) -> Result<()> {
    let c = Checker::new(side);
    if let Some(mu) = s.surface.mu {
        run.mu = c.bound(&sidecar_bounds::MU, mu)?;
    } else {
        run.notices.push(format!("{}: no [surface] mu; 1.0 assumed", side.display()));
    }
    if let Some(tc) = s.surface.ice_temp_c {
        run.ice_temp_c = c.bound(&sidecar_bounds::ICE_TEMP_C, tc)?;
        run.on_ice = true;
    }
    if let Some(v) = s.initial.vx {
        run.initial_vx = c.bound(&sidecar_bounds::INITIAL_VX, v)?;
    }
    run.regions = ground_regions(side, &s.surface.patch, &s.surface.band, &s.surface.stretch)?;
    if let Some(r) = s.road {
        // Within its bounds, and a grade the run's tyres can climb at its speed.
        run.road = r.road(side, run.mu)?;
    }
    Ok(())
}

/// Write a run in the measured-run format: the required columns, then the optional channels
/// `optional` (name, one value per sample) in the order given.
pub fn run_csv(
    t: &[f64],
    steer: &[f64],
    vx: &[f64],
    yaw_rate: &[f64],
    ay: &[f64],
    optional: &[(String, Vec<f64>)],
) -> String {
    let mut s = String::from("t,steer,vx,yaw_rate,ay");
    for (name, _) in optional {
        s.push_str(&format!(",{name}"));
    }
    s.push('\n');
    for k in 0..t.len() {
        s.push_str(&format!("{},{},{},{},{}", t[k], steer[k], vx[k], yaw_rate[k], ay[k]));
        for (_, values) in optional {
            s.push_str(&format!(",{}", values[k]));
        }
        s.push('\n');
    }
    s
}

/// Write a sidecar with the surface friction and, on ice, the ice temperature.
pub fn sidecar_toml(mu: f64, ice_temp_c: Option<f64>) -> String {
    match ice_temp_c {
        Some(t) => format!("[surface]\nmu = {mu}\nice_temp_c = {t}\n"),
        None => format!("[surface]\nmu = {mu}\n"),
    }
}
