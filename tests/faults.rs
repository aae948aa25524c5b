//! Fault injection through the command line, bounded to a few seconds each: SIGKILL at random
//! instants while a sweep replaces an existing result, SIGTERM and SIGINT, a full disk (a small
//! tmpfs where this process may mount one), and `merge` with hostile shard descriptions.
//! The figures these print are quoted in docs/reliability.md.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{vehsim, BIN};

/// A sweep spec `name` over `mus` (a list of friction values) with 6 speeds; plots off.
fn sweep_spec(name: &str, mus: &str, duration_s: f64) -> String {
    let vehicle = common::root().join("vehicles/sedan.toml");
    let head = common::sine_steer_spec(name, &vehicle.display().to_string(), duration_s);
    format!(
        r#"{head}[output]
interval_s = 0.01
plots = false
[sweep]
"maneuver.speed_mps" = [8.0, 9.0, 10.0, 11.0, 12.0, 13.0]
"surface.mu" = {mus}
"#
    )
}

/// Every entry under `dir` (relative path, bytes; folders as empty), sorted.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries {
            let p = e.unwrap().path();
            let rel = p.strip_prefix(dir).unwrap().display().to_string();
            let m = std::fs::symlink_metadata(&p).unwrap();
            if m.is_dir() {
                out.push((rel + "/", Vec::new()));
                stack.push(p);
            } else {
                out.push((rel, std::fs::read(&p).unwrap_or_default()));
            }
        }
    }
    out.sort();
    out
}

/// Hidden entries (temporaries, aside copies) directly in `dir`.
fn hidden(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).filter(|n| n.starts_with('.')).collect()
        })
        .unwrap_or_default()
}

