//! Hostile inputs, second round (issue 34): one regression test per command-line reproducer.
//! Every one must give a clean, bounded answer: validation within 2 s, the exit code README
//! defines, one message naming the file and the key (or line), nothing deleted or mixed.
//! docs/reliability.md lists them with their outcome.
//!
//! `cargo test --release --test hostile -- --nocapture` prints the measured times.

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use common::{vehsim, Case};

/// Longest a validation may take (the issue's bound), with room for a loaded machine.
const VALIDATE_BOUND: Duration = Duration::from_secs(2);

/// The ISO 3888-2 lane change at 7 m/s on the copied sedan with `tyre_model`.
fn dlc(tyre_model: &str) -> String {
    format!(
        "name = \"h\"\nvehicle = \"sedan.toml\"\ntyre_model = \"{tyre_model}\"\n[surface]\nmu = 0.15\n\
         [maneuver]\nkind = \"iso3888_2\"\nspeed_mps = 7.0\n"
    )
}

/// A scratch copy of the sedan with its tyre file and `.tir`, and the lane change with `tyre_model`.
fn case(tag: &str, tyre_model: &str) -> Case {
    let c = Case::new(tag, "h.toml", &dlc(tyre_model));
    std::fs::copy(common::root().join("vehicles/tyres/srtt_p225_60r16.tir"), c.dir.join("tyres/srtt_p225_60r16.tir"))
        .unwrap();
    c
}

/// `vehsim validate h.toml` in `c`: (exit code, stderr, seconds).
fn validate(c: &Case) -> (i32, String, f64) {
    let t0 = Instant::now();
    let (code, _, e) = c.run(&["validate", "h.toml"]);
    (code, e, t0.elapsed().as_secs_f64())
}

/// Exit 2 within the bound, one line naming `file` and every needle, no long digit run.
fn refused(c: &Case, what: &str, file: &str, needles: &[&str]) -> f64 {
    let (code, e, secs) = validate(c);
    assert_eq!(code, 2, "{what}: {e}");
    assert!(secs < VALIDATE_BOUND.as_secs_f64(), "{what}: validation took {secs:.2} s");
    assert_eq!(e.lines().count(), 1, "{what}: one line expected: {e}");
    assert!(e.contains(file), "{what}: message does not name {file}: {e}");
    for n in needles {
        assert!(e.contains(n), "{what}: message lacks '{n}': {e}");
    }
    let longest_digits = e.split(|c: char| !c.is_ascii_digit()).map(str::len).max().unwrap_or(0);
    assert!(longest_digits < 12, "{what}: a number printed at full length: {e}");
    eprintln!("{what}: refused in {secs:.3} s");
    secs
}

/// `.tir` coefficients, stiffnesses, inertias, areas and widths far outside a car's: each refused
/// at once naming its file and key (they used to validate forever, or in 14 s, or run for 10 min,
/// or be called plausible).
#[test]
fn extreme_coefficients_are_refused_within_two_seconds() {
    let tir = "tyres/srtt_p225_60r16.tir";
    for (what, from, to, key) in [
        ("PDY1 = 1e308", "PDY1                     = 1.00", "PDY1 = 1e308", "PDY1"),
        ("PKY1 = -1e20", "PKY1                     = -20", "PKY1 = -1e20", "PKY1"),
        ("PEY1 = 5 (E > 1)", "PEY1                     = -0.5", "PEY1 = 5", "PEY1"),
    ] {
        let c = case("hostile_tir", "pacejka");
        c.edit(tir, from, to);
        refused(&c, what, "srtt_p225_60r16.tir", &[&format!("key '{key}'"), "sedan.toml"]);
        // The same coefficient reaches the ATIIM-Pacejka tyre through its [pacejka] base.
        std::fs::write(c.dir.join("h.toml"), dlc("atiim_pacejka")).unwrap();
        refused(&c, what, "srtt_p225_60r16.tir", &[&format!("key '{key}'")]);
    }
    for v in ["1e10", "1e12"] {
        let c = case("hostile_stiff", "linear");
        c.edit(
            "tyres/srtt_p225_60r16.toml",
            "cornering_stiffness_n_per_rad = 69000.0",
            &format!("cornering_stiffness_n_per_rad = {v}"),
        );
        refused(
            &c,
            &format!("[linear] stiffness {v}"),
            "srtt_p225_60r16.toml",
            &["linear.cornering_stiffness_n_per_rad", v],
        );
    }
    for (key, to, shown) in [
        ("wheel_inertia_kgm2", "1e-9", "1e-9"),
        ("drag_area_m2", "1e9", "1e9"),
        ("body_width_m", "1e6", "1000000"),
        ("mass_kg", "1e12", "1e12"),
        ("yaw_inertia_kgm2", "1e300", "1e300"),
    ] {
        let c = case("hostile_vehicle", "pacejka");
        let text = std::fs::read_to_string(c.dir.join("sedan.toml")).unwrap();
        let line = text.lines().find(|l| l.starts_with(&format!("{key} ="))).unwrap().to_string();
        c.edit("sedan.toml", &line, &format!("{key} = {to}"));
        // The key itself is named (mass_kg = 1e12 was reported against the roll stiffness).
        refused(&c, &format!("{key} = {to}"), "sedan.toml", &[&format!("key '{key}'"), &format!("value {shown} ")]);
    }
}

