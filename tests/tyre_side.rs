//! TYRESIDE: a `.tir` tyre mounted on the side it was measured for is evaluated as is; on the other
//! side it is its mirror image (y -> -y), so conicity and ply-steer act mirror-symmetrically.

use std::path::PathBuf;

use vehsim_core::tyre::pacejka::{PacejkaTyre, TyreSide};
use vehsim_core::tyre::{TyreInput, TyreModel};
use vehsim_spec::tyre::TyreFileSpec;

const TIR: &str = "[UNITS]\nLENGTH = 'meter'\nFORCE = 'newton'\n[MODEL]\nPROPERTY_FILE_FORMAT = 'PAC2002'\n\
SIDE_LINE\n[DIMENSION]\nUNLOADED_RADIUS = 0.338\n[VERTICAL]\nFNOMIN = 4000\n[LONGITUDINAL_COEFFICIENTS]\n\
PCX1 = 1.5\nPDX1 = 1.2\nPKX1 = 22\nPHX1 = 0.001\nRBX1 = 12\nRCX1 = 1\n[LATERAL_COEFFICIENTS]\nPCY1 = 1.3\n\
PDY1 = 1.0\nPKY1 = -20\nPKY2 = 2\nPHY1 = 0.003\nPVY1 = 0.02\nPVY3 = -0.1\nRBY1 = 9\nRCY1 = 1\n\
[ALIGNING_COEFFICIENTS]\nQBZ1 = 10\nQCZ1 = 1.2\nQDZ1 = 0.09\nQEZ1 = -1.5\nQHZ1 = 0.002\nQDZ6 = 0.003\n";

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vehsim-tyreside-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A folder holding `t.tir` (text `tir`) and the tyre file `t.toml` whose `[pacejka]` reads it
/// (with the aligning moment); returns (folder, t.toml).
fn tyre_files(tag: &str, tir: &str) -> (PathBuf, PathBuf) {
    let d = dir(tag);
    std::fs::write(d.join("t.tir"), tir).unwrap();
    let p = d.join("t.toml");
    std::fs::write(
        &p,
        "name = \"t\"\nunloaded_radius_m = 0.338\nrolling_radius_m = 0.328\nnominal_load_n = 4000.0\n\
         [pacejka]\ntir_file = \"t.tir\"\naligning_moment = true\n",
    )
    .unwrap();
    (d, p)
}

fn build(tag: &str, side_line: &str) -> vehsim_core::Result<PacejkaTyre> {
    let (d, p) = tyre_files(tag, &TIR.replace("SIDE_LINE", side_line));
    let r = TyreFileSpec::load(&p).and_then(|s| s.build_pacejka(&p)).map(|(t, _)| t);
    std::fs::remove_dir_all(&d).unwrap();
    r
}

fn input(kappa: f64, alpha: f64, camber: f64) -> TyreInput {
    TyreInput { camber_rad: camber, ..TyreInput::new(3500.0, kappa, alpha, 1.0) }
}

fn grid() -> Vec<(f64, f64, f64)> {
    let mut v = Vec::new();
    for kappa in [-0.3, -0.02, 0.0, 0.01, 0.1] {
        for alpha in [-0.2, -0.01, 0.0, 0.004, 0.05, 0.3] {
            for camber in [-0.05, 0.0, 0.03] {
                v.push((kappa, alpha, camber));
            }
        }
    }
    v
}

#[test]
fn other_side_is_the_mirror_image() {
    let right = build("r", "TYRESIDE = 'RIGHT'").unwrap();
    assert_eq!(right.measured_side, TyreSide::Right);
    assert!(!right.is_mirrored());
    let as_measured = right.mounted_on(TyreSide::Right);
    let left = right.mounted_on(TyreSide::Left);
    assert!(left.is_mirrored());
    let back = left.mounted_on(TyreSide::Right);
    for (k, a, g) in grid() {
        let f = right.forces(&input(k, a, g));
        assert_eq!(as_measured.forces(&input(k, a, g)), f);
        assert_eq!(back.forces(&input(k, a, g)), f);
        let m = left.forces(&input(k, a, g));
        let o = right.forces(&input(k, -a, -g));
        assert_eq!((m.fx_n, m.fy_n, m.mz_nm), (o.fx_n, -o.fy_n, -o.mz_nm), "kappa {k} alpha {a} camber {g}");
        assert_eq!(left.peak_friction(&input(k, a, g)), right.peak_friction(&input(k, -a, -g)));
    }
    // Conicity / ply-steer: at zero slip and camber the lateral force and moment are non-zero and
    // opposite on the two sides, so a left/right pair cancels; the stiffnesses are the same.
    let z = input(0.0, 0.0, 0.0);
    let (fr, fl) = (right.forces(&z), left.forces(&z));
    assert!(fr.fy_n.abs() > 1.0 && fr.mz_nm.abs() > 0.01, "{fr:?}");
    assert_eq!((fl.fy_n, fl.mz_nm), (-fr.fy_n, -fr.mz_nm));
    assert_eq!(left.cornering_stiffness(&z), right.cornering_stiffness(&z));
    assert_eq!(left.longitudinal_stiffness(&z), right.longitudinal_stiffness(&z));
}

