//! One property suite run over every tyre provider (and a few variants): zero force at zero slip
//! and zero load, odd symmetry, the friction bound, continuity on a dense grid, the slope at zero
//! slip against the declared stiffness, and finiteness over the whole input box.

use std::path::Path;
use std::sync::Arc;

use vehsim_spec::tyre::TyreFileSpec;

use vehsim_core::tyre::TyreModelKind;
use vehsim_core::tyre::{TyreInput, TyreModel};

const SRTT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/vehicles/tyres/srtt_p225_60r16.toml");
const FZN: f64 = 4000.0;

struct Case {
    label: String,
    model: Arc<dyn TyreModel>,
    /// Fx odd in kappa and Fy even in kappa (not true of theoretical-slip / Dugoff models).
    odd_in_kappa: bool,
}

fn cases() -> Vec<Case> {
    let path = Path::new(SRTT);
    let spec = TyreFileSpec::load(path).expect("SRTT tyre file parses");
    let mut out = Vec::new();
    for &kind in TyreModelKind::ALL {
        let tyre = spec.build(path, kind).unwrap_or_else(|e| panic!("building {}: {e}", kind.as_str()));
        let odd = matches!(kind, TyreModelKind::Linear | TyreModelKind::Pacejka | TyreModelKind::AtiimPacejka);
        out.push(Case { label: kind.as_str().to_string(), model: tyre.model, odd_in_kappa: odd });
    }
    // Variants: the saturating linear tyre, Pacejka with the ellipse combination, the general
    // polynomial form.
    let mut s = spec.clone();
    s.linear.as_mut().unwrap().saturate = true;
    out.push(Case {
        label: "linear(saturate)".into(),
        model: s.build(path, TyreModelKind::Linear).unwrap().model,
        odd_in_kappa: true,
    });
    let mut s = spec.clone();
    s.pacejka.as_mut().unwrap().combined = "ellipse".into();
    out.push(Case {
        label: "pacejka(ellipse)".into(),
        model: s.build(path, TyreModelKind::Pacejka).unwrap().model,
        odd_in_kappa: true,
    });
    let mut s = spec.clone();
    s.pacejka.as_mut().unwrap().aligning_moment = true;
    out.push(Case {
        label: "pacejka(mz)".into(),
        model: s.build(path, TyreModelKind::Pacejka).unwrap().model,
        odd_in_kappa: true,
    });
    let mut s = spec.clone();
    let p = s.polynomial.as_mut().unwrap();
    p.form = "general".into();
    p.a2 = Some(-0.5);
    p.a3 = Some(0.05);
    out.push(Case {
        label: "polynomial(general)".into(),
        model: s.build(path, TyreModelKind::Polynomial).unwrap().model,
        odd_in_kappa: false,
    });
    out
}

fn input(fz: f64, kappa: f64, alpha: f64, mu: f64, dt: f64) -> TyreInput {
    let mut i = TyreInput::new(fz, kappa, alpha, mu);
    i.surface_temp_c = -3.0;
    i.contact_temp_c = -3.0 + dt;
    i
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n).map(|k| a + (b - a) * k as f64 / (n - 1) as f64).collect()
}

const PI2: f64 = std::f64::consts::FRAC_PI_2;
const MUS: [f64; 2] = [0.15, 1.0];
const DTS: [f64; 3] = [0.0, 2.0, 5.0];