/// A fastest mode no car has, from keys each within its own range (here a 1 us steer lag: a
/// mode of 1e6 1/s), is refused by the rate cap naming the vehicle file and what to check,
/// instead of a run with sub-microsecond steps.
#[test]
fn a_mode_faster_than_any_car_is_refused_naming_the_vehicle() {
    let c = case("hostile_rate", "pacejka");
    c.edit("sedan.toml", "[roll]", "[lateral]\nsteer_lag_s = 1e-6\n\n[roll]");
    refused(
        &c,
        "steer_lag_s = 1e-6",
        "sedan.toml",
        &["|lambda| = 1000000 1/s", "25000 1/s", "steer_lag_s", "h.toml key 'vehicle'"],
    );
}

/// The most extreme vehicle the bounds still accept (stiffest tyre, lightest wheel) validates
/// well within the bound: the step search is bisection, not a loop over step counts.
#[test]
fn the_most_extreme_accepted_vehicle_validates_quickly() {
    let c = case("hostile_edge", "linear");
    c.edit(
        "tyres/srtt_p225_60r16.toml",
        "cornering_stiffness_n_per_rad = 69000.0",
        "cornering_stiffness_n_per_rad = 5e6",
    );
    let text = std::fs::read_to_string(c.dir.join("tyres/srtt_p225_60r16.toml")).unwrap();
    let line = text.lines().find(|l| l.starts_with("longitudinal_stiffness_n =")).unwrap().to_string();
    c.edit("tyres/srtt_p225_60r16.toml", &line, "longitudinal_stiffness_n = 5e6");
    c.edit("sedan.toml", "wheel_inertia_kgm2 = 1.2", "wheel_inertia_kgm2 = 0.01");
    let (code, e, secs) = validate(&c);
    eprintln!("extreme accepted vehicle: exit {code} in {secs:.3} s");
    assert_eq!(code, 0, "{e}");
    assert!(secs < VALIDATE_BOUND.as_secs_f64(), "validation took {secs:.2} s: {e}");
}

/// The step search's bisection finds the same division as trying every count, for a stability
/// that holds from some count on, and asks at most about 16 + log2(counts) questions even for
/// 1e15 counts.
#[test]
fn the_step_search_bisects_in_bounded_time() {
    use std::cell::Cell;
    use vehsim_spec::maneuver::fewest_stable_division;
    for first_stable in [1usize, 2, 7, 16, 17, 18, 100, 12_345, 999_998] {
        let asked = Cell::new(0);
        let stable = |h: f64| {
            asked.set(asked.get() + 1);
            (0.01 / h).round() as usize >= first_stable
        };
        let got = fewest_stable_division(0.01, 0.01 / 1e6, stable);
        assert_eq!(got.map(|h| (0.01 / h).round() as usize), Some(first_stable), "from {first_stable}");
        assert!(asked.get() <= 16 + 2 + 20, "{} questions for {first_stable}", asked.get());
    }
    // Never stable below the plain step: none; and 1e15 counts cost about 70 questions.
    let asked = Cell::new(0);
    let never = |_: f64| {
        asked.set(asked.get() + 1);
        false
    };
    assert_eq!(fewest_stable_division(0.01, 1e-17, never), None);
    assert!(asked.get() <= 18, "{}", asked.get());
    assert_eq!(fewest_stable_division(0.01, f64::NAN, |_| true), None);
    assert_eq!(fewest_stable_division(0.01, 0.0, |_| true), None);
}

