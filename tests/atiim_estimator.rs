//! The per-step estimator against the full patch model (on the 64 x 48 reference grid), its
//! behaviour in the engine loop and its spec.

mod common;

use std::path::Path;
use std::time::Instant;

use vehsim_core::contact::estimator::{node_ice_temp_c, roll_speed_for, FlashTable, Statistic, TableRanges, TyreBuild};
use vehsim_core::contact::model::PatchParams;
use vehsim_core::contact::TyreContact;
use vehsim_spec::contact::ContactSpec;

use common::atiim::{full_rise, reference_grid, srtt_build};

fn tyre() -> TyreBuild {
    srtt_build(PatchParams { brush: false, ..PatchParams::srtt(-5.0) })
}

fn full(tb: &TyreBuild, fz: f64, vs: f64, vr: f64, t: f64, stat: Statistic) -> f64 {
    full_rise(&reference_grid(tb, fz), tb, vs, vr, t, stat)
}

/// The default table (statistic `max`) against the full model's maximum pixel rise (SRTT
/// parameters, friction law with c_T = 0.03 /K). The hottest pixel of the coarse table grid moves
/// less smoothly with load and speed than the patch average, so between nodes the table is looser
/// (worst at small rises where the rolling heat is a large share of the flux).
#[test]
fn table_agrees_with_full_model_at_and_between_nodes() {
    table_agrees(Statistic::Max, 0.05, 0.20);
}

/// The `mean` table against the full model's patch-average rise (worst between nodes at rises
/// below 0.1 K that the rolling heat dominates, which does not scale with the sliding speed).
#[test]
fn mean_table_agrees_with_full_model_at_and_between_nodes() {
    table_agrees(Statistic::Mean, 0.05, 0.11);
}

fn table_agrees(stat: Statistic, node_tol: f64, mid_tol: f64) {
    let tb = tyre();
    let rg = TableRanges { statistic: stat, ..TableRanges::default() };
    let full = |tb: &TyreBuild, fz, vs, vr, t| full(tb, fz, vs, vr, t, stat);
    let t0 = Instant::now();
    let table = FlashTable::build(Path::new("t"), &tb, &rg).unwrap();
    eprintln!("table build {:?} ({} nodes)", t0.elapsed(), table.ln_g.len() + table.ln_r0.len());
    let (la, sa, ra) = (table.load.clone(), table.slide.clone(), table.roll.clone());
    let val = |a: &vehsim_core::contact::estimator::Axis, u: f64| {
        let k = (u.floor() as usize).min(a.n() - 1);
        let f = u - k as f64;
        if f > 0.0 {
            (1.0 - f) * a.node(k) + f * a.node(k + 1)
        } else {
            a.node(k)
        }
    };
    // nodes: (load, slide, slip-fraction) nodes at the temperatures of the w nodes,
    // -T = R0(T) e^w, with R0(T) the full model's dry rise with the friction of -40 degC times the
    // dry law's temperature factor at T
    let mut worst_node: f64 = 0.0;
    for il in [0, 2, la.n() - 1] {
        for is in [0, 1, sa.n() - 1] {
            for ir in [0, 3, ra.n() - 1] {
                let (fz, vs) = (val(&la, il as f64).exp(), val(&sa, is as f64).exp());
                let vr = roll_speed_for(vs, val(&ra, ir as f64).exp());
                let r0 = full(&tb, fz, vs, vr, -1e6);
                for iw in [0, 3, table.w.n() - 1] {
                    let t = node_ice_temp_c(r0.ln(), tb.params.dry.temp_coeff_per_k, val(&table.w, iw as f64));
                    let f = full(&tb, fz, vs, vr, t);
                    let e = table.rise_k(fz, vs, vr, t);
                    if f > 0.05 {
                        worst_node = worst_node.max(((e - f) / f).abs());
                    }
                }
            }
        }
    }
    eprintln!("worst node error {worst_node:.4}");
    assert!(worst_node < node_tol, "node error {worst_node}");
    // between nodes: cell centres in every coordinate (the worst place for multilinear
    // interpolation), over the physical range of a vehicle run (roll speed <= 60 m/s); rises
    // below 0.05 K are checked in absolute terms (within 0.03 K) instead.
    let mut worst_mid: f64 = 0.0;
    let mut n = 0;
    for il in (0..la.n() - 1).map(|k| k as f64 + 0.5) {
        for is in (0..sa.n() - 1).map(|k| k as f64 + 0.5) {
            for ir in (0..ra.n() - 1).map(|k| k as f64 + 0.5) {
                for &t in &[-25.0, -7.0, -4.0, -2.5, -1.5, -0.7, -0.3] {
                    let (fz, vs) = (val(&la, il).exp(), val(&sa, is).exp());
                    let vr = roll_speed_for(vs, val(&ra, ir).exp());
                    if vr > 60.0 {
                        continue;
                    }
                    let f = full(&tb, fz, vs, vr, t);
                    let e = table.rise_k(fz, vs, vr, t);
                    if f < 0.05 {
                        // negligible rises: absolute agreement
                        assert!((e - f).abs() < 0.03, "fz {fz} vs {vs} vr {vr} T {t}: table {e} full {f}");
                    } else {
                        n += 1;
                        let err = ((e - f) / f).abs();
                        if err > worst_mid {
                            eprintln!(
                                "mid fz {fz:.0} vs {vs:.3} vr {vr:.2} T {t:.1}: table {e:.4} full {f:.4} err {err:.3}"
                            );
                        }
                        worst_mid = worst_mid.max(err);
                    }
                }
            }
        }
    }
    assert!(n > 50);
    eprintln!("worst between-node error {worst_mid:.4} over {n} points");
    assert!(worst_mid < mid_tol, "between-node error {worst_mid}");
}

