//! `run_tyre_command` on the shipped figure spec writes CSVs and valid PNG + SVG plots.

use std::path::Path;

use vehsim::tyre_sweep::run_tyre_command;

#[test]
fn tyre_curves_spec_writes_pngs_svgs_and_csvs() {
    let spec = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/tyre/tyre_curves.toml"));
    let root = std::env::temp_dir().join(format!("vehsim-tyre-cmd-{}", std::process::id()));
    let out = run_tyre_command(spec, &root).expect("tyre command runs");
    assert_eq!(out, root.join("tyre_curves"));
    let stems = [
        "fx_vs_slip_ratio_atiim_pacejka_4000N",
        "fy_vs_slip_angle_atiim_pacejka_4000N",
        "fx_vs_slip_ratio_dugoff_thermal_4000N",
        "compare_fx_4000N",
        "compare_fy_4000N",
    ];
    for s in stems {
        let png = std::fs::read(out.join(format!("{s}.png"))).unwrap_or_else(|e| panic!("{s}.png: {e}"));
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{s}.png is not a PNG");
        let svg = std::fs::read_to_string(out.join(format!("{s}.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{s}.svg is not an SVG");
    }
    let fx = std::fs::read_to_string(out.join("fx_vs_slip_ratio.csv")).unwrap();
    let mut lines = fx.lines();
    assert_eq!(lines.next(), Some("provider,fz_n,delta_t_k,mu_surface,kappa,fx_n,fy_n,mz_nm,fx_over_fz"));
    // 2 temperature providers x 6 rises + 5 compared providers, 201 points each.
    assert_eq!(lines.clone().count(), (2 * 6 + 5) * 201);
    for l in lines {
        let cols: Vec<&str> = l.split(',').collect();
        assert_eq!(cols.len(), 9, "{l}");
        for c in &cols[1..] {
            let v: f64 = c.parse().unwrap_or_else(|_| panic!("not a number: {c} in {l}"));
            assert!(v.is_finite(), "{l}");
        }
    }
    let fy = std::fs::read_to_string(out.join("fy_vs_slip_angle.csv")).unwrap();
    assert!(fy.starts_with("provider,fz_n,delta_t_k,mu_surface,alpha_deg,alpha_rad,fx_n,fy_n,mz_nm,fy_over_fz\n"));
    assert_eq!(fy.lines().count() - 1, (2 * 6 + 5) * 151);
    if std::env::var_os("VEHSIM_KEEP_TEST_OUTPUT").is_none() {
        std::fs::remove_dir_all(&root).unwrap();
    }
}

#[test]
fn bad_sweep_specs_are_input_errors() {
    let dir = std::env::temp_dir().join(format!("vehsim-tyre-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tyre = concat!(env!("CARGO_MANIFEST_DIR"), "/vehicles/tyres/srtt_p225_60r16.toml");
    let base = format!(
        "name = \"x\"\ntyre_file = \"{tyre}\"\nproviders = [\"pacejka\"]\nloads_n = [4000.0]\nmu_surface = 0.15\n\
         slip_ratio = {{ min = 0.0, max = 0.4, points = 11 }}\nslip_angle_deg = {{ min = 0.0, max = 10.0, points = 11 }}\n"
    );
    let cases = [
        (base.replace("\"pacejka\"", "\"magic\""), "unknown tyre model 'magic'"),
        (format!("{base}bogus = 1\n"), "bogus"),
        (base.replace("points = 11 }\nslip_angle", "points = 1 }\nslip_angle"), "slip_ratio.points"),
    ];
    for (text, needle) in cases {
        let p = dir.join("spec.toml");
        std::fs::write(&p, text).unwrap();
        let e = run_tyre_command(&p, &dir).unwrap_err();
        assert!(matches!(e, vehsim_core::Error::Input { .. }), "{e}");
        assert!(e.to_string().contains(needle), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
