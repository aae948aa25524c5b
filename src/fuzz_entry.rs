//! Entry points for coverage-guided fuzzing (`fuzz/`, cargo-fuzz) and for the corpus regression
//! test (`tests/fuzz_corpus.rs`): one function per kind of input, each taking raw bytes.
//!
//! Every function feeds its bytes to the same parser and validator the program uses for that kind
//! of file and throws the result away: bad input must come back as an error, never as a panic, a
//! hang or an abort. The functions themselves never panic on their own account, so any panic seen
//! by the fuzzer is a bug in the library. See docs/fuzzing.md.
//!
//! Paths: a spec names other files relative to itself (a manoeuvre its vehicle, a vehicle its tyre,
//! a tyre its `.tir` file, a scenario its pressure grid). Each entry therefore pretends its bytes
//! were read from a file next to the project's own inputs (`maneuvers/`, `vehicles/`,
//! `vehicles/tyres/`, `tests/data/atiim/`) so that those references resolve exactly as they do
//! for the shipped specs. Nothing here writes a file.
//!
//! Bounds that keep one execution in milliseconds (documented limits of the harness, not of the
//! program):
//! - specs naming a device or kernel file (`/dev/`, `/proc/`, `/sys/`) are skipped: reading
//!   `/dev/zero` or `/dev/stdin` never ends, whatever the parser does;
//! - manoeuvre sweeps with more than [`MAX_SWEEP_RUNS`] combinations are skipped (the program
//!   allows up to a million; each is validated separately);
//! - a manoeuvre with `contact.model = "atiim"` has its `[contact]` table validated up to, but not
//!   including, the flash-table build (seconds, cached per process for the whole run); the rest of
//!   the spec is then validated with the isothermal contact model;
//! - a manoeuvre that validates is simulated for at most [`SIM_SECONDS`] s, and only when that
//!   takes at most a few hundred integrator steps.

use std::path::{Path, PathBuf};

use crate::discover::measured::{apply_sidecar, parse_run_csv, MeasuredRun};
use vehsim_core::sim::Method;
use vehsim_core::tyre::{TyreInput, TyreModelKind};
use vehsim_spec::contact::{ContactSpec, ScenarioSpec};
use vehsim_spec::files::parse_toml;
use vehsim_spec::patch_file::{parse_csv, read_png_map, ImageLayout};
use vehsim_spec::tir::parse_tir;
use vehsim_spec::tyre::PacejkaSection;
use vehsim_spec::tyre::TyreFileSpec;
use vehsim_spec::VehicleFile;

/// Largest number of sweep combinations a fuzzed manoeuvre may expand into.
pub const MAX_SWEEP_RUNS: usize = 64;
/// Longest simulated time of a fuzzed manoeuvre that validates, s.
pub const SIM_SECONDS: f64 = 0.05;
/// Smallest integrator step for which a fuzzed manoeuvre is simulated, s.
const SIM_MIN_STEP_S: f64 = 2e-4;

/// Names of the targets, as used for `fuzz/fuzz_targets/<name>.rs`, `fuzz/corpus/<name>/` and
/// `fuzz/regressions/<name>/`, in the order of [`run_target`].
pub const TARGETS: &[&str] = &[
    "vehicle_toml",
    "maneuver_toml",
    "tyre_toml",
    "tir",
    "measured_csv",
    "sidecar_toml",
    "pressure_csv",
    "pressure_png",
    "atiim_scenario_toml",
    "cli_args",
];

/// Run target `name` on `data`; false when there is no target of that name.
pub fn run_target(name: &str, data: &[u8]) -> bool {
    let f: fn(&[u8]) = match name {
        "vehicle_toml" => vehicle_toml,
        "maneuver_toml" => maneuver_toml,
        "tyre_toml" => tyre_toml,
        "tir" => tir,
        "measured_csv" => measured_csv,
        "sidecar_toml" => sidecar_toml,
        "pressure_csv" => pressure_csv,
        "pressure_png" => pressure_png,
        "atiim_scenario_toml" => atiim_scenario_toml,
        "cli_args" => cli_args,
        _ => return false,
    };
    f(data);
    true
}