#[test]
fn tyreside_defaults_to_left_and_bad_values_are_input_errors() {
    let t = build("none", "").unwrap();
    assert_eq!(t.measured_side, TyreSide::Left);
    assert_eq!(build("l", "TYRESIDE = 'left'").unwrap().measured_side, TyreSide::Left);
    for (tag, line) in [("mid", "TYRESIDE = 'MIDDLE'"), ("sym", "TYRESIDE = 'SYMMETRIC'"), ("num", "TYRESIDE = 1")] {
        let e = build(tag, line).unwrap_err();
        assert!(matches!(e, vehsim_core::Error::Input { .. }), "{e}");
        let m = e.to_string();
        assert!(m.contains("t.tir") && m.contains("TYRESIDE") && m.contains("'LEFT'") && m.contains("'RIGHT'"), "{m}");
    }
}

// ------------------------------------------------------------------ which coefficients are sided

use vehsim_core::tyre::pacejka::{Combination, MfCoefficients};

/// A coefficient set with every coefficient that is not side-dependent set (most to 0.05, scale
/// factors to 1.05), plus `extra`.
fn coeffs_with(extra: &[(&str, f64)]) -> MfCoefficients {
    let mut m: std::collections::BTreeMap<&str, f64> = [
        ("FNOMIN", 4000.0),
        ("UNLOADED_RADIUS", 0.338),
        ("PCX1", 1.5),
        ("PDX1", 1.2),
        ("PKX1", 22.0),
        ("PCY1", 1.3),
        ("PDY1", 1.0),
        ("PKY1", -20.0),
        ("PKY2", 2.0),
        ("QBZ1", 10.0),
        ("QCZ1", 1.2),
        ("QDZ1", 0.09),
        ("QEZ1", -1.5),
        ("RBX1", 12.0),
        ("RCX1", 1.0),
        ("RBY1", 9.0),
        ("RCY1", 1.0),
        ("RVY5", 1.9),
        ("RVY6", 10.0),
    ]
    .into_iter()
    .collect();
    let zero = MfCoefficients::from_lookup(|_| Some(0.0), &mut Vec::new());
    let sided: Vec<&str> = zero.side_dependent().iter().map(|(n, _)| *n).collect();
    for n in MfCoefficients::NAMES {
        if !sided.contains(n) {
            m.entry(n).or_insert(if n.starts_with('L') { 1.05 } else { 0.05 });
        }
    }
    m.extend(extra.iter().copied());
    MfCoefficients::from_lookup(|n| m.get(n).copied(), &mut Vec::new())
}

/// Whether the tyre mounted on the other side gives the same forces at every grid point.
fn mirror_equal(c: &MfCoefficients, combination: Combination) -> bool {
    let t = PacejkaTyre::new(c.clone(), 1.0, 0.5, Some(combination), true);
    let m = t.mounted_on(TyreSide::Right);
    assert!(m.is_mirrored());
    grid().into_iter().all(|(k, a, g)| {
        let i = TyreInput { mu_surface: 0.3, ..input(k, a, g) };
        t.forces(&i) == m.forces(&i)
            && t.peak_friction(&i) == m.peak_friction(&i)
            && t.cornering_stiffness(&i) == m.cornering_stiffness(&i)
    })
}

