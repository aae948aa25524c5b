//! `vehsim tyre FILE`: force curves of tyre providers over slip, load and contact-temperature rise.
//!
//! The spec (TOML, unknown keys rejected) names a tyre file and the sweeps:
//!
//! ```toml
//! name = "tyre_curves"                      # output folder name under the output root
//! tyre_file = "../vehicles/tyres/srtt_p225_60r16.toml"   # relative to this spec
//! providers = ["pacejka", "atiim_pacejka", "dugoff", "dugoff_thermal"]  # side-by-side comparison
//! temperature_providers = ["atiim_pacejka"] # providers swept over delta_t_k (Fig. 5.2/5.3)
//! loads_n = [4000.0]                        # N
//! delta_t_k = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]    # K, contact-temperature rises
//! compare_delta_t_k = 0.0                   # K, rise used in the comparison figure
//! mu_surface = 0.15
//! surface_temp_c = -3.0                     # degC (Fig. 5.2: ice at -3 degC)
//! slip_ratio = { min = 0.0, max = 0.4, points = 161 }
//! slip_angle_deg = { min = 0.0, max = 15.0, points = 151 }
//! ```
//!
//! Output in `<out_root>/<name>/`:
//! - `fx_vs_slip_ratio.csv`, `fy_vs_slip_angle.csv`: every curve, long format, units in the headers.
//! - `fx_vs_slip_ratio_<provider>_<load>N.png/.svg` and `fy_vs_slip_angle_<provider>_<load>N.*` for
//!   each temperature provider, one curve per rise (the dissertation's Fig. 5.2 and 5.3).
//! - `compare_fx_<load>N.*` and `compare_fy_<load>N.*`: every provider at `compare_delta_t_k`
//!   (Fig. 5.9/5.10).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::output::{write_atomic, Staged};
use crate::plot::{line_chart, LineChart, Series};
use vehsim_core::error::{Checker, Error, Result};
use vehsim_core::tyre::TyreInput;
use vehsim_core::tyre::{Tyre, TyreModelKind};
use vehsim_spec::files::{parse_toml, read_input, resolve};
use vehsim_spec::tyre::TyreFileSpec;

/// A closed range sampled at `points` evenly spaced values.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// First value.
    pub min: f64,
    /// Last value.
    pub max: f64,
    /// Number of samples, 2–100000.
    pub points: usize,
}

impl Sweep {
    fn values(&self) -> impl Iterator<Item = f64> + '_ {
        let n = self.points.max(2);
        (0..n).map(move |k| self.min + (self.max - self.min) * k as f64 / (n - 1) as f64)
    }
}

fn default_surface_temp() -> f64 {
    -3.0
}

/// Raw spec of the tyre command.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TyreSweepSpec {
    /// Output folder name (letters, digits, `-`, `_`).
    pub name: String,
    /// Tyre file, relative to the spec.
    pub tyre_file: String,
    /// Providers compared side by side.
    pub providers: Vec<String>,
    /// Providers swept over `delta_t_k` (default none).
    #[serde(default)]
    pub temperature_providers: Vec<String>,
    /// Normal loads, N.
    pub loads_n: Vec<f64>,
    /// Contact-temperature rises, K.
    #[serde(default)]
    pub delta_t_k: Vec<f64>,
    /// Rise used in the comparison figures, K (default 0).
    #[serde(default)]
    pub compare_delta_t_k: f64,
    /// Surface friction coefficient.
    pub mu_surface: f64,
    /// Bulk ice temperature, degC (default -3).
    #[serde(default = "default_surface_temp")]
    pub surface_temp_c: f64,
    /// Slip-ratio sweep (dimensionless).
    pub slip_ratio: Sweep,
    /// Slip-angle sweep, degrees.
    pub slip_angle_deg: Sweep,
}

struct Curve {
    provider: &'static str,
    fz: f64,
    dt: f64,
    /// (slip, fx, fy, mz) with slip = kappa or alpha in rad.
    points: Vec<(f64, f64, f64, f64)>,
}