/// A run whose step an input drives down (here step_s = 1 us on a lane change) is refused before
/// it starts, with the estimate and --force named; nothing is written.
#[test]
fn a_run_that_would_take_minutes_is_refused_without_force() {
    let c = case("hostile_work", "pacejka");
    c.edit("h.toml", "speed_mps = 7.0\n", "speed_mps = 7.0\n[integrator]\nstep_s = 1e-6\n");
    let t0 = Instant::now();
    let (code, _, e) = c.run(&["run", "h.toml"]);
    assert_eq!(code, 2, "{e}");
    assert!(e.contains("estimated") && e.contains("in one run") && e.contains("--force"), "{e}");
    assert!(e.contains("3.") && e.contains("e7 integration steps"), "short form of the estimate: {e}");
    assert!(t0.elapsed() < VALIDATE_BOUND, "{:?}", t0.elapsed());
    assert!(!c.results().exists(), "nothing written");
    // `validate` says so too (and still passes the spec: it is valid, only long).
    let (code, _, e) = c.run(&["validate", "h.toml"]);
    assert_eq!(code, 0, "{e}");
    assert!(e.contains("warning") && e.contains("minutes of work") && e.contains("--force"), "{e}");
}

/// A named pipe given as the spec or as the vehicle file is refused at once (it used to block
/// until something was written into it).
#[test]
fn a_fifo_as_spec_or_vehicle_is_refused_without_blocking() {
    let c = case("hostile_fifo", "pacejka");
    for (name, spec) in [("pipe.toml", "pipe.toml"), ("vpipe.toml", "h.toml")] {
        let p = std::ffi::CString::new(c.dir.join(name).display().to_string()).unwrap();
        // SAFETY: mkfifo reads the NUL-terminated path we own.
        assert_eq!(unsafe { libc::mkfifo(p.as_ptr(), 0o600) }, 0);
        if spec == "h.toml" {
            c.edit("h.toml", "vehicle = \"sedan.toml\"", "vehicle = \"vpipe.toml\"");
        }
        let t0 = Instant::now();
        let (code, _, e) = c.run(&["validate", spec]);
        assert_eq!(code, 2, "{e}");
        assert!(e.contains(name) && e.contains("not a regular file"), "{e}");
        assert!(t0.elapsed() < VALIDATE_BOUND, "{:?}", t0.elapsed());
    }
}

/// A table written as an array (or a scalar) is refused naming the key; it used to run with the
/// array's values taken in field order.
#[test]
fn a_table_given_as_an_array_is_refused_naming_the_key() {
    for (what, from, to, key) in [
        ("surface = [1.0, 2.0]", "[surface]\nmu = 0.15\n", "surface = [1.0, 2.0]\n", "surface"),
        (
            "integrator = [\"rk4\", 0.01]",
            "name = \"h\"\n",
            "name = \"h\"\nintegrator = [\"rk4\", 0.01]\n",
            "integrator",
        ),
        ("surface = 0.15", "[surface]\nmu = 0.15\n", "surface = 0.15\n", "surface"),
    ] {
        let c = case("hostile_shape", "pacejka");
        c.edit("h.toml", from, to);
        refused(&c, what, "h.toml", &[&format!("key '{key}'"), "expected a table"]);
    }
    // In a vehicle file, and through a sweep (the path the Python layer takes).
    let c = case("hostile_shape_v", "pacejka");
    c.edit("sedan.toml", "[roll]", "lateral = [0.0, 0.0]\n[roll]");
    refused(&c, "lateral = [..]", "sedan.toml", &["key 'lateral'", "expected a table"]);
    let c = case("hostile_shape_s", "pacejka");
    std::fs::write(c.dir.join("h.toml"), format!("{}[sweep]\nsurface = [[0.1, 2.0]]\n", dlc("pacejka"))).unwrap();
    refused(&c, "swept surface = [0.1, 2.0]", "h.toml", &["key 'surface'", "expected a table"]);
}

/// A `.tir` whose [UNITS] say millimetres while the values are metres is refused naming the line
/// and the units; a UTF-8 byte-order mark is not text of the file.
#[test]
fn tir_units_are_checked_and_a_bom_is_skipped() {
    let tir = "tyres/srtt_p225_60r16.tir";
    let c = case("hostile_units", "pacejka");
    c.edit(tir, "LENGTH                   = 'meter'", "LENGTH = 'mm'");
    refused(&c, "LENGTH = 'mm'", "srtt_p225_60r16.tir", &["line ", "'mm'", "[UNITS]"]);
    let c = case("hostile_bom", "pacejka");
    let text = std::fs::read(c.dir.join(tir)).unwrap();
    std::fs::write(c.dir.join(tir), [&b"\xef\xbb\xbf"[..], &text].concat()).unwrap();
    let (code, e, _) = validate(&c);
    assert_eq!(code, 0, "a BOM is skipped: {e}");
}