/// `side_dependent` lists exactly the coefficients that make a tyre differ from its mirror image:
/// with all of them 0 (and every other coefficient non-zero) the mirrored tyre gives the same
/// forces, moment, bound and stiffness as numbers at every grid point, with either combined-slip
/// method; setting any one of them makes it differ.
#[test]
fn side_dependent_coefficients_are_exactly_the_asymmetric_ones() {
    let base = coeffs_with(&[]);
    let t = PacejkaTyre::new(base.clone(), 1.0, 0.5, None, true);
    assert!(t.has_mz && t.is_mirror_symmetric());
    for comb in [Combination::MagicFormula, Combination::Ellipse] {
        assert!(mirror_equal(&base, comb), "{comb:?}: a symmetric set differs from its mirror image");
    }
    for (name, _) in base.side_dependent() {
        let c = coeffs_with(&[(name, 0.02)]);
        assert!(!PacejkaTyre::new(c.clone(), 1.0, 0.5, None, true).is_mirror_symmetric());
        assert!(!mirror_equal(&c, Combination::MagicFormula), "{name} does not break the mirror symmetry");
    }
}

// ------------------------------------------------------------------------- the whole car, mounted

use vehsim_core::tyre::TyreModelKind;
use vehsim_spec::ManeuverFile;

/// The SRTT-like test tyre of `TIR` with only the lateral offset PVY1 = `pvy1` (conicity /
/// ply-steer: Fy = PVY1 mu_y Fz at zero slip), measured on `side`.
fn offset_tyre(tag: &str, side: &str, pvy1: f64) -> vehsim_core::tyre::Tyre {
    let tir = TIR
        .replace("SIDE_LINE", &format!("TYRESIDE = '{side}'"))
        .replace("PHX1 = 0.001\n", "")
        .replace("PHY1 = 0.003\nPVY1 = 0.02\nPVY3 = -0.1\n", &format!("PVY1 = {pvy1}\n"))
        .replace("QHZ1 = 0.002\nQDZ6 = 0.003\n", "");
    let (d, p) = tyre_files(tag, &tir);
    let t = TyreFileSpec::load(&p).and_then(|s| s.build(&p, TyreModelKind::Pacejka)).unwrap();
    std::fs::remove_dir_all(&d).unwrap();
    t
}

/// A sine steer of amplitude `steer_deg` (0: straight running) at 10 m/s on mu 0.3 with `tyre`,
/// model `vm`; the rows of the time series.
fn run(vm: &str, tyre: &vehsim_core::tyre::Tyre, steer_deg: f64) -> Vec<vehsim_core::sim::Row> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("maneuvers/sine_steer.toml");
    let mut file = ManeuverFile::load(&path).unwrap();
    file.tyre_model = "pacejka".into();
    file.vehicle_model = Some(vm.into());
    file.duration_s = Some(6.0);
    file.surface.mu = 0.3;
    file.maneuver.insert("steer_amplitude_deg".into(), toml::Value::Float(steer_deg));
    file.maneuver.insert("period_s".into(), toml::Value::Float(4.0));
    let mut cfg = file.build(&path).unwrap();
    cfg.vehicle.tyre = tyre.clone();
    vehsim_spec::run::execute(&cfg).rows
}

/// A tyre without side-dependent coefficients is the same on both sides: whatever its TYRESIDE,
/// both models run byte for byte the same (the SRTT file is such a tyre).
#[test]
fn a_symmetric_tyre_runs_the_same_whatever_its_side() {
    let (l, r) = (offset_tyre("sl", "LEFT", 0.0), offset_tyre("sr", "RIGHT", 0.0));
    assert!(l.same_on_both_sides() && r.same_on_both_sides());
    for vm in ["bicycle", "roll4dof"] {
        let (a, b) = (run(vm, &l, 10.0), run(vm, &r, 10.0));
        assert!(a.len() > 100);
        assert!(vehsim::run::timeseries_csv(&a) == vehsim::run::timeseries_csv(&b), "{vm}");
    }
}