#[test]
fn zero_force_at_zero_slip_and_at_zero_load() {
    for c in cases() {
        for &mu in &MUS {
            for &dt in &DTS {
                for &fz in &[0.5 * FZN, FZN, 3.0 * FZN] {
                    let f = c.model.forces(&input(fz, 0.0, 0.0, mu, dt));
                    assert!(f.fx_n.abs() < 1e-9 && f.fy_n.abs() < 1e-9, "{}: F(0,0) = {f:?}", c.label);
                }
                for &kappa in &[-1.0, -0.3, 0.0, 0.05, 1.0, 10.0] {
                    for &alpha in &[-PI2, -0.1, 0.0, 0.2, PI2] {
                        let f = c.model.forces(&input(0.0, kappa, alpha, mu, dt));
                        assert!(
                            f.fx_n == 0.0 && f.fy_n == 0.0 && f.mz_nm == 0.0,
                            "{}: nonzero force at zero load: {f:?}",
                            c.label
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn odd_symmetry_in_slip_angle_and_where_symmetric_in_slip_ratio() {
    for c in cases() {
        for &mu in &MUS {
            for &dt in &[0.0, 3.0] {
                for &fz in &[0.5 * FZN, FZN, 2.5 * FZN] {
                    for &kappa in &linspace(-1.0, 2.0, 13) {
                        for &alpha in &linspace(0.0, PI2, 11) {
                            let a = c.model.forces(&input(fz, kappa, alpha, mu, dt));
                            let b = c.model.forces(&input(fz, kappa, -alpha, mu, dt));
                            let tol = 1e-9 * fz;
                            assert!(
                                (a.fy_n + b.fy_n).abs() <= tol,
                                "{}: Fy not odd in alpha at {kappa},{alpha}",
                                c.label
                            );
                            assert!(
                                (a.fx_n - b.fx_n).abs() <= tol,
                                "{}: Fx not even in alpha at {kappa},{alpha}",
                                c.label
                            );
                            if c.odd_in_kappa && kappa.abs() <= 1.0 {
                                let m = c.model.forces(&input(fz, -kappa, alpha, mu, dt));
                                assert!((a.fx_n + m.fx_n).abs() <= tol, "{}: Fx not odd in kappa at {kappa}", c.label);
                                assert!((a.fy_n - m.fy_n).abs() <= tol, "{}: Fy not even in kappa at {kappa}", c.label);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The whole input box: kappa in [-1, 10], alpha in [-pi/2, pi/2], load in [0, 3 Fz_nominal].
fn box_grid() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut kappas = linspace(-1.0, 1.0, 41);
    kappas.extend(linspace(1.25, 10.0, 36));
    kappas.extend([-0.999_999, -1e-9, 1e-9]);
    let mut alphas = linspace(-PI2, PI2, 37);
    alphas.extend([-1e-9, 1e-9, PI2 - 1e-9]);
    let loads = linspace(0.0, 3.0 * FZN, 7);
    (kappas, alphas, loads)
}

#[test]
fn finite_everywhere_and_bounded_by_peak_friction() {
    let (kappas, alphas, loads) = box_grid();
    for c in cases() {
        for &mu in &MUS {
            for &dt in &DTS {
                for &fz in &loads {
                    for &kappa in &kappas {
                        for &alpha in &alphas {
                            let i = input(fz, kappa, alpha, mu, dt);
                            let f = c.model.forces(&i);
                            assert!(
                                f.fx_n.is_finite() && f.fy_n.is_finite() && f.mz_nm.is_finite(),
                                "{}: non-finite {f:?} at {i:?}",
                                c.label
                            );
                            let p = c.model.peak_friction(&i);
                            assert!(!p.is_nan() && p >= 0.0, "{}: peak_friction {p}", c.label);
                            if p.is_finite() {
                                let mag = f.fx_n.hypot(f.fy_n);
                                assert!(
                                    mag <= p * fz * (1.0 + 1e-9),
                                    "{}: |F| = {mag} > peak {p} * Fz at {i:?}",
                                    c.label
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A provider's cheap force floor ([`TyreModel::peak_force_floor_prepared`], what the plausibility
/// check skips its exact bound against) never exceeds the exact bound (N), for every provider
/// that has one, over the input box at the prepared load; the Magic Formula providers (ATIIM's
/// with its temperature law applied) have one.
#[test]
fn force_floor_is_below_the_peak_friction_bound() {
    let (kappas, alphas, loads) = box_grid();
    let mut with_floor = Vec::new();
    for c in cases() {
        for &mu in &MUS {
            for &dt in &DTS {
                for &fz in loads.iter().filter(|&&fz| fz > 0.0) {
                    let prepared = c.model.prepare(&input(fz, 0.0, 0.0, mu, dt));
                    for &kappa in &kappas {
                        for &alpha in &alphas {
                            let i = input(fz, kappa, alpha, mu, dt);
                            let Some(floor) = c.model.peak_force_floor_prepared(&prepared, &i) else { continue };
                            if !with_floor.contains(&c.label) {
                                with_floor.push(c.label.clone());
                            }
                            let bound = c.model.peak_friction_prepared(&prepared, &i) * fz;
                            assert!(
                                floor > 0.0 && floor <= bound,
                                "{}: floor {floor} > bound {bound} at {i:?}",
                                c.label
                            );
                        }
                    }
                }
            }
        }
    }
    for label in ["pacejka", "pacejka(ellipse)", "pacejka(mz)", "atiim_pacejka"] {
        assert!(with_floor.iter().any(|l| l == label), "{label} has no floor (those with one: {with_floor:?})");
    }
}

/// Continuity on dense lines through the box: between neighbouring samples (step h in kappa or
/// alpha) the force changes by at most 3 C_max h + 1e-6 Fz, where C_max is the larger of the
/// declared stiffnesses at this load (the steepest slope of every provider is at or near zero slip,
/// and no smooth curve here is steeper than three times it). A jump (a discontinuity) of the force
/// would break this bound however fine the grid.
#[test]
fn no_jumps_on_a_dense_grid() {
    let n_k = 4001;
    let n_a = 2001;
    for c in cases() {
        for &mu in &MUS {
            for &dt in &[0.0, 4.0] {
                for &fz in &[0.3 * FZN, FZN, 3.0 * FZN] {
                    let i0 = input(fz, 0.0, 0.0, mu, dt);
                    let cmax = c.model.longitudinal_stiffness(&i0).max(c.model.cornering_stiffness(&i0));
                    let kappas = linspace(-1.0, 10.0, n_k);
                    let hk = kappas[1] - kappas[0];
                    for &alpha in &[0.0, 0.03, 0.3, 1.2] {
                        let mut prev = None;
                        for &kappa in &kappas {
                            let f = c.model.forces(&input(fz, kappa, alpha, mu, dt));
                            if let Some((px, py)) = prev {
                                let d: f64 = f64::hypot(f.fx_n - px, f.fy_n - py);
                                assert!(
                                    d <= 3.0 * cmax * hk + 1e-6 * fz,
                                    "{}: jump {d} N at kappa {kappa}, alpha {alpha}, Fz {fz}, dT {dt}, mu {mu}",
                                    c.label
                                );
                            }
                            prev = Some((f.fx_n, f.fy_n));
                        }
                    }
                    let alphas = linspace(-PI2, PI2, n_a);
                    let ha = alphas[1] - alphas[0];
                    for &kappa in &[-1.0, -0.05, 0.0, 0.04, 0.5, 10.0] {
                        let mut prev = None;
                        for &alpha in &alphas {
                            let f = c.model.forces(&input(fz, kappa, alpha, mu, dt));
                            if let Some((px, py)) = prev {
                                let d: f64 = f64::hypot(f.fx_n - px, f.fy_n - py);
                                assert!(
                                    d <= 3.0 * cmax * ha + 1e-6 * fz,
                                    "{}: jump {d} N at alpha {alpha}, kappa {kappa}, Fz {fz}, dT {dt}, mu {mu}",
                                    c.label
                                );
                            }
                            prev = Some((f.fx_n, f.fy_n));
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn slope_at_zero_slip_equals_declared_stiffness() {
    let h = 1e-6;
    for c in cases() {
        for &mu in &MUS {
            for &dt in &[0.0, 3.0] {
                for &fz in &[0.5 * FZN, FZN, 2.0 * FZN] {
                    let i0 = input(fz, 0.0, 0.0, mu, dt);
                    let kx = c.model.longitudinal_stiffness(&i0);
                    let ky = c.model.cornering_stiffness(&i0);
                    let sx = (c.model.forces(&input(fz, h, 0.0, mu, dt)).fx_n
                        - c.model.forces(&input(fz, -h, 0.0, mu, dt)).fx_n)
                        / (2.0 * h);
                    let sy = (c.model.forces(&input(fz, 0.0, h, mu, dt)).fy_n
                        - c.model.forces(&input(fz, 0.0, -h, mu, dt)).fy_n)
                        / (2.0 * h);
                    assert!(kx > 0.0 && ky > 0.0, "{}: stiffness {kx}, {ky}", c.label);
                    assert!(
                        (sx - kx).abs() <= 0.005 * kx,
                        "{}: dFx/dkappa {sx} vs declared {kx} (Fz {fz}, mu {mu}, dT {dt})",
                        c.label
                    );
                    assert!(
                        (sy - ky).abs() <= 0.005 * ky,
                        "{}: dFy/dalpha {sy} vs declared {ky} (Fz {fz}, mu {mu}, dT {dt})",
                        c.label
                    );
                }
            }
        }
    }
}

#[test]
fn every_provider_is_in_the_suite() {
    let labels: Vec<String> = cases().into_iter().map(|c| c.label).collect();
    for name in TyreModelKind::ALL.iter().map(|k| k.as_str()) {
        assert!(labels.iter().any(|l| l == name), "{name} missing from the property suite");
    }
}
