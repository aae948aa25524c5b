//! ATIIM physics checks against closed forms, conservation and limits (no expected values taken
//! from the code under test).

use std::f64::consts::PI;
use std::path::Path;

use vehsim_core::contact::film::{advance, implicit_step, FilmCoeffs, FilmParams};
use vehsim_core::contact::model::{solve_patch, Operating, PatchParams};
use vehsim_core::contact::patch::{synthesize, PressureGrid, SynthInputs, TreadPattern};
use vehsim_core::contact::thermal::{ICE, LATENT_HEAT_J_KG, WATER_VISCOSITY_PA_S};

/// Constant friction 0.15, no rolling heat, the whole patch sliding: the closed-form setting.
fn params() -> PatchParams {
    let mut p = PatchParams::srtt(-3.0).with_constant_friction(0.15);
    p.brush = false;
    p
}

fn e_sum(p: &PatchParams) -> f64 {
    p.compound.solid.effusivity() + ICE.effusivity()
}

fn uniform_grid(rows: usize, cols: usize, len: f64, p: f64) -> PressureGrid {
    PressureGrid { rows, cols, dx_m: len / rows as f64, dy_m: 0.004, p_pa: vec![p; rows * cols] }
}

#[test]
fn uniform_patch_rise_matches_closed_form_within_one_percent() {
    let pp = params();
    let (rows, len, p0, v, vs) = (40, 0.16, 250e3, 20.0, 0.2);
    let g = uniform_grid(rows, 3, len, p0);
    let op = Operating { roll_speed_mps: v, slide_speed_mps: vs, ice_temp_c: -40.0 };
    let r = solve_patch(&g, &op, &pp);
    let q = pp.mu_dry * p0 * vs;
    // `Operating` is read as braking: the ice passes at the travel speed roll + slide
    let dt = g.dx_m / (v + vs);
    for i in 0..rows {
        let t = (i as f64 + 0.5) * dt;
        let exact = 2.0 * q * (t / PI).sqrt() / e_sum(&pp);
        for c in 0..3 {
            let got = r.rise_k[i * 3 + c];
            assert!((got - exact).abs() <= 0.01 * exact, "row {i}: {got} vs closed form {exact}");
        }
        assert!(!r.wet[i * 3]);
    }
}

/// Linearly growing pressure along travel gives q = a t; the closed form is
/// dT = (4/3) a t^(3/2) / (e sqrt(pi)). The discrete error must fall as the grid is refined.
#[test]
fn linear_flux_rise_converges_under_grid_refinement() {
    let pp = params();
    let (len, pmax, v, vs) = (0.16, 400e3, 20.0, 0.2);
    let mut errs = Vec::new();
    for rows in [8usize, 16, 32, 64, 128] {
        let dx = len / rows as f64;
        let p: Vec<f64> = (0..rows).map(|i| pmax * (i as f64 + 0.5) * dx / len).collect();
        let g = PressureGrid { rows, cols: 1, dx_m: dx, dy_m: 0.004, p_pa: p };
        let op = Operating { roll_speed_mps: v, slide_speed_mps: vs, ice_temp_c: -40.0 };
        let r = solve_patch(&g, &op, &pp);
        let vg = v + vs; // travel speed (braking reading of `Operating`)
        let a = pp.mu_dry * pmax * vs / (len / vg); // q = a t
        let i = rows - 1;
        let t = (i as f64 + 0.5) * dx / vg;
        let exact = 4.0 / 3.0 * a * t.powf(1.5) / (e_sum(&pp) * PI.sqrt());
        errs.push(((r.rise_k[i] - exact) / exact).abs());
    }
    for w in errs.windows(2) {
        assert!(w[1] < w[0], "error did not fall under refinement: {errs:?}");
    }
    assert!(errs[errs.len() - 1] < 0.01, "finest grid error {errs:?}");
}

fn srtt_grid(load: f64, rows: usize, cols: usize, void: f64, ribs: usize, pitch: f64) -> PressureGrid {
    synthesize(
        Path::new("test"),
        &SynthInputs {
            load_n: load,
            inflation_pa: 241.3e3,
            tread_width_m: 0.18,
            rated_load_n: 7000.0,
            camber_deg: 0.0,
            pattern: TreadPattern { ribs, void_ratio: void, block_pitch_m: pitch },
            rows,
            cols,
        },
    )
    .unwrap()
}