/// The project folder (where `vehicles/`, `maneuvers/` and `tests/data/` are).
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The file the bytes pretend to come from: `fuzz_input.<ext>` in the project folder `dir`.
fn pretend(dir: &str, ext: &str) -> PathBuf {
    root().join(dir).join(format!("fuzz_input.{ext}"))
}

/// The bytes as text, as the file loaders read them (non-UTF-8 files are an input error there,
/// before any parsing, so there is nothing more to exercise).
fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// Does the text name a device or kernel file (which a loader would read forever)?
fn names_special_file(text: &str) -> bool {
    ["/dev/", "/proc/", "/sys/"].iter().any(|p| text.contains(p))
}

/// A handful of tyre inputs across the documented domain (and a little beyond it).
fn tyre_inputs(fz_nominal: f64) -> Vec<TyreInput> {
    let mut v = Vec::new();
    for fz in [0.0, 0.5 * fz_nominal, 3.0 * fz_nominal] {
        for kappa in [-1.0, 0.0, 0.1, 10.0] {
            for alpha in [-1.5, 0.0, 0.2] {
                let mut i = TyreInput::new(fz, kappa, alpha, 0.15);
                i.camber_rad = 0.05;
                i.surface_temp_c = -5.0;
                i.contact_temp_c = 2.0;
                i.vx_mps = if kappa == 10.0 { 0.0 } else { 15.0 };
                v.push(i);
            }
        }
    }
    v
}

/// Evaluate every method of a built tyre provider on [`tyre_inputs`].
fn exercise_tyre(model: &dyn vehsim_core::tyre::TyreModel, fz_nominal: f64) {
    for i in tyre_inputs(fz_nominal) {
        std::hint::black_box(model.forces(&i));
        std::hint::black_box(model.peak_friction(&i));
        std::hint::black_box(model.longitudinal_stiffness(&i));
        std::hint::black_box(model.cornering_stiffness(&i));
    }
}

/// A vehicle spec (`vehicles/*.toml`): parse, then validate with the linear and the Magic Formula
/// tyre providers (which reads the tyre file it names).
pub fn vehicle_toml(data: &[u8]) {
    let Some(text) = text(data) else { return };
    if names_special_file(text) {
        return;
    }
    let path = pretend("vehicles", "toml");
    let Ok(v) = parse_toml::<VehicleFile>(&path, text) else { return };
    for kind in [TyreModelKind::Linear, TyreModelKind::Pacejka] {
        let _ = std::hint::black_box(v.build(&path, kind));
    }
}

/// Replace an ATIIM `[contact]` table (and sweeps of contact keys) by the isothermal model after
/// validating what can be validated without the flash-table build.
fn defuse_atiim(path: &Path, table: &mut toml::Table) {
    if let Some(toml::Value::Table(sweep)) = table.get_mut("sweep") {
        sweep.retain(|k, _| !k.starts_with("contact"));
    }
    let Some(toml::Value::Table(contact)) = table.get_mut("contact") else { return };
    if contact.get("model").and_then(|m| m.as_str()) != Some("atiim") {
        return;
    }
    let spec: Result<ContactSpec, _> = toml::Value::Table(contact.clone()).try_into();
    if let Ok(spec) = spec {
        let _ = std::hint::black_box(spec.ranges(path));
        let _ = std::hint::black_box(spec.tyre.params(path, "contact.tyre.", -3.0));
    }
    contact.insert("model".into(), toml::Value::String("isothermal".into()));
}

/// Number of runs a sweep table expands into (saturating).
fn sweep_runs(table: &toml::Table) -> usize {
    match table.get("sweep") {
        Some(toml::Value::Table(s)) => {
            s.values().map(|v| v.as_array().map_or(1, |a| a.len().max(1))).fold(1usize, |a, b| a.saturating_mul(b))
        }
        _ => 1,
    }
}