fn parse_kinds(path: &Path, key: &str, names: &[String]) -> Result<Vec<TyreModelKind>> {
    names.iter().map(|n| n.parse::<TyreModelKind>().map_err(|m| Error::key(path, key, m))).collect()
}

fn check_sweep(c: &Checker, key: &str, s: &Sweep, lo: f64, hi: f64) -> Result<()> {
    c.range(&format!("{key}.min"), s.min, lo, hi)?;
    c.range(&format!("{key}.max"), s.max, lo, hi)?;
    c.require(&format!("{key}.max"), s.max, s.max > s.min, "expected max > min")?;
    c.require(
        &format!("{key}.points"),
        s.points as f64,
        (2..=100_000).contains(&s.points),
        "expected 2 <= points <= 100000",
    )?;
    Ok(())
}

/// Run the tyre command on spec `spec`, writing into `out_root/<name>/`; returns that folder.
pub fn run_tyre_command(spec: &Path, out_root: &Path) -> Result<PathBuf> {
    let text = read_input(spec)?;
    vehsim_spec::kind::expect_text(spec, &text, vehsim_spec::kind::SpecKind::TyreCurves)?;
    let s: TyreSweepSpec = parse_toml(spec, &text)?;
    let (providers, thermal) = validate(spec, &s)?;
    let tyres = build_tyres(spec, &s, &providers, &thermal)?;
    let run = CurveRun { s: &s, tyres: &tyres };
    // Written under a temporary name and swapped in whole (see output::replace).
    let dest = out_root.join(&s.name);
    let staged = Staged::new(&dest)?;
    let out = staged.path().to_path_buf();
    let (long_curves, lat_curves) = run.curves_and_charts(&out, &providers, &thermal)?;
    write_csvs(&out, &s, &long_curves, &lat_curves)?;
    staged.commit()?;
    Ok(dest)
}

/// The spec's values in range; the providers compared and those swept over temperature rises.
fn validate(spec: &Path, s: &TyreSweepSpec) -> Result<(Vec<TyreModelKind>, Vec<TyreModelKind>)> {
    let c = Checker::new(spec);
    if s.name.is_empty() || !s.name.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_') {
        return Err(Error::key(spec, "name", format!("'{}' must be non-empty letters, digits, '-' or '_'", s.name)));
    }
    let providers = parse_kinds(spec, "providers", &s.providers)?;
    let thermal = parse_kinds(spec, "temperature_providers", &s.temperature_providers)?;
    if providers.is_empty() && thermal.is_empty() {
        return Err(Error::key(spec, "providers", "name at least one provider"));
    }
    if s.loads_n.is_empty() {
        return Err(Error::key(spec, "loads_n", "give at least one load"));
    }
    for &l in &s.loads_n {
        c.range("loads_n", l, 1.0, 1e6)?;
    }
    if !thermal.is_empty() && s.delta_t_k.is_empty() {
        return Err(Error::key(spec, "delta_t_k", "temperature_providers need at least one rise"));
    }
    for &d in &s.delta_t_k {
        c.range("delta_t_k", d, -50.0, 50.0)?;
    }
    c.range("compare_delta_t_k", s.compare_delta_t_k, -50.0, 50.0)?;
    c.range("mu_surface", s.mu_surface, 0.0, 3.0)?;
    c.range("surface_temp_c", s.surface_temp_c, -80.0, 80.0)?;
    check_sweep(&c, "slip_ratio", &s.slip_ratio, -1.0, 10.0)?;
    check_sweep(&c, "slip_angle_deg", &s.slip_angle_deg, -90.0, 90.0)?;
    Ok((providers, thermal))
}

/// The tyre of every provider named, built from the spec's tyre file.
fn build_tyres(
    spec: &Path,
    s: &TyreSweepSpec,
    providers: &[TyreModelKind],
    thermal: &[TyreModelKind],
) -> Result<Vec<(TyreModelKind, Tyre)>> {
    let tyre_path = resolve(spec, &s.tyre_file);
    let tyre_spec = TyreFileSpec::load(&tyre_path).map_err(vehsim_core::error::referred_by(spec, "tyre_file"))?;
    let mut all: Vec<TyreModelKind> = providers.to_vec();
    for k in thermal {
        if !all.contains(k) {
            all.push(*k);
        }
    }
    all.iter().map(|&k| tyre_spec.build(&tyre_path, k).map(|t| (k, t))).collect::<Result<_>>()
}

