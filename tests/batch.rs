//! Batches through the command line: sweep expansion, parallel determinism, failing runs,
//! shards and merge, plots, and `vehsim compare`.

mod common;

use std::path::{Path, PathBuf};

use common::vehsim;

/// A 2 s sine-steer spec in a scratch folder, with `extra` appended (e.g. a [sweep] table).
fn sweep_case(tag: &str, extra: &str) -> PathBuf {
    sweep_case_of(tag, extra, 2.0)
}

/// [`sweep_case`] with runs of `duration_s` simulated.
fn sweep_case_of(tag: &str, extra: &str, duration_s: f64) -> PathBuf {
    let dir = common::temp_dir(tag);
    let vehicle = common::root().join("vehicles/sedan.toml");
    let head = common::sine_steer_spec("sweep", &vehicle.display().to_string(), duration_s);
    let spec = format!("{head}[output]\ninterval_s = 0.05\n{extra}");
    std::fs::write(dir.join("sweep.toml"), spec).unwrap();
    dir
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Every file under `dir` (relative path, bytes), sorted.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.strip_prefix(dir).unwrap().display().to_string(), read(&p)));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn sweep_expands_to_the_full_product_in_declared_order() {
    let dir =
        sweep_case("product", "[sweep]\n\"maneuver.speed_mps\" = [8.0, 10.0, 12.0]\n\"surface.mu\" = [0.1, 0.2]\n");
    let (code, out, err) = vehsim(&dir, &["run", "--quiet", "sweep.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let csv = String::from_utf8(read(&dir.join("results/sweep/summary.csv"))).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 6);
    let expected = [("8.0", "0.1"), ("8.0", "0.2"), ("10.0", "0.1"), ("10.0", "0.2"), ("12.0", "0.1"), ("12.0", "0.2")];
    for (i, (r, (v, mu))) in rows.iter().zip(expected).enumerate() {
        assert_eq!((r[0], r[2], r[3]), (format!("run_{i:04}").as_str(), v, mu));
        // The swept value really reached the run: its summary.json names it and its speed is held.
        let json: serde_json::Value =
            serde_json::from_slice(&read(&dir.join(format!("results/sweep/run_{i:04}/summary.json")))).unwrap();
        assert_eq!(json["mu"].as_f64().unwrap(), mu.parse::<f64>().unwrap());
        let vmax = json["max_speed_mps"].as_f64().unwrap();
        assert!((vmax - v.parse::<f64>().unwrap()).abs() < 0.2, "run {i}: max speed {vmax}");
    }
}

#[test]
fn jobs_1_and_jobs_2_write_identical_bytes() {
    let dir = sweep_case("jobs", "[sweep]\n\"maneuver.speed_mps\" = [8.0, 9.0, 10.0, 11.0, 12.0]\n");
    let (c1, _, e1) = vehsim(&dir, &["run", "--quiet", "--jobs", "1", "--out", "r1", "sweep.toml"]);
    let (c2, _, e2) = vehsim(&dir, &["run", "--quiet", "--jobs", "2", "--out", "r2", "sweep.toml"]);
    assert_eq!((c1, c2), (0, 0), "{e1}{e2}");
    let (a, b) = (tree(&dir.join("r1")), tree(&dir.join("r2")));
    assert!(a.len() > 10, "too few files: {}", a.len());
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.0, y.0);
        // summary.json names the spec path, which is the same; everything must match to the byte.
        assert!(x.1 == y.1, "{} differs between --jobs 1 and --jobs 2", x.0);
    }
}

#[test]
fn a_failing_run_is_reported_while_the_others_finish() {
    let dir = sweep_case(
        "failing",
        "[sweep]\ntyre_model = [\"linear\", \"no_such_model\"]\n\"maneuver.speed_mps\" = [8.0, 10.0]\n",
    );
    let (code, out, err) = vehsim(&dir, &["run", "sweep.toml"]);
    // An invalid combination is bad input (exit 2, on stderr); the valid runs still finish.
    assert_eq!(code, 2, "{out}{err}");
    let csv = String::from_utf8(read(&dir.join("results/sweep/summary.csv"))).unwrap();
    let status: Vec<&str> = csv.lines().skip(1).map(|l| l.split(',').nth(1).unwrap()).collect();
    assert_eq!(status, ["ok", "ok", "invalid", "invalid"]);
    assert!(csv.contains("no_such_model") && csv.contains("allowed"), "{csv}");
    assert!(dir.join("results/sweep/run_0001/timeseries.csv").exists());
    assert!(!dir.join("results/sweep/run_0002").exists());
    assert!(err.contains("run_0002: invalid") && err.contains("run_0003: invalid"), "{err}");
}

