//! The ATIIM-modified Magic Formula as a modifier of the base curve: identity with `pacejka` when
//! there is no heating, the bounded melt-proximity law (monotone in ice temperature and in the rise,
//! floor, saturation, continuity at 0 degC), the dissertation's effect at melting (Fig. 5.2/6.1) on
//! any ice temperature, and bad input.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use vehsim_core::tyre::atiim::{AxisLaw, KShift, MeltLaw};
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::tyre::{TyreInput, TyreModel};
use vehsim_spec::tyre::TyreFileSpec;

const SRTT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/vehicles/tyres/srtt_p225_60r16.toml");

fn build(spec: &TyreFileSpec, kind: TyreModelKind) -> Arc<dyn TyreModel> {
    spec.build(Path::new(SRTT), kind).unwrap().model
}

fn srtt() -> TyreFileSpec {
    TyreFileSpec::load(Path::new(SRTT)).unwrap()
}

fn input(fz: f64, kappa: f64, alpha: f64, camber: f64, mu: f64, ice_c: f64, contact_c: f64) -> TyreInput {
    TyreInput {
        fz_n: fz,
        kappa,
        alpha_rad: alpha,
        camber_rad: camber,
        vx_mps: 20.0,
        mu_surface: mu,
        surface_temp_c: ice_c,
        contact_temp_c: contact_c,
    }
}

/// A small deterministic generator (64-bit LCG, top 53 bits) for the property grids.
struct Lcg(u64);
impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

/// Identity property: with the contact at the ice temperature (no heating) the ATIIM tyre equals
/// `pacejka` to 1e-12 relative in Fx, Fy, Mz, the stiffnesses and the friction bound, at every load,
/// slip ratio, slip angle, camber, surface friction and ice temperature; for the shipped `.tir` with
/// and without the aligning moment, the ellipse combination, and an inline coefficient set.
#[test]
fn no_heating_equals_the_base_magic_formula() {
    let mut variants = vec![srtt()];
    let mut s = srtt();
    s.pacejka.as_mut().unwrap().aligning_moment = true;
    variants.push(s);
    let mut s = srtt();
    s.pacejka.as_mut().unwrap().combined = "ellipse".into();
    variants.push(s);
    let mut s = srtt();
    let p = s.pacejka.as_mut().unwrap();
    p.tir_file = None;
    p.coefficients = Some(
        [("PCX1", 1.6), ("PDX1", 1.1), ("PKX1", 18.0), ("PCY1", 1.3), ("PDY1", 0.95), ("PKY1", 16.0), ("PKY2", 1.8)]
            .iter()
            .map(|(k, v)| (k.to_string(), *v))
            .collect(),
    );
    p.combined = "ellipse".into();
    variants.push(s);
    let mut g = Lcg(12);
    for spec in &variants {
        let base = build(spec, TyreModelKind::Pacejka);
        let atiim = build(spec, TyreModelKind::AtiimPacejka);
        for _ in 0..4000 {
            let ice = g.range(-30.0, 2.0);
            let i = input(
                g.range(0.0, 12000.0),
                g.range(-1.0, 3.0),
                g.range(-0.8, 0.8),
                g.range(-0.1, 0.1),
                g.range(0.05, 1.2),
                ice,
                ice,
            );
            let (a, b) = (atiim.forces(&i), base.forces(&i));
            for (x, y) in [(a.fx_n, b.fx_n), (a.fy_n, b.fy_n), (a.mz_nm, b.mz_nm)] {
                assert!(rel(x, y) <= 1e-12, "{i:?}: {a:?} vs {b:?}");
            }
            assert!(rel(atiim.peak_friction(&i), base.peak_friction(&i)) <= 1e-12, "{i:?}");
            assert!(rel(atiim.longitudinal_stiffness(&i), base.longitudinal_stiffness(&i)) <= 1e-12, "{i:?}");
            assert!(rel(atiim.cornering_stiffness(&i), base.cornering_stiffness(&i)) <= 1e-12, "{i:?}");
        }
    }
}

/// |F| of a tyre at one input.
fn mag(m: &dyn TyreModel, i: &TyreInput) -> f64 {
    let f = m.forces(i);
    f.fx_n.hypot(f.fy_n)
}

