//! The command line's guards: `compare` as a strict trajectory check, the exit codes in `--help`,
//! a closed stdout, work and file-size limits, and messages about referenced files.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};

use common::{vehsim, Case, BIN};

fn write(dir: &Path, name: &str, text: &str) -> String {
    std::fs::write(dir.join(name), text).unwrap();
    name.to_string()
}

/// A reference with two channels over 0..1 s and variants that must fail: a channel missing, only
/// `t_s`, shifted and shorter time ranges, times out of order in A; each with one line per channel.
#[test]
fn compare_fails_missing_channels_short_or_shifted_ranges_and_unordered_times() {
    let dir = common::temp_dir("guard_compare");
    let rows = |t0: f64, n: usize| -> String {
        (0..n)
            .map(|i| {
                let t = t0 + 0.1 * i as f64;
                format!("{t},{},{}\n", 2.0 * t, 1.0)
            })
            .collect()
    };
    let a = write(&dir, "a.csv", &format!("t_s,y,z\n{}", rows(0.0, 11)));
    let cases = [
        ("no_z.csv", "t_s,y\n0,0\n0.5,1\n1,2\n".to_string(), "FAIL z: not in B"),
        ("only_t.csv", "t_s\n0\n0.5\n1\n".to_string(), "FAIL y: not in B"),
        ("shifted.csv", format!("t_s,y,z\n{}", rows(0.5, 11)), "A 0 to 1.000 s, B 0.5000 to 1.500 s"),
        ("short.csv", format!("t_s,y,z\n{}", rows(0.0, 6)), "A 0 to 1.000 s, B 0 to 0.5000 s"),
        ("extra.csv", "t_s,y,z,w\n0,0,1,5\n1,2,1,5\n".to_string(), "FAIL w: not in A"),
    ];
    let (c, out, e) = vehsim(&dir, &["compare", &a, &a]);
    assert_eq!(c, 0, "{out}{e}");
    assert_eq!(out.lines().filter(|l| l.starts_with("ok")).count(), 3, "one line per channel:\n{out}");
    for (name, text, expect) in cases {
        let b = write(&dir, name, &text);
        let (c, out, e) = vehsim(&dir, &["compare", &a, &b]);
        assert_eq!(c, 1, "{name}: {out}{e}");
        assert!(out.contains(expect), "{name}: expected '{expect}' in\n{out}");
    }
    // A channel named by --ignore may be missing; one named that neither file has is bad input.
    let (c, out, _) = vehsim(&dir, &["compare", &a, "no_z.csv", "--ignore", "z"]);
    assert_eq!(c, 0, "{out}");
    assert!(out.contains("skip z"), "{out}");
    let (c, _, e) = vehsim(&dir, &["compare", &a, "no_z.csv", "--ignore", "nope"]);
    assert_eq!(c, 2, "{e}");
    // The reference's own time order is checked.
    let unordered = write(&dir, "unordered.csv", "t_s,y,z\n0,0,1\n0.2,1,1\n0.1,2,1\n");
    let (c, _, e) = vehsim(&dir, &["compare", &unordered, &a]);
    assert_eq!(c, 2, "{e}");
    assert!(
        e.contains("unordered.csv")
            && e.contains("not strictly increasing")
            && e.contains("data row 3 has 0.1 after 0.2"),
        "{e}"
    );
}

#[test]
fn help_lists_the_exit_codes() {
    let (c, out, _) = vehsim(Path::new("."), &["--help"]);
    assert_eq!(c, 0);
    for code in ["0 success", "1 a run failed", "2 bad input", "3 I/O", "130 / 143"] {
        assert!(out.contains(code), "--help lacks '{code}':\n{out}");
    }
}