#[test]
fn energy_balance_generated_equals_tread_plus_ice_plus_melting() {
    for &(d, sub) in &[(1.0, 16usize), (2e-4, 16)] {
        let mut pp = params();
        pp.film.asperity_d_m = d;
        pp.film.substeps = sub;
        let g = srtt_grid(7000.0, 64, 48, 0.3, 5, 0.03);
        let op = Operating { roll_speed_mps: 27.5, slide_speed_mps: 2.5, ice_temp_c: -3.0 };
        let r = solve_patch(&g, &op, &pp);
        let s = r.summary;
        assert!(s.wet_fraction > 0.1, "test case must melt");
        let out = s.power_tread_w + s.power_ice_w + s.power_melt_w;
        assert!(
            (out - s.power_generated_w).abs() < 0.01 * s.power_generated_w,
            "D {d}: gen {} vs out {out}",
            s.power_generated_w
        );
    }
}

/// Without squeeze-out, all melt water leaves at the trailing edge: the melting power must equal
/// rho L (film height leaving each track) x (transit speed) x (track width), independent of the
/// per-pixel melt bookkeeping; and generated = conducted + that.
#[test]
fn energy_balance_with_melt_from_exit_film_mass_flux() {
    let mut pp = params();
    pp.film.asperity_d_m = 1.0; // squeeze-out off
    pp.film.substeps = 16;
    let g = srtt_grid(7000.0, 64, 48, 0.0, 1, 0.0); // slick: no grooves, no refreezing gaps
    let (vr, vs) = (27.5, 2.5);
    let op = Operating { roll_speed_mps: vr, slide_speed_mps: vs, ice_temp_c: -3.0 };
    let r = solve_patch(&g, &op, &pp);
    let vg = vr + vs; // travel speed (braking reading of `Operating`)
    let last = g.rows - 1;
    let exit: f64 = (0..g.cols).map(|c| r.film_m[last * g.cols + c]).sum();
    let p_melt = ICE.density_kg_m3 * LATENT_HEAT_J_KG * exit * vg * g.dy_m;
    let s = r.summary;
    assert!(p_melt > 0.0);
    let out = s.power_tread_w + s.power_ice_w + p_melt;
    assert!((out - s.power_generated_w).abs() < 0.01 * s.power_generated_w, "gen {} vs {out}", s.power_generated_w);
}

#[test]
fn film_reaches_known_steady_states() {
    let rl = ICE.density_kg_m3 * LATENT_HEAT_J_KG;
    let (kappa, v, p) = (0.8, 2.0, 300e3);
    let a = 2.0 * kappa * WATER_VISCOSITY_PA_S * v * v / rl;
    // (1) viscous heating vs squeeze-out only: A = C h^4  ->  h* = (A / C)^(1/4)
    let d = 1e-4;
    let fp = FilmParams { kappa, asperity_d_m: d, substeps: 1 };
    let k = FilmCoeffs::new(&fp, v, 0.0, p);
    let c = 16.0 * p / (3.0 * WATER_VISCOSITY_PA_S * d * d);
    let h_star = (a / c).powf(0.25);
    let st = advance(0.0, 1.0, 20000, &k);
    assert!((st.h_end_m - h_star).abs() < 1e-3 * h_star, "{} vs {h_star}", st.h_end_m);
    // (2) viscous heating vs constant conduction only: kappa eta v^2 / h = q_c  ->  h* = kappa eta v^2 / q_c
    let qc = 40e3;
    let fp = FilmParams { kappa, asperity_d_m: 1e3, substeps: 1 };
    let k = FilmCoeffs::new(&fp, v, qc, p);
    let h_star = kappa * WATER_VISCOSITY_PA_S * v * v / qc;
    let st = advance(0.0, 1.0, 20000, &k);
    assert!((st.h_end_m - h_star).abs() < 1e-3 * h_star, "{} vs {h_star}", st.h_end_m);
    // (3) from above, it relaxes down to the same value
    let st = advance(5.0 * h_star, 1.0, 20000, &k);
    assert!((st.h_end_m - h_star).abs() < 1e-3 * h_star);
}