/// Monotonicity property of the shipped law: at the same slip, load and rise, colder ice never
/// gives less force (ice -25 ... -0.5 degC, contact capped at melting as the estimator caps it); and
/// on the same ice a larger rise never gives more force. Pure longitudinal, pure lateral and
/// combined slip, on the slip range a vehicle uses.
#[test]
fn colder_ice_is_never_more_slippery() {
    let m = build(&srtt(), TyreModelKind::AtiimPacejka);
    let ices: Vec<f64> = (0..=49).map(|k| -25.0 + 0.5 * k as f64).collect(); // -25 .. -0.5
    let mut g = Lcg(7);
    for _ in 0..600 {
        let fz = g.range(500.0, 9000.0);
        let (kappa, alpha) = match g.unit() {
            u if u < 0.33 => (g.range(-1.0, 1.0), 0.0),
            u if u < 0.66 => (0.0, g.range(-0.5, 0.5)),
            _ => (g.range(-0.5, 0.5), g.range(-0.3, 0.3)),
        };
        let mu = g.range(0.05, 0.3);
        for rise in [0.2, 0.7, 1.5, 3.0, 6.0, 12.0, 30.0] {
            let mut warmer = f64::INFINITY;
            let mut prev: Option<f64> = None;
            for &ice in &ices {
                let f = mag(&*m, &input(fz, kappa, alpha, 0.0, mu, ice, (ice + rise).min(0.0)));
                if let Some(p) = prev {
                    // ices run from cold to warm: the force must not rise
                    assert!(
                        f <= p * (1.0 + 1e-12) + 1e-9,
                        "fz {fz} kappa {kappa} alpha {alpha} rise {rise}: {f} at {ice} degC > {p} on colder ice"
                    );
                }
                prev = Some(f);
                warmer = warmer.min(f);
            }
            let _ = warmer;
        }
        for &ice in &[-20.0, -10.0, -3.0, -0.5] {
            let mut prev = f64::INFINITY;
            for k in 0..=40 {
                let contact = (ice + 0.05 * k as f64 * (-ice)).min(0.0);
                let f = mag(&*m, &input(fz, kappa, alpha, 0.0, mu, ice, contact));
                assert!(f <= prev * (1.0 + 1e-12) + 1e-9, "ice {ice} contact {contact}: {f} > {prev}");
                prev = f;
            }
        }
    }
}

/// (argmax, max) of f on [0, hi] sampled at 1e-4 steps.
fn peak_of(f: impl Fn(f64) -> f64, hi: f64) -> (f64, f64) {
    let n = (hi / 1e-4) as usize;
    (0..=n).map(|i| i as f64 * 1e-4).map(|k| (k, f(k))).fold((0.0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a })
}

/// Fig. 5.2 and 6.1 with the shipped calibration: when the contact reaches melting, the
/// longitudinal peak falls to peak_factor_at_melt = 0.5 of the base and sits at about half the
/// slip (0.45–0.55 of the base's; with the stiffness unchanged the peak slip scales with D/K), on
/// -3, -10 and -25 degC ice alike (the effect is reachable before melting caps the rise); the
/// lateral peak falls to 0.9 (Fig. 5.3: hardly changed). Halfway to melting the effect is partial.
#[test]
fn the_stated_effect_happens_at_melting_on_any_ice() {
    let m = build(&srtt(), TyreModelKind::AtiimPacejka);
    let fz = 4000.0;
    for ice in [-3.0, -10.0, -25.0] {
        let m = &*m;
        let fx = |contact: f64| move |k: f64| m.forces(&input(fz, k, 0.0, 0.0, 0.15, ice, contact)).fx_n;
        let fy = |contact: f64| move |a: f64| m.forces(&input(fz, 0.0, a, 0.0, 0.15, ice, contact)).fy_n;
        let (k0, p0) = peak_of(fx(ice), 0.4);
        let (k1, p1) = peak_of(fx(0.0), 0.4);
        assert!((p1 / p0 - 0.5).abs() < 1e-3, "{ice}: peak ratio {}", p1 / p0);
        assert!((0.45..=0.55).contains(&(k1 / k0)), "{ice}: peak-slip ratio {}", k1 / k0);
        let (_, q0) = peak_of(fy(ice), 0.4);
        let (_, q1) = peak_of(fy(0.0), 0.4);
        assert!((q1 / q0 - 0.9).abs() < 1e-3, "{ice}: lateral peak ratio {}", q1 / q0);
        let (_, ph) = peak_of(fx(ice / 2.0), 0.4);
        assert!(ph < p0 && ph > p1, "{ice}: halfway {ph} not between {p1} and {p0}");
    }
}

fn law(k_shift: KShift) -> MeltLaw {
    MeltLaw {
        k_shift,
        x: AxisLaw { peak_at_melt: 0.3, stiffness_at_melt: 0.6 },
        y: AxisLaw { peak_at_melt: 0.9, stiffness_at_melt: 1.0 },
        floor: 0.3,
    }
}