/// One tyre-curve run: the spec and the providers' tyres.
struct CurveRun<'a> {
    s: &'a TyreSweepSpec,
    tyres: &'a [(TyreModelKind, Tyre)],
}

impl CurveRun<'_> {
    /// The input at load `fz` (N), contact rise `dt` (K), slip ratio and slip angle (rad).
    fn input(&self, fz: f64, dt: f64, kappa: f64, alpha: f64) -> TyreInput {
        TyreInput {
            fz_n: fz,
            kappa,
            alpha_rad: alpha,
            camber_rad: 0.0,
            vx_mps: 10.0,
            mu_surface: self.s.mu_surface,
            surface_temp_c: self.s.surface_temp_c,
            contact_temp_c: self.s.surface_temp_c + dt,
        }
    }

    /// Every kind in `providers` and `thermal` was built; a kind that is not found yields no
    /// curve rather than a panic.
    fn tyre_of(&self, k: TyreModelKind) -> Option<&Tyre> {
        self.tyres.iter().find(|(kk, _)| *kk == k).map(|(_, t)| t)
    }

    /// Fx, Fy, Mz over the slip ratios.
    fn long_curve(&self, k: TyreModelKind, fz: f64, dt: f64) -> Curve {
        let points = self
            .s
            .slip_ratio
            .values()
            .filter_map(|kappa| {
                let f = self.tyre_of(k)?.model.forces(&self.input(fz, dt, kappa, 0.0));
                Some((kappa, f.fx_n, f.fy_n, f.mz_nm))
            })
            .collect();
        Curve { provider: k.as_str(), fz, dt, points }
    }

    /// Fx, Fy, Mz over the slip angles.
    fn lat_curve(&self, k: TyreModelKind, fz: f64, dt: f64) -> Curve {
        let points = self
            .s
            .slip_angle_deg
            .values()
            .filter_map(|deg| {
                let f = self.tyre_of(k)?.model.forces(&self.input(fz, dt, 0.0, deg.to_radians()));
                Some((deg.to_radians(), f.fx_n, f.fy_n, f.mz_nm))
            })
            .collect();
        Curve { provider: k.as_str(), fz, dt, points }
    }

    /// Per load: the thermal providers' curves over the rises and the providers' curves at the
    /// comparison rise, each pair drawn into `out`; all curves returned (longitudinal, lateral).
    fn curves_and_charts(
        &self,
        out: &Path,
        providers: &[TyreModelKind],
        thermal: &[TyreModelKind],
    ) -> Result<(Vec<Curve>, Vec<Curve>)> {
        let s = self.s;
        let mut long_curves = Vec::new();
        let mut lat_curves = Vec::new();
        for &fz in &s.loads_n {
            for &k in thermal {
                let lc: Vec<Curve> = s.delta_t_k.iter().map(|&dt| self.long_curve(k, fz, dt)).collect();
                let yc: Vec<Curve> = s.delta_t_k.iter().map(|&dt| self.lat_curve(k, fz, dt)).collect();
                let stem = format!("{}_{}N", k.as_str(), fz.round());
                let label = |c: &Curve| format!("ΔT = {} K", c.dt);
                fx_fy_charts(
                    out,
                    (&format!("fx_vs_slip_ratio_{stem}"), &format!("fy_vs_slip_angle_{stem}")),
                    &format!("{} Fx vs slip ratio, Fz = {} N, mu = {}", k.as_str(), fz, s.mu_surface),
                    &format!("{} Fy vs slip angle, Fz = {} N, mu = {}", k.as_str(), fz, s.mu_surface),
                    (&lc, &yc),
                    label,
                )?;
                long_curves.extend(lc);
                lat_curves.extend(yc);
            }
            if !providers.is_empty() {
                let dt = s.compare_delta_t_k;
                let lc: Vec<Curve> = providers.iter().map(|&k| self.long_curve(k, fz, dt)).collect();
                let yc: Vec<Curve> = providers.iter().map(|&k| self.lat_curve(k, fz, dt)).collect();
                let label = |c: &Curve| c.provider.to_string();
                fx_fy_charts(
                    out,
                    (&format!("compare_fx_{}N", fz.round()), &format!("compare_fy_{}N", fz.round())),
                    &format!("Fx vs slip ratio, Fz = {} N, mu = {}, ΔT = {} K", fz, s.mu_surface, dt),
                    &format!("Fy vs slip angle, Fz = {} N, mu = {}, ΔT = {} K", fz, s.mu_surface, dt),
                    (&lc, &yc),
                    label,
                )?;
                long_curves.extend(lc);
                lat_curves.extend(yc);
            }
        }
        Ok((long_curves, lat_curves))
    }
}