#[test]
fn film_growth_from_zero_matches_sqrt_law_and_never_nans() {
    // pure melting from h = 0: rho L dh/dt = kappa eta v^2 / h  ->  h = sqrt(2 kappa eta v^2 t / (rho L))
    let rl = ICE.density_kg_m3 * LATENT_HEAT_J_KG;
    let fp = FilmParams { kappa: 1.0, asperity_d_m: 1e3, substeps: 1 };
    let k = FilmCoeffs::new(&fp, 3.0, 0.0, 0.0);
    for &t in &[1e-6, 1e-3, 0.1] {
        let st = advance(0.0, t, 7, &k);
        let exact = (2.0 * WATER_VISCOSITY_PA_S * 9.0 * t / rl).sqrt();
        assert!((st.h_end_m - exact).abs() < 1e-9 * exact);
        // integral of 1/h from 0 to t = 2 t / h(t) exactly
        assert!((st.inv_h_integral - 2.0 * t / exact).abs() < 1e-6 * 2.0 * t / exact);
    }
    // refreezing (no heating, strong conduction) drives h to 0 without NaN or negative values
    let k = FilmCoeffs::new(&fp, 0.0, 1e6, 1e6);
    let mut s = 1e-7;
    for _ in 0..1000 {
        s = implicit_step(s, 1e-4, &k);
        assert!(s.is_finite() && s >= 0.0);
    }
    assert!(s < 1e-12);
    let st = advance(f64::NAN, 1e-3, 8, &k);
    assert!(st.h_end_m.is_finite());
}

/// The film and rise trends of the film and heat models, under a constant friction of 0.15 with
/// the whole patch sliding (the friction law's and the brush's own trends are tested in
/// `atiim_rig.rs`; with the carcass in series, 1 % slip leaves most of the patch adhering).
fn run(load: f64, vs: f64, ice: f64) -> vehsim_core::contact::model::PatchSummary {
    let mut pp = PatchParams::srtt(ice).with_constant_friction(0.15);
    pp.brush = false;
    let g = srtt_grid(load, 48, 32, 0.3, 5, 0.03);
    solve_patch(&g, &Operating { roll_speed_mps: 25.0 + vs, slide_speed_mps: vs, ice_temp_c: ice }, &pp).summary
}

#[test]
fn film_and_rise_increase_with_load_and_sliding_speed() {
    let loads = [4000.0, 5500.0, 7000.0, 8500.0];
    let films: Vec<f64> = loads.iter().map(|&l| run(l, 2.5, -3.0).max_film_m).collect();
    for w in films.windows(2) {
        assert!(w[1] > w[0], "film vs load {films:?}");
    }
    let rises: Vec<f64> = loads.iter().map(|&l| run(l, 0.3, -20.0).mean_rise_k).collect();
    for w in rises.windows(2) {
        assert!(w[1] > w[0], "rise vs load {rises:?}");
    }
    let speeds = [2.0, 2.5, 3.0, 4.0];
    let films: Vec<f64> = speeds.iter().map(|&v| run(7000.0, v, -3.0).max_film_m).collect();
    for w in films.windows(2) {
        assert!(w[1] > w[0], "film vs sliding speed {films:?}");
    }
    let rises: Vec<f64> = [0.1, 0.2, 0.4, 0.8].iter().map(|&v| run(7000.0, v, -20.0).mean_rise_k).collect();
    for w in rises.windows(2) {
        assert!(w[1] > w[0], "rise vs sliding speed {rises:?}");
    }
}