/// A sweep spec of 6 runs on the copied sedan (linear tyre, short runs), `tyre_model` as given.
fn sweep(tyre_model: &str) -> String {
    let head = common::sine_steer_spec("s", "sedan.toml", 0.5).replace("\"linear\"", &format!("\"{tyre_model}\""));
    format!("{head}[output]\nplots = false\n[sweep]\n\"maneuver.speed_mps\" = [8.0, 9.0, 10.0]\n\"surface.mu\" = [0.15, 0.3]\n")
}

/// Shard 1/2 of a sweep and shard 2/2 of a copy with another tyre model used to merge into a
/// mixed batch; a truncated timeseries.csv was merged without complaint; a folder that is not a
/// shard got "shard.json: file not found". Each is now exit 2 naming the shard (and the run file).
#[test]
fn merge_refuses_mixed_truncated_and_foreign_folders() {
    let c = Case::new("hostile_merge", "s.toml", &sweep("linear"));
    std::fs::write(c.dir.join("d.toml"), sweep("dugoff")).unwrap();
    let (code, _, e) = c.run(&["run", "--quiet", "--out", "p", "--shard", "1/2", "s.toml"]);
    assert_eq!(code, 0, "{e}");
    let (code, _, e) = c.run(&["run", "--quiet", "--out", "p", "--shard", "2/2", "d.toml"]);
    assert_eq!(code, 0, "{e}");
    let (code, _, e) = c.run(&["merge", "p/s.shard-1-of-2", "p/s.shard-2-of-2"]);
    assert_eq!(code, 2, "{e}");
    assert!(e.contains("s.shard-2-of-2") && e.contains("s.shard-1-of-2") && e.contains("different batches"), "{e}");
    assert!(!c.dir.join("p/s").exists(), "nothing merged");
    // The right shard 2, then one of its time series cut short.
    let (code, _, e) = c.run(&["run", "--quiet", "--out", "p", "--shard", "2/2", "s.toml"]);
    assert_eq!(code, 0, "{e}");
    let ts = c.dir.join("p/s.shard-2-of-2/run_0001/timeseries.csv");
    let full = std::fs::read(&ts).unwrap();
    std::fs::write(&ts, &full[..full.len() / 2]).unwrap();
    let (code, _, e) = c.run(&["merge", "p/s.shard-1-of-2", "p/s.shard-2-of-2"]);
    assert_eq!(code, 2, "{e}");
    assert!(e.contains("s.shard-2-of-2") && e.contains("run_0001/timeseries.csv") && e.contains("truncated"), "{e}");
    std::fs::write(&ts, &full).unwrap();
    let (code, _, e) = c.run(&["merge", "p/s.shard-1-of-2", "p/s.shard-2-of-2"]);
    assert_eq!(code, 0, "the restored shards merge: {e}");
    // A folder that is not a shard.
    let (code, _, e) = c.run(&["merge", "p"]);
    assert_eq!(code, 2, "{e}");
    assert!(e.contains("not a shard folder") && e.contains("--shard"), "{e}");
}