/// Conicity / ply steer on a real car, PAC2002 convention (docs/tyres.md, "Tyre side"). A LEFT
/// file with PVY1 > 0 pushes the left wheels to +y at zero slip; mounted on the right it is
/// mirrored and pushes to -y. So on a straight-running car each axle's pair cancels (no pull), and
/// the car with a LEFT file is its own mirror image: a sine steer and the opposite sine steer give
/// mirrored trajectories. Mounting the right tyres reversed (the measured tyre, not its mirror
/// image, on the right: every wheel pushes to +y) makes the car pull to +y; so does the bicycle
/// that ignored the side. The same holds on the bicycle model (one mirrored pair per axle).
#[test]
fn conicity_cancels_on_an_axle_and_the_car_is_mirror_symmetric() {
    let tyre = offset_tyre("c", "LEFT", 0.03);
    assert!(!tyre.same_on_both_sides());
    let y_end = |rows: &[vehsim_core::sim::Row]| rows.last().unwrap().obs.kin.y_m;
    for vm in ["roll4dof", "bicycle"] {
        // Straight running: no pull.
        let s = run(vm, &tyre, 0.0);
        let max_y = s.iter().map(|r| r.obs.kin.y_m.abs()).fold(0.0, f64::max);
        let max_r = s.iter().map(|r| r.obs.kin.yaw_rate_radps.abs()).fold(0.0, f64::max);
        assert!(max_y < 1e-9 && max_r < 1e-12, "{vm}: straight car pulls: |Y| {max_y} m, |r| {max_r} rad/s");
        // Both right wheels carrying the tyre as measured (reversed mounting): a pull to +y.
        let mut same = tyre.clone();
        same.mounted[1] = same.mounted[0].clone();
        let p = run(vm, &same, 0.0);
        // (The car crabs: slip angles of about PVY1 mu Fz / C_alpha balance the offsets, so the
        // drift is small, 0.09 m over the 60 m of the 4-DOF run, but 1e8 times the mounted car's.)
        assert!(y_end(&p) > 0.03, "{vm}: reversed right tyres should pull to +y, Y = {}", y_end(&p));
        // Mirror symmetry of the whole car.
        let (a, b) = (run(vm, &tyre, 8.0), run(vm, &tyre, -8.0));
        assert_eq!(a.len(), b.len());
        let mut worst: f64 = 0.0;
        for (ra, rb) in a.iter().zip(&b) {
            let (ka, kb) = (ra.obs.kin, rb.obs.kin);
            for (u, v) in [
                (ka.x_m, kb.x_m),
                (ka.y_m, -kb.y_m),
                (ka.yaw_rad, -kb.yaw_rad),
                (ka.vy_mps, -kb.vy_mps),
                (ka.yaw_rate_radps, -kb.yaw_rate_radps),
                (ra.obs.fy_n[0], -rb.obs.fy_n[0]),
                (ra.obs.fy_n[1], -rb.obs.fy_n[1]),
            ] {
                worst = worst.max((u - v).abs() / (1.0 + u.abs()));
            }
        }
        assert!(worst < 1e-9, "{vm}: mirrored manoeuvre not mirrored: worst relative difference {worst:e}");
        assert!(y_end(&a).abs() > 1.0, "{vm}: a real manoeuvre");
        // Without the mirror (both sides as measured) the symmetry fails.
        let (c, d) = (run(vm, &same, 8.0), run(vm, &same, -8.0));
        let gap = (y_end(&c) + y_end(&d)).abs();
        assert!(gap > 0.1, "{vm}: the unmirrored car should not be mirror-symmetric (gap {gap} m)");
    }
}

// ------------------------------------------------------------------------------- bad input, CLI

/// Through the command line: a TYRESIDE that is neither LEFT nor RIGHT is exit code 2 with a
/// message naming the .tir file, the key and the allowed values.
#[test]
fn bad_tyreside_exits_2_naming_file_and_key() {
    let (d, _) = tyre_files("cli", &TIR.replace("SIDE_LINE", "TYRESIDE = 'BOTH'"));
    let spec = d.join("curves.toml");
    std::fs::write(
        &spec,
        "name = \"c\"\ntyre_file = \"t.toml\"\nproviders = [\"pacejka\"]\nloads_n = [4000.0]\n\
         mu_surface = 0.15\nslip_ratio = { min = 0.0, max = 0.4, points = 11 }\n\
         slip_angle_deg = { min = 0.0, max = 10.0, points = 11 }\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_vehsim"))
        .args(["tyre", spec.to_str().unwrap(), "--out", d.join("out").to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("t.tir") && err.contains("TYRESIDE") && err.contains("'LEFT', 'RIGHT'"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    std::fs::remove_dir_all(&d).unwrap();
}