/// A manoeuvre spec (`maneuvers/*.toml`, with its sweep): parse, expand, validate every
/// combination (vehicle and tyre files included), and simulate the first valid one briefly.
pub fn maneuver_toml(data: &[u8]) {
    let Some(text) = text(data) else { return };
    if names_special_file(text) {
        return;
    }
    let path = pretend("maneuvers", "toml");
    let mut table: toml::Table = match parse_toml(&path, text) {
        Ok(t) => t,
        Err(_) => return,
    };
    if sweep_runs(&table) > MAX_SWEEP_RUNS {
        return;
    }
    defuse_atiim(&path, &mut table);
    let Ok(batch) = crate::batch::from_table(&path, table) else { return };
    let Some(mut cfg) = batch.runs.into_iter().find_map(|r| r.config.ok()) else { return };
    let s = &mut cfg.settings;
    let adaptive_ok = match s.method {
        Method::Rk4 | Method::Rk4Exp | Method::Rk4Lag => true,
        Method::Dopri5 { rtol, atol } | Method::Dop853 { rtol, atol } => rtol >= 1e-8 && atol >= 1e-10,
    };
    if s.step_s >= SIM_MIN_STEP_S && adaptive_ok {
        s.duration_s = s.duration_s.min(SIM_SECONDS);
        std::hint::black_box(vehsim_spec::run::execute(&cfg));
    }
}

/// A tyre spec (`vehicles/tyres/*.toml`): parse, build every provider (the Magic Formula one may
/// read the `.tir` file it names) and evaluate the ones that build.
pub fn tyre_toml(data: &[u8]) {
    let Some(text) = text(data) else { return };
    if names_special_file(text) {
        return;
    }
    let path = pretend("vehicles/tyres", "toml");
    let Ok(spec) = parse_toml::<TyreFileSpec>(&path, text) else { return };
    for &kind in TyreModelKind::ALL {
        if let Ok(t) = spec.build(&path, kind) {
            exercise_tyre(t.model.as_ref(), t.nominal_load_n);
        }
    }
}

/// A `.tir` property file: parse, then build the Magic Formula provider from its coefficients
/// (as a tyre file with `[pacejka] tir_file = ...` would) and evaluate it.
pub fn tir(data: &[u8]) {
    let Some(text) = text(data) else { return };
    let path = pretend("vehicles/tyres", "tir");
    let Ok(f) = parse_tir(&path, text) else { return };
    let coefficients = vehsim_core::tyre::pacejka::MfCoefficients::NAMES
        .iter()
        .filter_map(|n| f.num(n).map(|v| (n.to_string(), v)))
        .collect();
    let spec = TyreFileSpec {
        name: "fuzz".into(),
        unloaded_radius_m: f.num("UNLOADED_RADIUS").unwrap_or(0.33),
        rolling_radius_m: 0.3,
        nominal_load_n: f.num("FNOMIN").unwrap_or(4000.0),
        relaxation_length_x_m: 0.15,
        linear: None,
        polynomial: None,
        pacejka: Some(PacejkaSection {
            tir_file: None,
            coefficients: Some(coefficients),
            overrides: Default::default(),
            mu_reference: 1.0,
            stiffness_mu_exponent: 0.5,
            combined: "auto".into(),
            aligning_moment: true,
        }),
        dugoff: None,
        dugoff_thermal: None,
        atiim_pacejka: None,
    };
    if let Ok((t, _)) = spec.build_pacejka(&path) {
        exercise_tyre(&t, spec.nominal_load_n);
    }
}

/// A measured-run CSV (`RUN.csv`), without a sidecar.
pub fn measured_csv(data: &[u8]) {
    let Some(text) = text(data) else { return };
    let _ = std::hint::black_box(parse_run_csv(&pretend("tests/data/discover", "csv"), text));
}

/// A valid two-second run the sidecar target applies its bytes to.
fn base_run() -> &'static MeasuredRun {
    static RUN: std::sync::OnceLock<MeasuredRun> = std::sync::OnceLock::new();
    RUN.get_or_init(|| {
        let csv = "t,steer,vx,yaw_rate,ay\n0,0,10,0,0\n1,0.01,10,0.02,0.2\n2,0.02,10,0.04,0.4\n";
        parse_run_csv(Path::new("base.csv"), csv).unwrap_or_else(|e| unreachable!("the base run is valid: {e}"))
    })
}

