//! TYRESIDE: a `.tir` tyre mounted on the side it was measured for is evaluated as is; on the other
//! side it is its mirror image (y -> -y), so conicity and ply-steer act mirror-symmetrically.

use std::path::PathBuf;

use vehsim::tyre::pacejka::{PacejkaTyre, TyreSide};
use vehsim::tyre::spec::TyreFileSpec;
use vehsim::tyre::{TyreInput, TyreModel};

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

fn build(tag: &str, side_line: &str) -> vehsim::Result<PacejkaTyre> {
    let d = dir(tag);
    std::fs::write(d.join("t.tir"), TIR.replace("SIDE_LINE", side_line)).unwrap();
    let p = d.join("t.toml");
    std::fs::write(
        &p,
        "name = \"t\"\nunloaded_radius_m = 0.338\nrolling_radius_m = 0.328\nnominal_load_n = 4000.0\n\
         [pacejka]\ntir_file = \"t.tir\"\naligning_moment = true\n",
    )
    .unwrap();
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
        assert!(matches!(e, vehsim::Error::Input { .. }), "{e}");
        let m = e.to_string();
        assert!(m.contains("t.tir") && m.contains("TYRESIDE") && m.contains("'LEFT'") && m.contains("'RIGHT'"), "{m}");
    }
}