/// Flash heat priced with the transmitted force: F = mu_dry Fz reproduces the table's own flux;
/// with no melting (very cold ice) the rise is proportional to F; no force, no flash; the melting
/// cap still holds; the `max` table gives a larger rise than the `mean` table.
#[test]
fn flash_is_priced_with_the_transmitted_force() {
    let tb = tyre();
    let small = TableRanges { grid: (8, 8), load_n: (2000.0, 12000.0, 3), ..TableRanges::default() };
    let table = FlashTable::build(Path::new("t"), &tb, &small).unwrap();
    let mean = FlashTable::build(Path::new("t"), &tb, &TableRanges { statistic: Statistic::Mean, ..small }).unwrap();
    let mu = tb.params.mu_dry;
    for (fz, vs, vr) in [(4000.0, 0.5, 15.0), (7000.0, 2.0, 5.0), (3000.0, 0.05, 25.0)] {
        for t in [-1e6, -20.0, -3.0] {
            let r = table.rise_k(fz, vs, vr, t);
            assert_eq!(table.rise_k_for_force(fz, vs, vr, t, mu * fz), r);
            assert_eq!(table.rise_k_for_force(fz, vs, vr, t, 0.0), 0.0);
            assert!(mean.rise_k(fz, vs, vr, t) < r, "max table below mean table at {fz} {vs} {vr} {t}");
            assert!(table.rise_k_for_force(fz, vs, vr, t, 20.0 * mu * fz) <= -t, "melting cap");
        }
        let r = table.rise_k(fz, vs, vr, -1e6);
        for k in [0.1, 0.5, 2.0] {
            let rk = table.rise_k_for_force(fz, vs, vr, -1e6, k * mu * fz);
            assert!((rk / r - k).abs() < 1e-9 * k, "dry rise linear in the force: {rk} / {r} vs {k}");
        }
    }
    let spec: ContactSpec = toml::from_str("model = \"atiim\"\nstatistic = \"median\"").unwrap();
    let err = spec.build(Path::new("m.toml"), 2, -5.0).err().expect("must fail").to_string();
    assert!(err.contains("contact.statistic") && err.contains("max, mean") && err.contains("m.toml"), "{err}");
}

fn contact(fz: f64, vr: f64, vs: f64, f: f64, t: f64) -> TyreContact {
    TyreContact { fz_n: fz, roll_speed_mps: vr, slide_speed_mps: vs, friction_force_n: f, surface_temp_c: t }
}