/// A measured-run sidecar (`RUN.toml`) applied to a valid run.
pub fn sidecar_toml(data: &[u8]) {
    let Some(text) = text(data) else { return };
    let mut run = base_run().clone();
    let _ = std::hint::black_box(apply_sidecar(&mut run, &pretend("tests/data/discover", "toml"), text));
}

/// A pressure-grid CSV (kPa, one line per row).
pub fn pressure_csv(data: &[u8]) {
    let Some(text) = text(data) else { return };
    let _ = std::hint::black_box(parse_csv(&pretend("tests/data/atiim", "csv"), text, 0.005, 0.005));
}

/// A PNG pressure map, read through two layouts: the one of the project's PNG tests (footprint
/// [0, 0, 10, 8), colour bar [20, 0, 24, 64)) and one taken from the last 10 bytes of the input
/// (PNG decoders ignore bytes after the IEND chunk, so the fuzzer can vary the layout by appending
/// them): four footprint and four colour-bar coordinates, the tolerance and the bar's top
/// pressure, one byte each.
pub fn pressure_png(data: &[u8]) {
    let path = pretend("tests/data/atiim", "png");
    let fixed = ImageLayout {
        footprint: [0, 0, 10, 8],
        colour_bar: [20, 0, 24, 64],
        bar_min_pa: 0.0,
        bar_max_pa: 630e3,
        tolerance: 40.0,
        dx_m: 0.005,
        dy_m: 0.005,
    };
    let _ = std::hint::black_box(read_png_map(&path, data, &fixed));
    if let Some(tail) = data.len().checked_sub(10).map(|n| &data[n..]) {
        let b = |i: usize| u32::from(tail[i]);
        let lay = ImageLayout {
            footprint: [b(0), b(1), b(2), b(3)],
            colour_bar: [b(4), b(5), b(6), b(7)],
            bar_min_pa: 0.0,
            bar_max_pa: f64::from(tail[9]) * 10e3,
            tolerance: f64::from(tail[8]) * 2.0,
            dx_m: 0.005,
            dy_m: 0.005,
        };
        let _ = std::hint::black_box(read_png_map(&path, data, &lay));
    }
}

/// An ATIIM scenario file (`vehsim atiim FILE`): parse and validate, which reads the pressure CSV
/// or PNG it names (relative to `tests/data/atiim/`) or synthesizes a grid.
pub fn atiim_scenario_toml(data: &[u8]) {
    let Some(text) = text(data) else { return };
    if names_special_file(text) {
        return;
    }
    let path = pretend("tests/data/atiim", "toml");
    let Ok(spec) = parse_toml::<ScenarioSpec>(&path, text) else { return };
    let _ = std::hint::black_box(spec.validate(&path));
}

/// Command-line arguments, one per line (a final newline ends the last one; bytes need not be
/// UTF-8 on Unix): parsed with the CLI's clap definition, then the argument values the CLI parses
/// itself before touching any file (`compare --tol`, `synth --effect/--params`). Nothing runs.
pub fn cli_args(data: &[u8]) {
    use clap::Parser;
    let mut args: Vec<std::ffi::OsString> = vec!["vehsim".into()];
    let body = data.strip_suffix(b"\n").unwrap_or(data);
    if !body.is_empty() {
        for a in body.split(|b| *b == b'\n') {
            #[cfg(unix)]
            args.push(<std::ffi::OsStr as std::os::unix::ffi::OsStrExt>::from_bytes(a).to_os_string());
            #[cfg(not(unix))]
            args.push(String::from_utf8_lossy(a).into_owned().into());
        }
    }
    let Ok(cli) = crate::cli::Cli::try_parse_from(args) else { return };
    match cli.command {
        crate::cli::Command::Compare { tol, .. } => {
            let _ = std::hint::black_box(crate::compare::parse_tolerances(&tol));
        }
        crate::cli::Command::Synth { effect, params, .. } => {
            if let Some(e) = crate::discover::Effect::from_name(&effect) {
                let _ = std::hint::black_box(crate::discover::synth::parse_params(e, &params));
            }
        }
        _ => {}
    }
}