/// The law's closed form for the SRTT family: p = w(dT)/w(M), w = (25/3 dT^2 + 5/3) dT; bounded
/// in [0, 1]; saturates (p = 1 at and above melting); 0 for no heating, a negative or NaN rise;
/// continuous across 0 degC ice (the margin never falls below 0.1 K); factors never below the floor.
#[test]
fn melt_proximity_closed_form_and_bounds() {
    let l = law(KShift::Srtt);
    let w = |d: f64| (25.0 / 3.0 * d * d + 5.0 / 3.0) * d;
    for (ice, dt) in [(-10.0, 2.0), (-10.0, 7.5), (-3.0, 1.0), (-25.0, 10.0)] {
        let p = l.proximity(ice, ice + dt);
        assert!(rel(p, w(dt) / w(-ice)) < 1e-14, "{ice} {dt}: {p}");
    }
    assert_eq!(l.proximity(-10.0, 0.0), 1.0);
    assert_eq!(l.proximity(-10.0, 5.0), 1.0); // above melting: saturated, not extrapolated
    assert_eq!(l.proximity(-10.0, -10.0), 0.0);
    assert_eq!(l.proximity(-10.0, -12.0), 0.0);
    assert_eq!(l.proximity(-10.0, f64::NAN), 0.0);
    assert_eq!(l.proximity(f64::NAN, -1.0), 0.0);
    // continuity at 0 degC ice: -1e-9 and +1e-9 give the same p for the same rise
    let (a, b) = (l.proximity(-1e-9, 0.05 - 1e-9), l.proximity(1e-9, 0.05 + 1e-9));
    assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    assert!((l.proximity(0.0, 0.1) - 1.0).abs() < 1e-12);
    let lin = law(KShift::None);
    assert!((lin.proximity(-8.0, -6.0) - 0.25).abs() < 1e-15);
    for p in [0.0, 0.3, 1.0] {
        let s = l.scale(p);
        for f in [s.mu_x, s.k_x, s.mu_y, s.k_y] {
            assert!((0.3..=1.0).contains(&f), "{p}: {s:?}");
        }
    }
    let s = l.scale(1.0);
    assert_eq!((s.mu_x, s.k_x, s.mu_y, s.k_y), (0.3, 0.6, 0.9, 1.0));
    let s = l.scale(0.5);
    assert!((s.mu_x - 0.65).abs() < 1e-15 && (s.k_x - 0.8).abs() < 1e-15);
}

// --------------------------------------------------------------------------------------- bad input

