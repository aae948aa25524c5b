//! `vehsim atiim FILE [--out DIR]`: run one ATIIM scenario and write its maps, the drawbar-pull
//! curve and a summary into `out_root/<name>/` (a temporary folder swapped in whole).
//!
//! Files: `pressure.csv` (kPa), `rise.csv` (K), `wet.csv` (1 = melting), `film.csv` (nm),
//! `friction.csv` (tau / p), `mu_visc.csv` (eq. 4.13, wet pixels), each row one grid row along
//! travel (leading edge first); a heat map `<same stem>.png/.svg` of each; `drawbar.csv` and
//! `drawbar.png/.svg`; `summary.json` (with `tread_bulk`, the tread band over a run at the
//! operating point, [`vehsim_core::contact::tread_bulk`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::output::{write_atomic, Staged};
use crate::plot::{heat_map, xy_chart, HeatMap, LineStyle, Series, XyChart};
use vehsim_core::contact::model::{drawbar_curve, slip_stiffness_per_fz, solve_patch_at, Kinematics, PatchResult};
use vehsim_core::contact::tread_bulk::{TreadBulk, RIG_TRACK_M, SRTT_ROLLING_RADIUS_M};
use vehsim_core::error::{Error, Result};
use vehsim_spec::contact::{Scenario, ScenarioSpec};

fn csv_grid(values: &[f64], cols: usize, digits: usize) -> String {
    let mut s = String::new();
    for row in values.chunks(cols.max(1)) {
        let line: Vec<String> = row.iter().map(|v| format!("{v:.digits$}")).collect();
        let _ = writeln!(s, "{}", line.join(","));
    }
    s
}

fn nested(values: &[f64], cols: usize) -> Vec<Vec<f64>> {
    values.chunks(cols.max(1)).map(|r| r.to_vec()).collect()
}

/// Slip ratios every 0.005 from the smallest to the largest of `listed`, with the listed ones
/// included, ascending and without repeats (what the drawbar chart draws).
fn fine_slips(listed: &[f64]) -> Vec<f64> {
    let (lo, hi) = listed.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &k| (a.min(k), b.max(k)));
    let mut out: Vec<f64> = listed.to_vec();
    if lo.is_finite() && hi.is_finite() {
        let n = ((hi - lo) / 0.005).ceil() as usize;
        out.extend((0..=n).map(|j| (lo + j as f64 * 0.005).min(hi)));
    }
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    out
}