/// fx_vs_slip_ratio.csv and fy_vs_slip_angle.csv of the curves, into `out`.
fn write_csvs(out: &Path, s: &TyreSweepSpec, long_curves: &[Curve], lat_curves: &[Curve]) -> Result<()> {
    let mut csv = String::from("provider,fz_n,delta_t_k,mu_surface,kappa,fx_n,fy_n,mz_nm,fx_over_fz\n");
    for cv in long_curves {
        for p in &cv.points {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{}",
                cv.provider,
                cv.fz,
                cv.dt,
                s.mu_surface,
                p.0,
                p.1,
                p.2,
                p.3,
                p.1 / cv.fz
            );
        }
    }
    write_atomic(&out.join("fx_vs_slip_ratio.csv"), csv.as_bytes())?;
    let mut csv = String::from("provider,fz_n,delta_t_k,mu_surface,alpha_deg,alpha_rad,fx_n,fy_n,mz_nm,fy_over_fz\n");
    for cv in lat_curves {
        for p in &cv.points {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{}",
                cv.provider,
                cv.fz,
                cv.dt,
                s.mu_surface,
                p.0.to_degrees(),
                p.0,
                p.1,
                p.2,
                p.3,
                p.2 / cv.fz
            );
        }
    }
    write_atomic(&out.join("fy_vs_slip_angle.csv"), csv.as_bytes())?;
    Ok(())
}

/// Draw the pair of charts of one sweep: Fx versus slip ratio from `curves.0` into `stems.0`,
/// Fy versus slip angle (in degrees) from `curves.1` into `stems.1`.
fn fx_fy_charts(
    out: &Path,
    stems: (&str, &str),
    fx_title: &str,
    fy_title: &str,
    curves: (&[Curve], &[Curve]),
    label: impl Fn(&Curve) -> String + Copy,
) -> Result<()> {
    line_chart(
        &out.join(stems.0),
        &chart(fx_title.to_string(), "slip ratio κ (-)", "Fx (N)", curves.0, label, |p| (p.0, p.1)),
    )?;
    line_chart(
        &out.join(stems.1),
        &chart(fy_title.to_string(), "slip angle α (deg)", "Fy (N)", curves.1, label, |p| (p.0.to_degrees(), p.2)),
    )
}

fn chart(
    title: String,
    x: &str,
    y: &str,
    curves: &[Curve],
    label: impl Fn(&Curve) -> String,
    map: impl Fn(&(f64, f64, f64, f64)) -> (f64, f64),
) -> LineChart {
    let series: Vec<Series> =
        curves.iter().map(|c| Series { label: label(c), points: c.points.iter().map(&map).collect() }).collect();
    LineChart {
        title,
        x_label: x.into(),
        y_label: y.into(),
        note: crate::plot::coincidence_note(&series, y.split(' ').next().unwrap_or(y)),
        series,
    }
}

/// `vehsim tyre`: run the spec and print where its results went.
pub(crate) fn cli_tyre(spec: &Path, out_root: &Path) -> Result<std::process::ExitCode> {
    let dir = run_tyre_command(spec, out_root)?;
    println!("{} -> {}", spec.display(), dir.display());
    Ok(std::process::ExitCode::SUCCESS)
}
