//! `vehsim tyre` and `vehsim atiim` through the command line: a good spec writes its outputs
//! (exit 0); an unknown provider, a malformed `.tir` line, an unsupported property-file format,
//! a negative pressure or a missing file are bad input (exit 2, one message naming the file,
//! nothing written).

mod common;

use common::vehsim;

/// A scratch folder with a tyre-curve spec naming `providers` and a tyre file that uses `tir`.
fn tyre_case(tag: &str, providers: &str, tir: &str) -> std::path::PathBuf {
    let dir = common::temp_dir(tag);
    let root = common::root();
    let tyre = std::fs::read_to_string(root.join("vehicles/tyres/srtt_p225_60r16.toml")).unwrap();
    std::fs::write(dir.join("tyre.toml"), tyre).unwrap();
    std::fs::write(dir.join("srtt_p225_60r16.tir"), tir).unwrap();
    let spec = std::fs::read_to_string(root.join("scenarios/tyre/tyre_curves.toml"))
        .unwrap()
        .replace("../../vehicles/tyres/srtt_p225_60r16.toml", "tyre.toml")
        .replace(
            "providers = [\"polynomial\", \"pacejka\", \"dugoff\", \"dugoff_thermal\", \"atiim_pacejka\"]",
            &format!("providers = [{providers}]"),
        )
        .replace("points = 201", "points = 21")
        .replace("points = 151", "points = 16");
    std::fs::write(dir.join("curves.toml"), spec).unwrap();
    dir
}

fn shipped_tir() -> String {
    std::fs::read_to_string(common::root().join("vehicles/tyres/srtt_p225_60r16.tir")).unwrap()
}

#[test]
fn tyre_command_writes_curves_and_rejects_bad_input() {
    let dir = tyre_case("tyre-good", "\"pacejka\", \"atiim_pacejka\"", &shipped_tir());
    let (code, out, err) = vehsim(&dir, &["tyre", "curves.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(dir.join("results/tyre_curves").is_dir());

    let dir = tyre_case("tyre-unknown", "\"pacejka\", \"magic\"", &shipped_tir());
    let (code, _, err) = vehsim(&dir, &["tyre", "curves.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("magic"), "{err}");
    assert!(!dir.join("results").exists());

    // A malformed line in the .tir file: the message names the file and the line number.
    let tir = shipped_tir();
    let n = tir.lines().position(|l| l.trim_start().starts_with("LONGVL")).expect("LONGVL line") + 1;
    let bad = tir.replacen("LONGVL", "LONGVL = = 3 ???", 1);
    let dir = tyre_case("tyre-malformed", "\"pacejka\"", &bad);
    let (code, _, err) = vehsim(&dir, &["tyre", "curves.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(".tir") && err.contains(&n.to_string()), "line {n} not named: {err}");

    let bad = tir.replacen("'PAC2002'", "'MF_SWIFT_61'", 1);
    assert_ne!(bad, tir, "the shipped .tir should name PAC2002");
    let dir = tyre_case("tyre-format", "\"pacejka\"", &bad);
    let (code, _, err) = vehsim(&dir, &["tyre", "curves.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("PROPERTY_FILE_FORMAT") || err.contains("MF_SWIFT_61"), "{err}");
}

#[test]
fn atiim_command_writes_outputs_and_rejects_bad_input() {
    let dir = common::temp_dir("atiim-cli");
    let data = common::root().join("tests/data/atiim");
    for f in ["valid_csv.toml", "valid.csv", "negative.csv"] {
        std::fs::copy(data.join(f), dir.join(f)).unwrap();
    }
    let (code, out, err) = vehsim(&dir, &["atiim", "valid_csv.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(dir.join("results/csv_case/summary.json").exists());

    let bad = std::fs::read_to_string(dir.join("valid_csv.toml"))
        .unwrap()
        .replace("valid.csv", "negative.csv")
        .replace("csv_case", "neg_case");
    std::fs::write(dir.join("neg.toml"), bad).unwrap();
    let (code, _, err) = vehsim(&dir, &["atiim", "neg.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("negative.csv"), "{err}");
    assert!(!dir.join("results/neg_case").exists());

    let (code, _, err) = vehsim(&dir, &["atiim", "missing.toml"]);
    assert_eq!(code, 2, "{err}");
}