/// Run the scenario in `spec` and write results into `out_root/<name>/`; returns that folder.
pub fn run_atiim_command(spec: &Path, out_root: &Path) -> Result<PathBuf> {
    let sc = ScenarioSpec::load(spec)?;
    // Written under a temporary name and swapped in whole (see output::replace).
    let dest = out_root.join(&sc.name);
    let staged = Staged::new(&dest)?;
    let dir = staged.path().to_path_buf();
    let op = sc.operating();
    let res = solve_patch_at(&sc.grid, &op, &sc.params);
    write_maps(&dir, &sc, &res)?;
    let curve =
        drawbar_curve(&sc.grid, &sc.params, sc.drawbar_speed_mps, sc.slip_angle_rad, sc.ice_temp_c, &sc.drawbar_slips);
    let mut csv =
        String::from("slip_ratio,drawbar_coeff,friction_coeff,wet_fraction,sliding_fraction,max_film_nm,mean_rise_k\n");
    for (k, s) in &curve {
        let _ = writeln!(
            csv,
            "{k:.4},{:.5},{:.5},{:.4},{:.4},{:.2},{:.4}",
            s.drawbar_coeff,
            s.friction_coeff,
            s.wet_fraction,
            s.sliding_fraction,
            s.max_film_m * 1e9,
            s.mean_rise_k
        );
    }
    write_atomic(&dir.join("drawbar.csv"), csv.as_bytes())?;
    // The chart draws the curve sampled every 0.5 % of slip over the listed range (a patch solve is
    // about a millisecond), with the listed slips of drawbar.csv as markers on it.
    let fine = fine_slips(&sc.drawbar_slips);
    let fine_curve = drawbar_curve(&sc.grid, &sc.params, sc.drawbar_speed_mps, sc.slip_angle_rad, sc.ice_temp_c, &fine);
    let mut series = vec![Series {
        label: "ATIIM (sum of tau dA / Fz)".into(),
        points: fine_curve.iter().map(|(k, s)| (k * 100.0, s.drawbar_coeff)).collect(),
    }];
    let mut styles = vec![LineStyle::default()];
    // Markers only where they stand apart (a dense list is the curve itself).
    if curve.len() <= 20 {
        series.push(Series {
            label: "listed slips (drawbar.csv)".into(),
            points: curve.iter().map(|(k, s)| (k * 100.0, s.drawbar_coeff)).collect(),
        });
        styles.push(LineStyle { points_only: true, ..LineStyle::default() });
    }
    xy_chart(
        &dir.join("drawbar"),
        &XyChart {
            title: format!("Drawbar pull vs slip at {} m/s, ice {:.0} °C", sc.drawbar_speed_mps, sc.ice_temp_c),
            x_label: "slip ratio (%)".into(),
            y_label: "drawbar-pull coefficient (-)".into(),
            note: format!("Scenario {}; the curve is solved every 0.5 % of slip and at each listed slip.", sc.name),
            series,
            styles,
            ..XyChart::default()
        },
    )?;
    let summary = serde_json::json!({
        "name": sc.name,
        "title": sc.title,
        "spec_file": spec.display().to_string(),
        "grid": { "rows": sc.grid.rows, "cols": sc.grid.cols, "pixel_length_m": sc.grid.dx_m, "pixel_width_m": sc.grid.dy_m },
        "operating": {
            "speed_mps": sc.speed_mps, "slip_ratio": sc.slip_ratio, "slip_angle_deg": sc.slip_angle_rad.to_degrees(),
            "ice_temp_c": sc.ice_temp_c, "roll_speed_mps": op.speeds().0, "slide_speed_mps": op.slide_speed_mps(),
        },
        "params": {
            "shore_a": sc.params.compound.shore_a, "youngs_modulus_mpa": sc.params.compound.youngs_modulus_pa() * 1e-6,
            "mu_dry": sc.params.mu_dry, "kappa": sc.params.film.kappa, "asperity_d_m": sc.params.film.asperity_d_m,
            "critical_film_m": sc.params.critical_film_m, "brush": sc.params.brush, "lock_time_s": sc.params.lock_time_s,
            "adhesion_peak": sc.params.dry.peak_gain, "peak_speed_mps": sc.params.dry.peak_speed_mps,
            "pressure_exponent": sc.params.dry.pressure_exponent, "temp_coeff_per_k": sc.params.dry.temp_coeff_per_k,
            "speed_scale_mps": sc.params.dry.speed_scale_mps, "speed_exponent": sc.params.dry.speed_exponent,
            "carcass_stiffness_n_per_m": sc.params.carcass_n_per_m, "rolling_resistance": sc.params.rolling_resistance,
            "slip_stiffness_per_fz": slip_stiffness_per_fz(&sc.grid, &sc.params, sc.speed_mps, sc.ice_temp_c),
        },
        "summary": res.summary,
        "tread_bulk": tread_bulk_json(&sc, &op, &res),
        "max_film_nm": res.summary.max_film_m * 1e9,
        "drawbar": curve.iter().map(|(k, s)| serde_json::json!({"slip_ratio": k, "coeff": s.drawbar_coeff, "friction_coeff": s.friction_coeff, "wet_fraction": s.wet_fraction})).collect::<Vec<_>>(),
    });
    let text = serde_json::to_string_pretty(&summary).map_err(|e| Error::Run(format!("summary.json: {e}")))?;
    write_atomic(&dir.join("summary.json"), text.as_bytes())?;
    staged.commit()?;
    Ok(dest)
}

/// The tread band over a run at the operating point (`tread_bulk`): its steady rise, time
/// constant, the rise after 60, 300 and 600 s from the ice temperature and after one run over the
/// rig's 16 ft track at the travel speed (70 s at 7 cm/s), and the interface's share.
fn tread_bulk_json(sc: &Scenario, op: &Kinematics, res: &PatchResult) -> serde_json::Value {
    let b = TreadBulk::new(
        &sc.params,
        &res.summary,
        sc.grid.load_n(),
        op.speeds().0,
        sc.grid.contact_area_m2(),
        sc.spec.tyre.tread_width_m,
        SRTT_ROLLING_RADIUS_M,
    );
    let run_s = RIG_TRACK_M / op.travel_speed_mps.max(1e-9);
    serde_json::json!({
        "model": b,
        "rig_track_m": RIG_TRACK_M,
        "rig_run_s": run_s,
        "rise_after_rig_run_k": b.rise_after_k(run_s),
        "contact_rise_after_rig_run_k": b.contact_rise_k(b.rise_after_k(run_s)),
        "rolling_radius_m": SRTT_ROLLING_RADIUS_M,
        "rise_after_60s_k": b.rise_after_k(60.0),
        "rise_after_300s_k": b.rise_after_k(300.0),
        "rise_after_600s_k": b.rise_after_k(600.0),
        "contact_rise_steady_k": b.contact_rise_k(b.steady_rise_k),
    })
}