#[test]
fn shards_merged_equal_the_whole() {
    let dir = sweep_case(
        "shards",
        "[sweep]\n\"maneuver.speed_mps\" = [8.0, 9.0, 10.0, 11.0, 12.0]\n\"surface.mu\" = [0.1, 0.3]\n",
    );
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "whole", "sweep.toml"]);
    assert_eq!(c, 0, "{e}");
    for k in 1..=3 {
        let shard = format!("{k}/3");
        let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "parts", "--shard", &shard, "sweep.toml"]);
        assert_eq!(c, 0, "{e}");
    }
    // Merging an incomplete set is refused.
    let (c, _, e) = vehsim(&dir, &["merge", "parts/sweep.shard-1-of-3", "parts/sweep.shard-2-of-3"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("missing"), "{e}");
    let (c, out, e) =
        vehsim(&dir, &["merge", "parts/sweep.shard-1-of-3", "parts/sweep.shard-2-of-3", "parts/sweep.shard-3-of-3"]);
    assert_eq!(c, 0, "{out}{e}");
    // The merged folder, plots included, is byte for byte the unsharded one.
    let whole = tree(&dir.join("whole/sweep"));
    let merged = tree(&dir.join("parts/sweep"));
    assert!(whole.iter().any(|(p, _)| p.starts_with("plots")));
    assert_eq!(whole.iter().map(|x| &x.0).collect::<Vec<_>>(), merged.iter().map(|x| &x.0).collect::<Vec<_>>());
    for (x, y) in whole.iter().zip(&merged) {
        assert!(x.1 == y.1, "{} differs", x.0);
    }
    assert!(dir.join("parts/sweep.shard-1-of-3/run_0000").exists(), "shards are kept by default");
    // A second merge with --remove-shards gives the same folder and removes the shards.
    let shards = ["parts/sweep.shard-1-of-3", "parts/sweep.shard-2-of-3", "parts/sweep.shard-3-of-3"];
    let (c, out, e) = vehsim(&dir, &[&["merge", "--remove-shards"][..], &shards[..]].concat());
    assert_eq!(c, 0, "{out}{e}");
    assert!(tree(&dir.join("parts/sweep")) == merged);
    assert!(shards.iter().all(|s| !dir.join(s).exists()), "--remove-shards removes them");
}

fn is_png(p: &Path) -> bool {
    read(p).starts_with(b"\x89PNG\r\n\x1a\n")
}

#[test]
fn batch_and_plot_command_write_valid_png_and_svg() {
    let dir = sweep_case("plots", "[sweep]\n\"maneuver.speed_mps\" = [8.0, 12.0]\n");
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "sweep.toml"]);
    assert_eq!(c, 0, "{e}");
    let plots = dir.join("results/sweep/plots");
    for stem in ["yaw_rate", "slip_front", "slip_rear", "speed", "steer", "trajectory"] {
        assert!(is_png(&plots.join(format!("{stem}.png"))), "{stem}.png");
        let svg = String::from_utf8(read(&plots.join(format!("{stem}.svg")))).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{stem}.svg");
        assert!(svg.contains("speed_mps=8.0") && svg.contains("speed_mps=12.0"), "{stem}.svg lacks the legend");
    }
    std::fs::remove_dir_all(&plots).unwrap();
    let (c, out, e) = vehsim(&dir, &["plot", "results/sweep"]);
    assert_eq!(c, 0, "{out}{e}");
    assert!(is_png(&plots.join("yaw_rate.png")));
    let (c, _, e) = vehsim(&dir, &["plot", "nowhere"]);
    assert_eq!(c, 2, "{e}");
}