#[test]
fn nothing_melts_when_the_rise_cannot_reach_zero() {
    // Upper bound: the largest pressure applied over the whole contact time. With ice at -20 degC
    // and this bound below 20 K, no pixel may be wet.
    let pp = PatchParams::srtt(-20.0).with_constant_friction(0.15);
    let g = srtt_grid(8500.0, 48, 32, 0.3, 5, 0.03);
    let (vr, vs) = (20.0, 1.0);
    let pmax = g.p_pa.iter().cloned().fold(0.0, f64::max);
    let tmax = g.rows as f64 * g.dx_m / vr;
    let bound = 2.0 * pp.mu_dry * pmax * vs * (tmax / PI).sqrt() / e_sum(&pp);
    assert!(bound < 20.0, "test case too hot: bound {bound}");
    let r = solve_patch(&g, &Operating { roll_speed_mps: vr, slide_speed_mps: vs, ice_temp_c: -20.0 }, &pp);
    assert!(r.wet.iter().all(|w| !w));
    assert!(r.film_m.iter().all(|h| *h == 0.0));
    assert!(r.summary.max_rise_k <= bound * 1.0001);
    // and with ice at -1 degC the same patch does melt
    let r = solve_patch(&g, &Operating { roll_speed_mps: vr, slide_speed_mps: vs, ice_temp_c: -1.0 }, &pp);
    assert!(r.wet.iter().any(|w| *w));
}

#[test]
fn synthesized_patch_carries_the_load_and_changes_shape_with_load_and_camber() {
    for &l in &[2000.0, 4000.0, 7000.0, 8500.0] {
        let g = srtt_grid(l, 64, 48, 0.3, 5, 0.03);
        assert!((g.load_n() - l).abs() < 1e-9 * l);
    }
    // edge-to-centre pressure ratio grows with load (oval -> rectangular with edge pressure)
    let ratio = |l: f64| {
        let g = srtt_grid(l, 64, 48, 0.0, 1, 0.0);
        let col_max = |c: usize| (0..g.rows).map(|r| g.p(r, c)).fold(0.0, f64::max);
        let edge = (0..g.cols).map(col_max).find(|v| *v > 0.0).unwrap();
        edge / col_max(g.cols / 2)
    };
    assert!(ratio(8500.0) > ratio(4000.0));
    // camber: positive camber shortens and unloads the +y half
    let g = synthesize(
        Path::new("t"),
        &SynthInputs {
            load_n: 7000.0,
            inflation_pa: 241.3e3,
            tread_width_m: 0.18,
            rated_load_n: 7000.0,
            camber_deg: 4.0,
            pattern: TreadPattern { ribs: 1, void_ratio: 0.0, block_pitch_m: 0.0 },
            rows: 64,
            cols: 48,
        },
    )
    .unwrap();
    let half = |lo: usize, hi: usize| {
        (0..g.rows).flat_map(|r| (lo..hi).map(move |c| (r, c))).map(|(r, c)| g.p(r, c)).sum::<f64>()
    };
    assert!(half(24, 48) < half(0, 24));
}

#[test]
fn degenerate_inputs_give_finite_cold_results() {
    let pp = params();
    let g = uniform_grid(10, 4, 0.1, 200e3);
    for op in [
        Operating { roll_speed_mps: 0.0, slide_speed_mps: 0.0, ice_temp_c: -5.0 },
        Operating { roll_speed_mps: f64::NAN, slide_speed_mps: f64::INFINITY, ice_temp_c: f64::NAN },
        Operating { roll_speed_mps: 10.0, slide_speed_mps: 1.0, ice_temp_c: 0.0 },
        Operating { roll_speed_mps: -3.0, slide_speed_mps: -1.0, ice_temp_c: -5.0 },
    ] {
        let r = solve_patch(&g, &op, &pp);
        for v in r.rise_k.iter().chain(&r.film_m).chain(&r.mu).chain(&r.q_gen) {
            assert!(v.is_finite(), "{op:?}");
        }
    }
    // zero speeds: no heat at all
    let r = solve_patch(&g, &Operating { roll_speed_mps: 0.0, slide_speed_mps: 0.0, ice_temp_c: -5.0 }, &pp);
    assert!(r.rise_k.iter().all(|v| *v == 0.0));
    // a hand-built grid whose data does not match its shape is treated as empty, not a panic
    let bad = PressureGrid { rows: 10, cols: 4, dx_m: 0.01, dy_m: 0.01, p_pa: vec![1e5; 7] };
    let r = solve_patch(&bad, &Operating { roll_speed_mps: 10.0, slide_speed_mps: 1.0, ice_temp_c: -5.0 }, &pp);
    assert!(r.rise_k.is_empty());
}
