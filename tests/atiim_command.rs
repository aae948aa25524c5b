//! `run_atiim_command` on shipped scenarios writes valid PNG, SVG, CSV and JSON.

use std::path::Path;

use vehsim::atiim::run_atiim_command;

fn check_dir(dir: &Path, rows: usize, cols: usize) {
    for stem in ["pressure", "rise", "wet", "film", "friction", "mu_visc", "drawbar"] {
        let png = std::fs::read(dir.join(format!("{stem}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{stem}.png");
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{stem}.svg");
    }
    for stem in ["pressure", "rise", "wet", "film", "friction", "mu_visc"] {
        let text = std::fs::read_to_string(dir.join(format!("{stem}.csv"))).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), rows, "{stem}.csv rows");
        for l in lines {
            let vals: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            assert_eq!(vals.len(), cols, "{stem}.csv cols");
            assert!(vals.iter().all(|v| v.is_finite() && *v >= 0.0), "{stem}.csv values");
        }
    }
    let db = std::fs::read_to_string(dir.join("drawbar.csv")).unwrap();
    assert!(db.starts_with("slip_ratio,drawbar_coeff"));
    assert!(db.lines().count() >= 3);
    let js: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let s = &js["summary"];
    for k in ["max_rise_k", "mean_rise_k", "max_film_m", "drawbar_coeff", "wet_fraction", "load_n"] {
        assert!(s[k].as_f64().is_some_and(|v| v.is_finite()), "summary.{k}");
    }
    // no temporary files left behind
    for e in std::fs::read_dir(dir).unwrap() {
        let n = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!n.contains(".tmp"), "left {n}");
    }
}

#[test]
fn shipped_scenario_writes_maps_curve_and_summary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("vehsim-atiim-cmd-{}", std::process::id()));
    let dir = run_atiim_command(&root.join("scenarios/atiim/srtt_7kN_torque.toml"), &out).unwrap();
    assert_eq!(dir, out.join("srtt_7kN_torque"));
    check_dir(&dir, 64, 48);
    let js: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    // the load carried by the grid is the scenario's load
    assert!((js["summary"]["load_n"].as_f64().unwrap() - 7000.0).abs() < 1e-6);
    let dir = run_atiim_command(&root.join("tests/data/atiim/valid_csv.toml"), &out).unwrap();
    check_dir(&dir, 4, 4);
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn every_shipped_scenario_loads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/atiim");
    let mut n = 0;
    for e in std::fs::read_dir(&root).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            vehsim_spec::contact::ScenarioSpec::load(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            n += 1;
        }
    }
    assert!(n >= 5);
}