#[test]
fn compare_accepts_identical_and_detects_a_perturbed_trajectory() {
    let dir = sweep_case("compare", "");
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "sweep.toml"]);
    assert_eq!(c, 0, "{e}");
    let a = dir.join("results/sweep/timeseries.csv");
    let text = String::from_utf8(read(&a)).unwrap();
    let (c, out, _) = vehsim(&dir, &["compare", a.to_str().unwrap(), a.to_str().unwrap()]);
    assert_eq!(c, 0, "{out}");
    assert!(out.contains("within tolerance"), "{out}");
    // Perturb the yaw rate of one row by 1e-3 rad/s.
    let col = text.lines().next().unwrap().split(',').position(|c| c == "yaw_rate_radps").unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut f: Vec<String> = lines[20].split(',').map(str::to_string).collect();
    let t = f[0].clone();
    f[col] = (f[col].parse::<f64>().unwrap() + 1e-3).to_string();
    lines[20] = f.join(",");
    let b = dir.join("perturbed.csv");
    std::fs::write(&b, lines.join("\n") + "\n").unwrap();
    let (c, out, _) = vehsim(&dir, &["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    assert_eq!(c, 1, "{out}");
    assert!(out.contains("worst channel: yaw_rate_radps"), "{out}");
    // The time of the perturbed row, printed to four significant digits.
    let shown: f64 = out.split("at t = ").nth(1).and_then(|r| r.split(' ').next()).unwrap().parse().unwrap();
    let t: f64 = t.parse().unwrap();
    assert!((shown - t).abs() <= 5e-4 * t.abs().max(1.0), "t = {t} s not shown: {out}");
    let (c, out, _) =
        vehsim(&dir, &["compare", a.to_str().unwrap(), b.to_str().unwrap(), "--tol", "yaw_rate_radps=2e-3"]);
    assert_eq!(c, 0, "{out}");
    let (c, _, e) = vehsim(&dir, &["compare", a.to_str().unwrap(), "missing.csv"]);
    assert_eq!(c, 2, "{e}");
}

/// A run that spins out is marked `failed` with its event while the other runs of the batch
/// finish: a 15 m/s sine steer on mu 0.15 ice, rear drive, 4-DOF, ATIIM-Pacejka: 0.5 degrees of
/// steer stays within friction, 3 degrees spins the car. (A constant-radius run that is too fast
/// for its circle now ends earlier, leaving the circle: see tests/plausibility.rs.)
#[test]
fn a_spin_out_is_a_failed_run_and_the_batch_goes_on() {
    let dir = common::temp_dir("spinout");
    let spec = format!(
        "name = \"spin\"\nvehicle = \"{}/vehicles/sedan_rwd.toml\"\ntyre_model = \"atiim_pacejka\"\n\
         vehicle_model = \"roll4dof\"\nduration_s = 12.0\n[surface]\nmu = 0.15\n[maneuver]\nkind = \"sine_steer\"\n\
         speed_mps = 15.0\nsteer_amplitude_deg = 1.0\nperiod_s = 4.0\n[contact]\nmodel = \"atiim\"\n[sweep]\n\
         \"maneuver.steer_amplitude_deg\" = [0.5, 3.0]\n",
        common::root().display()
    );
    std::fs::write(dir.join("cr.toml"), spec).unwrap();
    let (code, out, err) = vehsim(&dir, &["run", "--quiet", "cr.toml"]);
    assert_eq!(code, 1, "{out}{err}");
    let csv = String::from_utf8(read(&dir.join("results/spin/summary.csv"))).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!((rows[0][1], rows[1][1]), ("ok", "failed"), "{csv}");
    assert!(rows[1].contains(&"spin_out"), "{csv}");
    let json: serde_json::Value =
        serde_json::from_slice(&read(&dir.join("results/spin/run_0001/summary.json"))).unwrap();
    assert!(json["events"].as_array().unwrap().iter().any(|e| e["kind"] == "spin_out"));
}

/// `vehsim validate` checks every sweep combination and names the invalid ones.
#[test]
fn validate_checks_every_sweep_combination() {
    let dir = sweep_case("validate", "[sweep]\ntyre_model = [\"linear\", \"no_such_model\"]\n");
    let (code, out, err) = vehsim(&dir, &["validate", "sweep.toml"]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("run_0001") && err.contains("no_such_model"), "{err}");
    assert!(!dir.join("results").exists());
    let dir = sweep_case("validate-ok", "[sweep]\n\"surface.mu\" = [0.1, 0.2, 0.3]\n");
    let (code, out, err) = vehsim(&dir, &["validate", "sweep.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("3 runs"), "{out}");
}

/// SIGINT during a batch: the process says it was interrupted, exits 130, and leaves neither a
/// results folder nor a temporary one; an earlier complete result of the same name is kept.
#[test]
fn sigint_leaves_a_complete_result_or_none_and_says_so() {
    let speeds: Vec<String> = (0..3000).map(|i| format!("{:.3}", 8.0 + 0.001 * i as f64)).collect();
    // The extra text continues the spec's [output] table, then adds the sweep.
    let extra =
        format!("timeseries = false\nplots = false\n[sweep]\n\"maneuver.speed_mps\" = [{}]\n", speeds.join(", "));
    // Runs of 60 s simulated (about 3 ms each): the 3000 take seconds on any machine, so the
    // signal at 0.7 s lands while validating or between runs (with 2 s runs a fast machine
    // finished the whole batch first).
    let dir = sweep_case_of("sigint", &extra, 60.0);
    // An earlier, complete result of the same name.
    std::fs::create_dir_all(dir.join("results/sweep")).unwrap();
    std::fs::write(dir.join("results/sweep/summary.csv"), "earlier\n").unwrap();
    let child = std::process::Command::new(common::BIN)
        .args(["run", "--quiet", "--jobs", "1", "sweep.toml"])
        .current_dir(&dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(700));
    let kill = std::process::Command::new("sh").args(["-c", &format!("kill -INT {}", child.id())]).status().unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "stderr: {err}");
    // Stopped while validating the 3000 combinations, between runs, or by the handler itself when
    // no check point came within 0.9 s (it removes the temporaries it knows of).
    assert!(
        err.contains("interrupted by SIGINT")
            && (err.contains("results/sweep left as it was")
                || err.contains("nothing written")
                || err.contains("nothing partial was written")),
        "{err}"
    );
    let left: Vec<_> =
        std::fs::read_dir(dir.join("results")).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    assert_eq!(left, vec![std::ffi::OsString::from("sweep")], "temporaries left behind");
    assert_eq!(std::fs::read_to_string(dir.join("results/sweep/summary.csv")).unwrap(), "earlier\n");
}