/// (file stem, values for the CSV, title, colour-scale label, CSV decimals, values shown).
type MapRow<'a> = (&'a str, &'a Vec<f64>, &'a str, &'a str, usize, &'a Vec<f64>);

fn write_maps(dir: &Path, sc: &Scenario, r: &PatchResult) -> Result<()> {
    let g = &sc.grid;
    let cols = g.cols;
    let kpa: Vec<f64> = g.p_pa.iter().map(|p| p * 1e-3).collect();
    let wet: Vec<f64> = r.wet.iter().map(|w| if *w { 1.0 } else { 0.0 }).collect();
    let film_nm: Vec<f64> = r.film_m.iter().map(|h| h * 1e9).collect();
    // eq. 4.13 diverges in low-pressure edge pixels (partly groove, partly rubber): the map's colour
    // scale is capped at 1 so the patch stays readable; the CSV keeps the raw values.
    let mu_visc_shown: Vec<f64> = r.mu_visc.iter().map(|m| m.min(1.0)).collect();
    let maps: [MapRow; 6] = [
        ("pressure", &kpa, "contact pressure", "p (kPa)", 2, &kpa),
        ("rise", &r.rise_k, "temperature rise", "dT (K)", 4, &r.rise_k),
        ("wet", &wet, "wet (1) / dry (0)", "wet", 0, &wet),
        ("film", &film_nm, "water-film height", "h (nm)", 2, &film_nm),
        ("friction", &r.mu, "friction coefficient tau/p", "mu (-)", 4, &r.mu),
        ("mu_visc", &r.mu_visc, "viscous friction eq. 4.13, wet pixels (shown <= 1)", "mu_visc (-)", 4, &mu_visc_shown),
    ];
    let xr = (-0.5 * g.cols as f64 * g.dy_m * 1e3, 0.5 * g.cols as f64 * g.dy_m * 1e3);
    let yr = (0.0, g.rows as f64 * g.dx_m * 1e3);
    for (stem, vals, what, unit, digits, shown) in maps {
        write_atomic(&dir.join(format!("{stem}.csv")), csv_grid(vals, cols, digits).as_bytes())?;
        heat_map(
            &dir.join(stem),
            &HeatMap {
                title: format!("{}: {what}", sc.name),
                x_label: "lateral position y (mm)".into(),
                y_label: "distance behind leading edge (mm)".into(),
                value_label: unit.into(),
                x_range: xr,
                y_range: yr,
                values: nested(shown, cols),
                classes: if stem == "wet" { vec![(0.0, "dry".into()), (1.0, "wet".into())] } else { Vec::new() },
            },
        )?;
    }
    Ok(())
}

/// `vehsim atiim`: run the scenario and print where its results went.
pub(crate) fn cli_atiim(spec: &Path, out_root: &Path) -> Result<std::process::ExitCode> {
    let dir = run_atiim_command(spec, out_root)?;
    println!("{} -> {}", spec.display(), dir.display());
    Ok(std::process::ExitCode::SUCCESS)
}

#[cfg(test)]
mod fine_slip_tests {
    use super::fine_slips;

    #[test]
    fn fine_slips_keep_the_listed_ones_and_step_at_most_half_a_percent() {
        let listed = [0.0, 0.025, 0.05, 0.075, 0.1, 0.15, 0.4, 0.333];
        let f = fine_slips(&listed);
        assert!(listed.iter().all(|k| f.contains(k)), "{f:?}");
        assert_eq!((f[0], *f.last().unwrap()), (0.0, 0.4));
        assert!(f.windows(2).all(|w| w[1] > w[0] && w[1] - w[0] <= 0.005 + 1e-12), "{f:?}");
        assert_eq!(fine_slips(&[0.1]), vec![0.1]);
        assert!(fine_slips(&[]).is_empty());
    }
}