#[test]
fn estimator_warms_only_by_rolling_without_sliding_heats_with_it_and_stays_finite() {
    let spec: ContactSpec = toml::from_str("model = \"atiim\"").unwrap();
    let t0 = Instant::now();
    let mut est = spec.build(Path::new("m.toml"), 2, -10.0).unwrap();
    eprintln!("build {:?}", t0.elapsed());
    let mut out = [0.0; 2];
    // the first sample advances over no time: both at the ice temperature; a standing tyre stays
    // there, a rolling one warms only by the band's rolling (hysteresis) heat: 0.5 x 0.010 x
    // 4000 N x 20 m/s = 400 W into a 1500-2000 J/K skin, under 0.1 K after 0.1 s
    est.update(0.0, &[contact(4000.0, 20.0, 0.0, 0.0, -10.0), contact(4000.0, 0.0, 0.0, 0.0, -10.0)], &mut out);
    assert_eq!(out, [-10.0, -10.0]);
    for _ in 0..10 {
        est.update(0.01, &[contact(4000.0, 20.0, 0.0, 0.0, -10.0), contact(4000.0, 0.0, 0.0, 0.0, -10.0)], &mut out);
    }
    assert!(out[0] > -10.0 && out[0] < -9.9, "{out:?}");
    assert_eq!(out[1], -10.0);
    // sustained sliding: the contact rises above the ice, monotonically over time, never above 0
    let mut last = -10.0;
    for _ in 0..500 {
        est.update(0.01, &[contact(4000.0, 20.0, 1.0, 600.0, -10.0), contact(4000.0, 20.0, 0.0, 0.0, -10.0)], &mut out);
        assert!(out[0] >= last - 1e-12 && out[0] <= 0.0, "{out:?}");
        last = out[0];
    }
    assert!(out[0] > -10.0 + 0.1);
    // second tyre: rolling heat only (400 W), no sliding power and no flash: warmer than the ice,
    // less than half the sliding tyre's rise (measured 0.26 K against 1.28 K after 5 s)
    assert!(out[1] > -10.0 && out[1] + 10.0 < 0.5 * (out[0] + 10.0), "{out:?}");
    // garbage in: finite out
    est.update(
        f64::NAN,
        &[contact(f64::NAN, f64::INFINITY, -1.0, f64::NAN, -5.0), contact(-1.0, 0.0, 1e9, 1e9, -5.0)],
        &mut out,
    );
    assert!(out.iter().all(|v| v.is_finite() && *v <= 0.0), "{out:?}");
}

#[test]
fn contact_spec_rejects_bad_values_with_key_names() {
    let bad = [
        ("model = \"magic\"", "contact.model"),
        ("model = \"atiim\"\n[tyre]\ninflation_kpa = -3.0", "contact.tyre.inflation_kpa"),
        ("model = \"atiim\"\n[tyre]\ncompound = \"slick\"", "contact.tyre.compound"),
        ("model = \"atiim\"\nload_range_n = [5000.0, 1000.0]", "contact.load_range_n[1]"),
    ];
    for (text, key) in bad {
        let spec: ContactSpec = toml::from_str(text).unwrap();
        let err = spec.build(Path::new("m.toml"), 2, -5.0).err().expect("must fail").to_string();
        assert!(err.contains(key) && err.contains("m.toml"), "{err}");
    }
    assert!(toml::from_str::<ContactSpec>("model = \"atiim\"\nbogus = 1").is_err());
}

#[test]
fn full_contact_table_with_every_key_parses_and_builds() {
    #[derive(serde::Deserialize)]
    struct M {
        contact: ContactSpec,
    }
    let text = r#"
[contact]
model = "atiim"
rolling_radius_m = 0.328
skin_depth_m = 0.002
air_temp_c = -5.0
load_range_n = [2000.0, 12000.0]
slide_speed_range_mps = [0.01, 30.0]
slip_fraction_min = 1e-4
table_nodes = [3, 3, 3, 3]
table_grid = [8, 8]

[contact.tyre]
inflation_kpa = 241.3
tread_width_m = 0.18
rated_load_n = 7000.0
compound = "tire_d"
void_ratio = 0.3
ribs = 5
block_pitch_m = 0.03
tread_depth_m = 0.00797
mu_dry = 0.15
kappa = 1.0
asperity_d_m = 2e-4
critical_film_nm = 50.0
brush = true
lock_time_s = 1.0
film_substeps = 8
"#;
    let m: M = toml::from_str(text).unwrap();
    let mut est = m.contact.build(Path::new("m.toml"), 4, -3.0).unwrap();
    let mut out = [0.0; 4];
    est.update(0.01, &[contact(4000.0, 20.0, 1.0, 600.0, -3.0); 4], &mut out);
    assert!(out.iter().all(|t| *t > -3.0 && *t <= 0.0), "{out:?}");
    assert_eq!(ContactSpec::default().model, "isothermal");
}