/// `vehsim validate ... | head -1`: the closed pipe is a clean exit 0 with nothing on stderr.
#[test]
fn a_closed_stdout_is_a_clean_exit() {
    let spec = common::root().join("maneuvers/dlc.toml");
    let args: Vec<String> =
        std::iter::once("validate".to_string()).chain(std::iter::repeat_n(spec.display().to_string(), 400)).collect();
    let mut child = Command::new(BIN).args(&args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    // Read nothing and close the pipe: every println! after this point meets EPIPE.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// The guards' spec: an hour-long sine steer on the sedan next to it.
fn spec() -> String {
    common::sine_steer_spec("g", "sedan.toml", 3600.0)
}

/// Work above the limits is refused with its estimate and nothing is written; `--jobs` is capped.
#[test]
fn absurd_work_is_refused_with_the_estimate() {
    let case = Case::new("guard_limits", "g.toml", &format!("{}[integrator]\nstep_s = 1e-8\n", spec()));
    let (c, _, e) = case.run(&["run", "g.toml"]);
    if c == 2 && e.contains("step_s") && !e.contains("estimated") {
        // The spec's own bounds on the step already refuse it; use a long sweep instead.
    } else {
        assert_eq!(c, 2, "{e}");
        assert!(e.contains("estimated") && e.contains("--force"), "{e}");
    }
    // 300 runs of 3600 s each: about 1e9 steps at the default step and some 60 GB of output.
    let speeds: Vec<String> = (0..100).map(|i| format!("{}", 5.0 + 0.01 * i as f64)).collect();
    let sweep = format!(
        "{}[sweep]\n\"maneuver.speed_mps\" = [{}]\n\"surface.mu\" = [0.1, 0.2, 0.3]\n",
        spec(),
        speeds.join(", ")
    );
    std::fs::write(case.dir.join("g.toml"), sweep).unwrap();
    let (c, _, e) = case.run(&["run", "g.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("estimated") && e.contains("integration steps") && e.contains("GB of output"), "{e}");
    assert!(!case.results().exists(), "nothing written");
    let (c, _, e) = case.run(&["run", "--jobs", "100000", "g.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("--jobs") && e.contains("at most"), "{e}");
}

/// Referenced files: a missing one names the referring file and key; a non-spec one (a system
/// file) is not echoed; a huge or endless one is refused; a missing key names its table.
#[test]
fn referenced_file_messages_name_the_referrer_and_echo_nothing() {
    let case = Case::new("guard_messages", "g.toml", &spec());
    case.edit("g.toml", "vehicle = \"sedan.toml\"", "vehicle = \"nothere.toml\"");
    let (c, _, e) = case.run(&["validate", "g.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("nothere.toml: file not found") && e.contains("g.toml key 'vehicle'"), "{e}");
    // A file that is not a spec: its text is never shown.
    let secret = "root:x:0:0:secret-text:/root:/bin/bash\n";
    std::fs::write(case.dir.join("passwd"), secret.repeat(3)).unwrap();
    case.edit("g.toml", "nothere.toml", "passwd");
    let (c, _, e) = case.run(&["validate", "g.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(!e.contains("secret-text") && !e.contains("root:x") && e.contains("key 'vehicle'"), "{e}");
    case.edit("g.toml", "passwd", "/dev/zero");
    let (c, _, e) = case.run(&["validate", "g.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("not a regular file"), "{e}");
    // The tyre named by the vehicle, two levels down.
    case.edit("g.toml", "/dev/zero", "sedan.toml");
    case.edit("sedan.toml", "tyres/srtt_p225_60r16.toml", "tyres/gone.toml");
    let (c, _, e) = case.run(&["validate", "g.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("gone.toml: file not found") && e.contains("key 'tyre'") && e.contains("key 'vehicle'"), "{e}");
    case.edit("sedan.toml", "tyres/gone.toml", "tyres/srtt_p225_60r16.toml");
    // A missing key names its table, not line 1.
    let veh = std::fs::read_to_string(case.dir.join("sedan.toml")).unwrap();
    let line = veh.lines().find(|l| l.starts_with("mass_kg")).unwrap().to_string();
    case.edit("sedan.toml", &line, "");
    let (c, _, e) = case.run(&["validate", "g.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("missing key 'mass_kg' in the top level") && !e.contains("line 1"), "{e}");
    // A spec file above the size limit.
    std::fs::write(case.dir.join("huge.toml"), "#".repeat(17 << 20)).unwrap();
    let (c, _, e) = case.run(&["validate", "huge.toml"]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("larger than the 16 MiB"), "{e}");
}