fn tmp(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vehsim-tyre-atiim-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn build_error(tag: &str, text: &str) -> String {
    let dir = tmp(tag);
    std::fs::copy(Path::new(SRTT).with_extension("tir"), dir.join("srtt_p225_60r16.tir")).unwrap();
    let p = dir.join("t.toml");
    std::fs::write(&p, text).unwrap();
    let e = TyreFileSpec::load(&p).and_then(|s| s.build(&p, TyreModelKind::AtiimPacejka)).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(matches!(e, vehsim_core::Error::Input { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("t.toml"), "names the file: {msg}");
    msg
}

/// A factor outside [floor, 1], a floor outside (0, 1], a negative shift coefficient, and an ATIIM
/// section without its base curve: input errors naming the file, the key and what is allowed.
#[test]
fn bad_atiim_sections_are_input_errors() {
    let text = std::fs::read_to_string(SRTT).unwrap();
    let e = build_error("pk", &text.replace("peak_factor_at_melt = 0.5", "peak_factor_at_melt = 1.2"));
    assert!(e.contains("atiim_pacejka.longitudinal.peak_factor_at_melt") && e.contains("<= 1"), "{e}");
    let e = build_error("pk0", &text.replace("peak_factor_at_melt = 0.9", "peak_factor_at_melt = 0.05"));
    assert!(e.contains("atiim_pacejka.lateral.peak_factor_at_melt") && e.contains("min_factor"), "{e}");
    let e = build_error("st", &text.replacen("stiffness_factor_at_melt = 1.0", "stiffness_factor_at_melt = 1.5", 1));
    assert!(e.contains("atiim_pacejka.longitudinal.stiffness_factor_at_melt"), "{e}");
    for bad in ["0.0", "1.5", "-0.2"] {
        let e = build_error("fl", &text.replace("min_factor = 0.1", &format!("min_factor = {bad}")));
        assert!(e.contains("atiim_pacejka.min_factor") && e.contains("0 < min_factor <= 1"), "{e}");
    }
    let e = build_error(
        "qa",
        &text.replace("k_shift = \"srtt\"", "k_shift = \"quadratic\"\nk_shift_a = -1.0\nk_shift_b = 1.0"),
    );
    assert!(e.contains("atiim_pacejka.k_shift_a"), "{e}");
    let e = build_error(
        "qz",
        &text.replace("k_shift = \"srtt\"", "k_shift = \"quadratic\"\nk_shift_a = 0.0\nk_shift_b = 0.0"),
    );
    assert!(e.contains("atiim_pacejka.k_shift_b") && e.contains("> 0"), "{e}");
    let a = text.find("[pacejka]").unwrap();
    let b = text.find("[dugoff]").unwrap();
    let e = build_error("nobase", &format!("{}{}", &text[..a], &text[b..]));
    assert!(e.contains("atiim_pacejka") && e.contains("base curve") && e.contains("[pacejka]"), "{e}");
    // the old self-contained coefficients are no longer keys of the section
    let e = build_error("old", &text.replace("min_factor = 0.1", "min_factor = 0.1\nmu_reference = 0.15"));
    assert!(e.contains("mu_reference"), "{e}");
}

// ------------------------------------------------------------------------------------ identity run

fn simulate(spec: &str, tyre_model: &str, vehicle_model: &str, contact: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(spec);
    let mut file = vehsim_spec::ManeuverFile::load(&path).unwrap();
    file.tyre_model = tyre_model.to_string();
    file.vehicle_model = Some(vehicle_model.to_string());
    file.contact.model = contact.to_string();
    let cfg = file.build(&path).unwrap();
    vehsim::run::timeseries_csv(&vehsim_spec::run::execute(&cfg).rows)
}

/// A whole run with `atiim_pacejka` and isothermal contact gives the same time series as
/// `pacejka` (byte-identical CSV), on the bicycle and the 4-DOF model; with the ATIIM estimator
/// (heating) it differs.
#[test]
fn isothermal_atiim_run_equals_the_pacejka_run() {
    for vm in ["bicycle", "roll4dof"] {
        let a = simulate("maneuvers/dlc.toml", "pacejka", vm, "isothermal");
        let b = simulate("maneuvers/dlc.toml", "atiim_pacejka", vm, "isothermal");
        assert!(a.lines().count() > 100, "{vm}: a real run");
        assert!(a == b, "{vm}: isothermal atiim_pacejka run differs from pacejka");
    }
    let a = simulate("maneuvers/dlc.toml", "pacejka", "bicycle", "atiim");
    let b = simulate("maneuvers/dlc.toml", "atiim_pacejka", "bicycle", "atiim");
    assert!(a != b, "heating must change the ATIIM run");
}

fn peak_ay(spec: &str, tyre_model: &str, ice_c: f64) -> f64 {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(spec);
    let mut file = vehsim_spec::ManeuverFile::load(&path).unwrap();
    file.tyre_model = tyre_model.to_string();
    file.surface.temperature_c = ice_c;
    let mut cfg = file.build(&path).unwrap();
    cfg.output.timeseries = false;
    vehsim_spec::run::execute(&cfg).summary.peak_ay_mps2
}

/// No collapse on cold ice (the criterion): in the shipped ice-temperature lane change
/// (60 km/h, mu 0.15, ATIIM contact) the ATIIM tyre's peak a_y stays within 10 % of its base
/// tyre's at -10 and -20 degC, and the colder ice is not the more slippery one.
#[test]
fn lane_change_on_cold_ice_does_not_collapse() {
    let spec = "maneuvers/dissertation/dlc_60kmh_ice_temperature.toml";
    let base = peak_ay(spec, "pacejka", -10.0);
    let at10 = peak_ay(spec, "atiim_pacejka", -10.0);
    let at20 = peak_ay(spec, "atiim_pacejka", -20.0);
    for (t, a) in [(-10, at10), (-20, at20)] {
        assert!((a / base - 1.0).abs() < 0.10, "{t} degC: ATIIM peak a_y {a} vs Pacejka {base}");
    }
    assert!(at20 >= at10, "colder ice more slippery: {at20} at -20 degC < {at10} at -10 degC");
}

/// Through the command line: a temperature-law factor out of range is exit code 2 with a message
/// naming the tyre file and the key.
#[test]
fn bad_atiim_factor_exits_2_naming_file_and_key() {
    let dir = tmp("cli");
    std::fs::copy(Path::new(SRTT).with_extension("tir"), dir.join("srtt_p225_60r16.tir")).unwrap();
    let text = std::fs::read_to_string(SRTT).unwrap().replace("peak_factor_at_melt = 0.9", "peak_factor_at_melt = 1.4");
    std::fs::write(dir.join("bad_tyre.toml"), text).unwrap();
    let spec = dir.join("curves.toml");
    std::fs::write(
        &spec,
        "name = \"c\"\ntyre_file = \"bad_tyre.toml\"\nproviders = [\"atiim_pacejka\"]\nloads_n = [4000.0]\n\
         mu_surface = 0.15\nslip_ratio = { min = 0.0, max = 0.4, points = 11 }\n\
         slip_angle_deg = { min = 0.0, max = 10.0, points = 11 }\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_vehsim"))
        .args(["tyre", spec.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bad_tyre.toml") && err.contains("atiim_pacejka.lateral.peak_factor_at_melt"), "{err}");
    assert!(err.contains("<= 1"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