/// A small xorshift generator: the instants are random but reproducible from the printed seed.
struct Rng(u64);
impl Rng {
    fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn signal(pid: u32, sig: &str) {
    let ok = Command::new("kill").args([sig, &pid.to_string()]).status().unwrap().success();
    assert!(ok || sig == "-KILL", "kill {sig} {pid}");
}

/// SIGKILL at 24 random instants while a sweep replaces an existing result with another: the
/// results folder is always, byte for byte, the complete old one or the complete new one, and
/// the next run cleans the killed run's leftovers.
#[test]
fn sigkill_while_replacing_leaves_the_old_or_the_new_folder_complete() {
    let dir = common::temp_dir("fault_kill");
    std::fs::write(dir.join("a.toml"), sweep_spec("res", "[0.15, 0.3]", 3.0)).unwrap();
    std::fs::write(dir.join("b.toml"), sweep_spec("res", "[0.2, 0.4]", 3.0)).unwrap();
    let mut trees = Vec::new();
    let mut full = Duration::ZERO;
    for spec in ["a.toml", "b.toml"] {
        let t0 = Instant::now();
        let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--jobs", "2", spec]);
        full = full.max(t0.elapsed());
        assert_eq!(c, 0, "{e}");
        trees.push(tree(&dir.join("results/res")));
    }
    assert!(trees[0] != trees[1] && trees[0].len() == trees[1].len() && trees[0].len() > 20);
    let seed = std::env::var("VEHSIM_FAULT_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(0x5eed_1234_u64);
    let mut rng = Rng(seed);
    let (mut old, mut new) = (0, 0);
    let kills = 24;
    for i in 0..kills {
        // Alternate the specs so that every run replaces a complete folder with a different one.
        let (spec, before) = if i % 2 == 0 { ("a.toml", 1) } else { ("b.toml", 0) };
        let at = full.mul_f64(1.2 * rng.next_f64());
        let mut child = Command::new(BIN)
            .args(["run", "--quiet", "--jobs", "2", spec])
            .current_dir(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(at);
        let _ = child.kill();
        let _ = child.wait();
        let now = tree(&dir.join("results/res"));
        if now == trees[before] {
            old += 1;
        } else if now == trees[1 - before] {
            new += 1;
        } else {
            panic!("kill {i} at {at:?} (seed {seed}): results/res is neither the old nor the new folder");
        }
        // Leave the folder as `before` expects for the next kill: the other spec's result.
        if now != trees[1 - before] {
            let (c, _, e) = vehsim(&dir, &["run", "--quiet", spec]);
            assert_eq!(c, 0, "{e}");
        }
    }
    // The next complete run removes whatever the killed runs left.
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "a.toml"]);
    assert_eq!(c, 0, "{e}");
    assert!(hidden(&dir.join("results")).is_empty(), "{:?}", hidden(&dir.join("results")));
    eprintln!(
        "{kills} SIGKILLs (seed {seed}, instants uniform in 0..{:.2} s): {old} old folder, {new} new folder, 0 partial",
        1.2 * full.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Start `args` in `dir`, send `sig` after `after`, return (exit code, stderr, seconds from the
/// signal to the exit).
fn interrupt(dir: &Path, args: &[&str], sig: &str, after: Duration) -> (i32, String, f64) {
    let child =
        Command::new(BIN).args(args).current_dir(dir).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    std::thread::sleep(after);
    let t0 = Instant::now();
    signal(child.id(), sig);
    let out = child.wait_with_output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned(), t0.elapsed().as_secs_f64())
}

/// SIGTERM and SIGINT stop a sweep and a single long run alike within about a second, with one
/// line and exit 143 / 130, leaving no temporary and the previous result as it was.
#[test]
fn sigterm_and_sigint_stop_every_run_quickly_and_leave_no_temporaries() {
    let dir = common::temp_dir("fault_term");
    // 36 runs of 3000 s, rows every 1 s: seconds of work on any machine, so that the signal at
    // 0.4 s lands mid-sweep (36 runs of 60 s took 0.38 s on a fast machine: the sweep could end
    // before the signal).
    let sweep =
        sweep_spec("res", "[0.15, 0.2, 0.25, 0.3, 0.35, 0.4]", 3000.0).replace("interval_s = 0.01", "interval_s = 1.0");
    std::fs::write(dir.join("sweep.toml"), sweep).unwrap();
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "sweep.toml"]);
    assert_eq!(c, 0, "{e}");
    let before = tree(&dir.join("results/res"));
    // One run with no check point inside: 3000 s of simulated time.
    let long = sweep_spec("long", "[0.15]", 3000.0)
        .replace("\"maneuver.speed_mps\" = [8.0, 9.0, 10.0, 11.0, 12.0, 13.0]\n", "");
    std::fs::write(dir.join("long.toml"), long.replace("[sweep]\n\"surface.mu\" = [0.15]\n", "")).unwrap();
    for (spec, sig, code, name) in [
        ("sweep.toml", "-TERM", 143, "SIGTERM"),
        ("sweep.toml", "-INT", 130, "SIGINT"),
        ("long.toml", "-TERM", 143, "SIGTERM"),
        ("long.toml", "-INT", 130, "SIGINT"),
    ] {
        let (c, err, secs) = interrupt(&dir, &["run", "--quiet", "--force", spec], sig, Duration::from_millis(400));
        assert_eq!(c, code, "{spec} {sig}: {err}");
        let lines: Vec<&str> = err.lines().collect();
        assert_eq!(lines.len(), 1, "{err}");
        assert!(lines[0].contains(&format!("interrupted by {name}")) && lines[0].contains("results/"), "{err}");
        assert!(secs < 2.5, "{spec} {sig}: stopped after {secs:.2} s");
        assert!(hidden(&dir.join("results")).is_empty(), "{:?}", hidden(&dir.join("results")));
        eprintln!("{spec} {name}: exit {c} after {secs:.2} s: {}", lines[0]);
    }
    assert!(tree(&dir.join("results/res")) == before, "the previous result is left as it was");
    assert!(!dir.join("results/long").exists());
    // Leftovers of a killed process are found and removed at the next start.
    let stale = dir.join("results/.res.tmp4999999");
    std::fs::create_dir_all(stale.join("run_0000")).unwrap();
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "sweep.toml"]);
    assert_eq!(c, 0, "{e}");
    assert!(e.contains("warning: removed") && e.contains(".res.tmp4999999"), "{e}");
    assert!(hidden(&dir.join("results")).is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Mount a tmpfs of `kib` KiB at `at`; false where this process may not mount.
fn mount_tmpfs(at: &Path, kib: u32) -> bool {
    std::fs::create_dir_all(at).unwrap();
    Command::new("mount")
        .args(["-t", "tmpfs", "-o", &format!("size={kib}k"), "tmpfs", at.to_str().unwrap()])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

struct Unmount(PathBuf);
impl Drop for Unmount {
    fn drop(&mut self) {
        let _ = Command::new("umount").args(["-l", self.0.to_str().unwrap()]).status();
    }
}

/// A full disk (a 200 KiB tmpfs): the sweep is refused before it starts with its estimate, and
/// when forced it fails with exit 3; `tyre` and `atiim` likewise. Nothing half-written carries a
/// final name and an older result stays whole. Where no tmpfs can be mounted the injected writer
/// error of the library's unit test (output::tests) covers the same path.
#[test]
fn a_full_disk_leaves_nothing_half_written() {
    let dir = common::temp_dir("fault_full");
    let disk = dir.join("disk");
    if !mount_tmpfs(&disk, 200) {
        eprintln!("skipped: cannot mount a tmpfs here (the injected writer error in output::tests covers this)");
        return;
    }
    let _unmount = Unmount(disk.clone());
    std::fs::write(dir.join("small.toml"), sweep_spec("res", "[0.15]", 0.1)).unwrap();
    std::fs::write(dir.join("big.toml"), sweep_spec("res", "[0.15, 0.2, 0.25, 0.3]", 6.0)).unwrap();
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "disk", "small.toml"]);
    assert_eq!(c, 0, "{e}");
    let before = tree(&disk);
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "disk", "big.toml"]);
    assert_eq!(c, 3, "{e}");
    // The sizes are told in the unit that suits them (the tmpfs has kilobytes free, not "0.00 GB").
    assert!(e.contains("kB free there") && !e.contains("0.00 GB"), "{e}");
    eprintln!("full disk, not forced: {}", e.trim());
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--force", "--out", "disk", "big.toml"]);
    assert_eq!(c, 3, "{e}");
    assert!(e.contains("No space left on device"), "{e}");
    assert!(tree(&disk) == before, "the older result is whole and nothing else was left");
    for (cmd, spec) in [("tyre", "maneuvers/tyre_curves.toml"), ("atiim", "maneuvers/atiim/srtt_4kN_free_rolling.toml")]
    {
        let spec = common::root().join(spec);
        if !spec.exists() {
            continue;
        }
        let (c, _, e) = vehsim(&dir, &[cmd, spec.to_str().unwrap(), "--out", "disk"]);
        assert_eq!(c, 3, "{cmd}: {e}");
        assert!(tree(&disk) == before, "{cmd} left something on the full disk");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `merge` with hostile shard.json names (a parent path, an absolute path, empty, dots, a
/// separator) and a shard whose run folder is a symlink out: each refused with exit 2, and not a
/// byte outside the results root changes (nor inside it).
#[test]
fn hostile_merge_names_touch_nothing_outside_the_root() {
    let dir = common::temp_dir("fault_merge");
    std::fs::write(dir.join("s.toml"), sweep_spec("s", "[0.15]", 0.5)).unwrap();
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "root/results", "--shard", "1/1", "s.toml"]);
    assert_eq!(c, 0, "{e}");
    std::fs::create_dir_all(dir.join("victim")).unwrap();
    std::fs::write(dir.join("victim/precious.txt"), "keep me").unwrap();
    std::fs::write(dir.join("root/keep.txt"), "keep me too").unwrap();
    let shard = dir.join("root/results/s.shard-1-of-1");
    let good = std::fs::read_to_string(shard.join("shard.json")).unwrap();
    let victim = dir.join("victim");
    let names = [
        "../victim".to_string(),
        "../../victim".to_string(),
        victim.display().to_string(),
        String::new(),
        ".".into(),
        "..".into(),
        "/".into(),
        "a/b".into(),
        ".hidden".into(),
        "x\\u0000y".into(),
        "s/../../../victim".into(),
    ];
    let snapshot = tree(&dir);
    let mut refused = 0;
    for n in &names {
        let json = good.replacen("\"name\":\"s\"", &format!("\"name\":{}", serde_json_string(n)), 1);
        assert_ne!(json, good);
        std::fs::write(shard.join("shard.json"), &json).unwrap();
        let (c, _, e) = vehsim(&dir, &["merge", "--remove-shards", shard.to_str().unwrap()]);
        assert_eq!(c, 2, "name {n:?}: {e}");
        refused += 1;
        let mut now = tree(&dir);
        now.retain(|(p, _)| p != "root/results/s.shard-1-of-1/shard.json");
        let mut was = snapshot.clone();
        was.retain(|(p, _)| p != "root/results/s.shard-1-of-1/shard.json");
        assert!(now == was, "name {n:?} changed files");
    }
    std::fs::write(shard.join("shard.json"), &good).unwrap();
    // A run folder that is a symlink out of the root, and a destination that is a symlink out.
    let run0 = shard.join("run_0000");
    std::fs::rename(&run0, dir.join("victim/run_0000")).unwrap();
    std::os::unix::fs::symlink(dir.join("victim/run_0000"), &run0).unwrap();
    let (c, _, e) = vehsim(&dir, &["merge", "--remove-shards", shard.to_str().unwrap()]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("incomplete shard"), "{e}");
    std::fs::remove_file(&run0).unwrap();
    std::fs::rename(dir.join("victim/run_0000"), &run0).unwrap();
    std::os::unix::fs::symlink(&victim, dir.join("root/results/s")).unwrap();
    let (c, _, e) = vehsim(&dir, &["merge", "--remove-shards", shard.to_str().unwrap()]);
    assert_eq!(c, 3, "{e}");
    assert!(e.contains("not a folder"), "{e}");
    assert!(shard.join("run_0000/summary.json").exists(), "a failed merge keeps its shards");
    assert_eq!(std::fs::read_dir(&victim).unwrap().count(), 1);
    assert_eq!(std::fs::read_to_string(dir.join("victim/precious.txt")).unwrap(), "keep me");
    // An incomplete shard (a run folder removed) is refused.
    std::fs::remove_file(dir.join("root/results/s")).unwrap();
    std::fs::remove_dir_all(shard.join("run_0003")).unwrap();
    let (c, _, e) = vehsim(&dir, &["merge", shard.to_str().unwrap()]);
    assert_eq!(c, 2, "{e}");
    assert!(e.contains("run_0003"), "{e}");
    eprintln!("{refused} hostile names and 3 hostile layouts refused; 0 files outside the root touched");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A JSON string literal (the tests avoid a serde_json dev-dependency of their own).
fn serde_json_string(s: &str) -> String {
    if s.contains("\\u") {
        return format!("\"{s}\"");
    }
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// Shards on two file systems (one on a tmpfs): the merge copies across, the result equals the
/// unsharded run byte for byte, and `--remove-shards` removes both shards only afterwards.
#[test]
fn merge_across_file_systems_copies_and_verifies() {
    let dir = common::temp_dir("fault_xfs");
    let other = dir.join("other");
    if !mount_tmpfs(&other, 8192) {
        eprintln!("skipped: cannot mount a tmpfs here");
        return;
    }
    let _unmount = Unmount(other.clone());
    std::fs::write(dir.join("s.toml"), sweep_spec("s", "[0.15]", 0.5)).unwrap();
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "whole", "s.toml"]);
    assert_eq!(c, 0, "{e}");
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "parts", "--shard", "1/2", "s.toml"]);
    assert_eq!(c, 0, "{e}");
    let (c, _, e) = vehsim(&dir, &["run", "--quiet", "--out", "other", "--shard", "2/2", "s.toml"]);
    assert_eq!(c, 0, "{e}");
    let (c, out, e) = vehsim(&dir, &["merge", "--remove-shards", "parts/s.shard-1-of-2", "other/s.shard-2-of-2"]);
    assert_eq!(c, 0, "{out}{e}");
    assert!(tree(&dir.join("parts/s")) == tree(&dir.join("whole/s")), "merged differs from the whole run");
    assert!(!dir.join("parts/s.shard-1-of-2").exists() && !other.join("s.shard-2-of-2").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