/// `garbage` in a run's timeseries.csv, or only its header: `vehsim plot` is exit 2 naming the
/// file, and the existing plots stay byte for byte (they used to be deleted, with exit 0).
#[test]
fn plot_keeps_the_old_charts_when_the_time_series_is_unreadable() {
    let c = Case::new("hostile_plot", "r.toml", &common::sine_steer_spec("r", "sedan.toml", 2.0));
    let (code, _, e) = c.run(&["run", "--quiet", "r.toml"]);
    assert_eq!(code, 0, "{e}");
    let run = c.results().join("r");
    let plots = |d: &Path| {
        let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(d.join("plots"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
            .collect();
        v.sort();
        v
    };
    let before = plots(&run);
    assert!(before.len() >= 10, "{} plot files", before.len());
    let ts = run.join("timeseries.csv");
    let header = std::fs::read_to_string(&ts).unwrap().lines().next().unwrap().to_string();
    for (what, text) in [("garbage", "garbage\n".to_string()), ("header only", format!("{header}\n"))] {
        std::fs::write(&ts, &text).unwrap();
        let (code, _, e) = vehsim(&c.dir, &["plot", "results/r"]);
        assert_eq!(code, 2, "{what}: {e}");
        assert!(e.contains("timeseries.csv"), "{what}: {e}");
        assert!(plots(&run) == before, "{what}: the old plots changed");
        let hidden: Vec<_> = std::fs::read_dir(&run)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(hidden.is_empty(), "{what}: temporaries left: {hidden:?}");
    }
}

/// A measured run of 2 s at 100 Hz (as tests/discover_input.rs), with `edit` applied to each row.
fn measured(edit: impl Fn(usize, f64, [f64; 4]) -> String) -> String {
    let mut s = String::from("t,steer,vx,yaw_rate,ay\n");
    for k in 0..201 {
        let t = k as f64 * 0.01;
        s.push_str(&edit(k, t, [0.01 * t, 10.0, 0.03 * t, 0.3 * t]));
        s.push('\n');
    }
    s
}

fn row(t: f64, v: [f64; 4]) -> String {
    format!("{t},{},{},{},{}", v[0], v[1], v[2], v[3])
}

/// `vehsim discover` on one run: (exit code, stderr, seconds); nothing may be written on refusal.
fn discover(tag: &str, text: &str, extra: &[&str]) -> (i32, String, f64) {
    let dir = common::temp_dir(tag);
    std::fs::write(dir.join("run1.csv"), text).unwrap();
    let vehicle = common::root().join("vehicles/sedan.toml").display().to_string();
    let args: Vec<&str> =
        [&["discover", "--vehicle", vehicle.as_str(), "--out", "out"][..], extra, &["run1.csv"]].concat();
    let t0 = Instant::now();
    let (code, _, e) = vehsim(&dir, &args);
    let secs = t0.elapsed().as_secs_f64();
    if code == 2 {
        assert!(!dir.join("out").exists(), "{tag}: written on bad input");
    }
    (code, e, secs)
}

/// Time in microseconds (still running after 900 s) or milliseconds (2.5 min, then a verdict),
/// negative vx, vx = 0 with a yaw rate, a short row, and more samples than the work limit: each is
/// exit 2 at once with one message naming the file and what is wrong.
#[test]
fn discover_inputs_are_sanity_checked_before_any_search() {
    for (tag, text, needles) in [
        ("hostile_us", measured(|_, t, v| row(t * 1e6, v)), &["column 't'", "10000 s apart", "microseconds"][..]),
        ("hostile_ms", measured(|_, t, v| row(t * 1e3, v)), &["column 't'", "10 s apart", "milliseconds"][..]),
        ("hostile_neg", measured(|_, t, v| row(t, [v[0], -v[1], v[2], v[3]])), &["line 2", "column 'vx'", ">= 0"][..]),
        (
            "hostile_zero",
            measured(|_, t, v| row(t, [v[0], 0.0, 0.2 + v[2], v[3]])),
            &["line 2", "yaw rate 0.200", "vx = 0.000"][..],
        ),
        (
            "hostile_short",
            measured(|k, t, v| if k == 50 { "1,2,3,4".into() } else { row(t, v) }),
            &["line 52: 4 fields, the header has 5"][..],
        ),
    ] {
        let (code, e, secs) = discover(tag, &text, &[]);
        assert_eq!(code, 2, "{tag}: {e}");
        assert_eq!(e.lines().count(), 1, "{tag}: {e}");
        assert!(e.contains("run1.csv"), "{tag}: {e}");
        for n in needles {
            assert!(e.contains(n), "{tag}: lacks '{n}': {e}");
        }
        assert!(!e.contains("(line:"), "{tag}: the csv crate's own position leaked: {e}");
        assert!(secs < VALIDATE_BOUND.as_secs_f64(), "{tag}: {secs:.2} s");
    }
    // 250 001 samples (2500 s at 100 Hz): above the work limit, refused unless --force.
    let mut big = String::from("t,steer,vx,yaw_rate,ay\n");
    for k in 0..250_001 {
        big.push_str(&format!("{},0,10,0,0\n", k as f64 * 0.01));
    }
    let (code, e, secs) = discover("hostile_big", &big, &[]);
    assert_eq!(code, 2, "{e}");
    assert!(e.contains("250001 samples") && e.contains("--force"), "{e}");
    eprintln!("discover work limit: refused in {secs:.2} s");
}
