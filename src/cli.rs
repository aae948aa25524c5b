//! Command-line interface: parse arguments, validate every input before anything runs, call the
//! library, print results, and map errors to exit codes in one place ([`report`], [`EXIT_CODES`]).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::error::Error;
use crate::output::num::{sig, Sig};
use crate::output::signals;
use crate::output::table::Table;
use crate::{batch, compare};

/// The exit codes, as `--help` shows them (README "Exit codes" says the same).
pub const EXIT_CODES: &str =
    "Exit codes: 0 success; 1 a run failed (diverged, spun out, left its path) or compare found a \
difference; 2 bad input (a spec, a flag, a referenced file); 3 I/O or environment error (disk full, permission, a \
collision); 130 / 143 stopped by SIGINT / SIGTERM (temporary output removed, results left complete or as before).";

#[derive(Debug, Parser)]
#[command(name = "vehsim", version, about = "Vehicle-dynamics simulation for driving on ice", after_help = EXIT_CODES)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run manoeuvre specs (with their sweeps) and write results/<name>/.
    Run {
        /// Manoeuvre spec files (TOML).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Folder for the results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Worker threads for the runs of a sweep (default: all cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Run only the K-th of N disjoint parts of each sweep (K from 1 to N), into
        /// results/<name>.shard-K-of-N/; join the parts with `vehsim merge`.
        #[arg(long)]
        shard: Option<crate::batch::Shard>,
        /// No progress bar, no table; print nothing but errors.
        #[arg(long)]
        quiet: bool,
        /// Run even above the work and output limits (1e9 steps, 10 GB, the free space).
        #[arg(long)]
        force: bool,
    },
    /// Join shard folders (results/<name>.shard-K-of-N) into results/<name>/.
    Merge {
        /// Every shard folder of one batch.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Remove the shard folders once the merged folder is in place and every copied file was
        /// compared with its source (default: keep them).
        #[arg(long)]
        remove_shards: bool,
    },
    /// Draw the standard charts of a results folder (one run or a batch) into <folder>/plots/.
    Plot {
        /// A results folder, e.g. results/dlc_ice.
        folder: PathBuf,
    },
    /// Compare two time-series CSV files channel by channel, one line per channel; exit 0 when every
    /// channel is within tolerance, both have every channel (or it is --ignore'd) and their time
    /// ranges overlap by at least 99 %; 1 otherwise.
    Compare {
        /// Reference file.
        a: PathBuf,
        /// File compared with the reference (interpolated onto its times).
        b: PathBuf,
        /// Absolute tolerance of one channel, e.g. --tol yaw_rate_radps=1e-4 (repeatable).
        #[arg(long = "tol")]
        tol: Vec<String>,
        /// Absolute tolerance of every channel not named by --tol.
        #[arg(long, default_value_t = 1e-6)]
        default_tol: f64,
        /// A channel allowed to be in only one of the files (repeatable).
        #[arg(long)]
        ignore: Vec<String>,
    },
    /// Check manoeuvre specs, every sweep combination, and the vehicle and tyre files they name;
    /// run nothing.
    Validate {
        /// Manoeuvre spec files (TOML) to check.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// No progress counter (it appears only on a terminal, for sweeps that take seconds).
        #[arg(long)]
        quiet: bool,
    },
    /// Sweep tyre forces over slip for the providers, loads and temperature rises of a tyre-curve
    /// spec; write CSV and PNG/SVG plots into <out>/<name>/.
    Tyre {
        /// Tyre-curve spec file (TOML), e.g. scenarios/tyre/tyre_curves.toml.
        file: PathBuf,
        /// Folder under which <name>/ is written.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Evaluate the ATIIM contact-patch model for a scenario spec; write grids, heat maps, the
    /// drawbar-pull curve and summary.json into <out>/<name>/.
    Atiim {
        /// ATIIM scenario spec file (TOML).
        file: PathBuf,
        /// Folder under which <name>/ is written.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Time repeated runs of one spec (simulation only, no output files); prints median and min
    /// wall time, real-time factor, steps and peak memory (format: src/bench.rs).
    Bench {
        /// Manoeuvre spec file (TOML) of the run to time.
        file: PathBuf,
        /// Number of timed runs.
        #[arg(long, default_value_t = 200)]
        runs: usize,
        /// Vehicle model instead of the spec's: bicycle or roll4dof.
        #[arg(long)]
        model: Option<String>,
        /// Tyre provider instead of the spec's (linear, polynomial, pacejka, dugoff, ...).
        #[arg(long)]
        tyre_model: Option<String>,
        /// Contact-temperature model instead of the spec's: isothermal or atiim.
        #[arg(long)]
        contact: Option<String>,
        /// One tab-separated line (columns: see src/bench.rs) instead of the sentence.
        #[arg(long)]
        tsv: bool,
    },
    /// ISO 3888-2: the highest entry speed that clears the course; constant radius: the highest
    /// steady lateral acceleration; for every [sweep] combination. Writes <out>/<name>/envelope.csv
    /// and plots/envelope.png/.svg (spec keys: src/envelope.rs, docs/iso3888-2.md).
    Envelope {
        /// Envelope spec: a run spec (iso3888_2 or constant_radius) with optional `[envelope]` search
        /// settings and `[sweep]` (e.g. scenarios/envelope/envelope_ice_temperature.toml).
        file: PathBuf,
        /// Output root; the envelope is written to OUT/<name>/ (envelope.csv, plots/).
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Worker threads (default: all cores); the output does not depend on it.
        #[arg(long)]
        jobs: Option<usize>,
    },
    /// Find where measured runs and the baseline model disagree, name the missing effect, fit it and
    /// show the gap shrink on held-out data; writes report.json, report.md, effects.toml, plots.
    Discover {
        /// Vehicle spec file.
        #[arg(long)]
        vehicle: PathBuf,
        /// Tyre file (default: the one the vehicle names).
        #[arg(long)]
        tyre: Option<PathBuf>,
        /// Tyre provider: linear, polynomial, pacejka (default), dugoff, dugoff_thermal, atiim_pacejka.
        #[arg(long, default_value = "pacejka")]
        tyre_model: String,
        /// Baseline model: bicycle (default) or roll4dof.
        #[arg(long, default_value = "bicycle")]
        model: String,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Measured runs (RUN.csv, each with an optional RUN.toml sidecar).
        #[arg(required = true)]
        runs: Vec<PathBuf>,
        /// No progress and no summary (progress is shown only on a terminal anyway).
        #[arg(long)]
        quiet: bool,
    },
    /// Generate measured-like runs (CSV + sidecar, seeded sensor noise) from the replay model with one
    /// effect switched on (or `none`).
    Synth {
        /// tyre_relaxation, load_transfer, thermal_friction, friction_change, steer_compliance,
        /// sensor_bias, axle_cornering_stiffness, axle_peak_friction, yaw_inertia or none; the
        /// --params names pick the form (steer_lag_s: steering lag; stretch_*: a stretch; patch_*:
        /// a ground patch; relaxation_length_front_m: transient slip; load_sensitivity_*).
        #[arg(long)]
        effect: String,
        /// Effect parameters, name=value (repeatable); defaults per effect.
        #[arg(long = "params", num_args = 1..)]
        params: Vec<String>,
        /// Vehicle spec file.
        #[arg(long, default_value = "vehicles/sedan.toml")]
        vehicle: PathBuf,
        /// Tyre provider.
        #[arg(long, default_value = "pacejka")]
        tyre_model: String,
        /// Noise seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
    /// Convert the Stanford race-lap data set (one column per file) into measured runs.
    ConvertStanford {
        /// Folder with t.txt, delta.txt, vx.txt, yawRate.txt, ayCG.txt, vy.txt, axCG.txt.
        dir: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Segment length, s.
        #[arg(long, default_value_t = 20.0)]
        segment_s: f64,
        /// Number of segments (from the start).
        #[arg(long, default_value_t = 6)]
        segments: usize,
    },
}

/// The one place an error becomes a message and an exit code; an interruption ends the process
/// with its one line (130 / 143).
pub fn report(e: &Error) -> ExitCode {
    if let Error::Interrupted(kept) = e {
        signals::exit_with(e.exit_code(), &signals::interrupted_line(kept));
    }
    eprintln!("error: {e}");
    ExitCode::from(e.exit_code())
}

/// Entry point used by the binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Validate { files, quiet } => {
            crate::progress::set_quiet(quiet);
            let mut code = ExitCode::SUCCESS;
            for f in &files {
                let b = match batch::load(f) {
                    Ok(b) => b,
                    Err(e) => {
                        code = report(&e);
                        continue;
                    }
                };
                let mut invalid = 0;
                for r in &b.runs {
                    match &r.config {
                        Ok(cfg) => {
                            for w in &cfg.vehicle.tyre_warnings {
                                eprintln!("warning: {w}");
                            }
                        }
                        Err(msg) => {
                            invalid += 1;
                            eprintln!("error: {} {}: {msg}", f.display(), batch::run_folder(r.index));
                        }
                    }
                }
                if invalid > 0 {
                    code = ExitCode::from(2);
                } else if let Some(Ok(cfg)) = b.runs.first().map(|r| &r.config) {
                    println!(
                        "{}: ok ({} run{}; {} with {} on mu {}, tyre model {}, vehicle model {})",
                        f.display(),
                        b.runs.len(),
                        if b.runs.len() == 1 { "" } else { "s" },
                        cfg.kind,
                        cfg.vehicle.name,
                        Sig(cfg.env.mu),
                        cfg.tyre_model.as_str(),
                        cfg.vehicle_model.as_str()
                    );
                }
            }
            code
        }
        Command::Run { files, out, jobs, shard, quiet, force } => {
            crate::progress::set_quiet(quiet);
            let mut batches = Vec::new();
            for f in &files {
                match batch::load(f) {
                    Ok(b) => batches.push(b),
                    Err(e) => return report(&e),
                }
            }
            let mut warned = std::collections::BTreeSet::new();
            for w in batches
                .iter()
                .flat_map(|b| &b.runs)
                .filter_map(|r| r.config.as_ref().ok())
                .flat_map(|c| &c.vehicle.tyre_warnings)
            {
                if warned.insert(w.clone()) {
                    eprintln!("warning: {w}");
                }
            }
            let mut names = std::collections::BTreeSet::new();
            for b in &batches {
                if !names.insert(b.name.clone()) {
                    return report(&Error::key(
                        &b.spec_file,
                        "name",
                        format!(
                            "'{}' is used by more than one spec in this call; results would overwrite each other",
                            b.name
                        ),
                    ));
                }
            }
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            match jobs {
                Some(0) => return report(&Error::input(std::path::Path::new("--jobs"), "expected at least 1 thread")),
                Some(j) if j > 4 * cores && !force => {
                    let allowed = format!("{j} threads; at most 4 x {cores} cores = {} (or --force)", 4 * cores);
                    return report(&Error::input(std::path::Path::new("--jobs"), allowed));
                }
                _ => {}
            }
            for b in &batches {
                if let Err(e) = batch::check_limits(b, shard, &out, force) {
                    return report(&e);
                }
            }
            let mut code = ExitCode::SUCCESS;
            for b in &batches {
                let opts = batch::Options { jobs, shard, progress: !quiet };
                let result = match batch::execute(b, &out, opts) {
                    Ok(r) => r,
                    Err(e) => return report(&e),
                };
                if result.records.iter().any(|r| r.status == "invalid") {
                    code = ExitCode::from(2);
                } else if result.records.iter().any(|r| r.status != "ok") && code == ExitCode::SUCCESS {
                    code = ExitCode::from(1);
                }
                for r in result.records.iter().filter(|r| r.status == "invalid") {
                    eprintln!("error: {} {}: invalid: {}", b.name, batch::run_folder(r.index), r.message);
                }
                if quiet {
                    for r in result.records.iter().filter(|r| r.status == "failed") {
                        eprintln!("{} {}: {} {}", b.name, batch::run_folder(r.index), r.status, r.message);
                    }
                    continue;
                }
                if b.is_sweep() {
                    println!("{}: {} runs -> {}", b.name, result.records.len(), result.dir.display());
                    print!("{}", batch::table(&b.keys, &result.records, 40));
                } else if let Some(s) = result.records.first().and_then(|r| r.summary.as_ref()) {
                    let verdict = match s.passed {
                        Some(true) => "passed".to_string(),
                        Some(false) => format!("FAILED ({} cone boundaries hit)", s.cones_hit),
                        None => "no pass rule".to_string(),
                    };
                    let verdict = if s.plausible { verdict } else { format!("{verdict}, IMPLAUSIBLE") };
                    println!(
                        "{}: {} at t = {} s, {}; peak yaw rate {} rad/s, peak sideslip {} deg, peak ay {} m/s^2 -> {}",
                        b.name,
                        s.end_reason,
                        Sig(s.end_time_s),
                        verdict,
                        Sig(s.peak_yaw_rate_radps),
                        Sig(s.peak_sideslip_rad.to_degrees()),
                        Sig(s.peak_ay_mps2),
                        result.dir.display()
                    );
                    for r in &s.implausible {
                        println!("  implausible: {r}");
                    }
                }
            }
            code
        }
        Command::Tyre { file, out } => match crate::tyre::run_tyre_command(&file, &out) {
            Ok(d) => {
                println!("{} -> {}", file.display(), d.display());
                ExitCode::SUCCESS
            }
            Err(e) => report(&e),
        },
        Command::Atiim { file, out } => match crate::contact::command::run_atiim_command(&file, &out) {
            Ok(d) => {
                println!("{} -> {}", file.display(), d.display());
                ExitCode::SUCCESS
            }
            Err(e) => report(&e),
        },
        Command::Merge { shards, remove_shards } => match batch::merge(&shards, remove_shards) {
            Ok(d) => {
                println!("merged {} shards -> {}", shards.len(), d.display());
                ExitCode::SUCCESS
            }
            Err(e) => report(&e),
        },
        Command::Plot { folder } => match crate::plot::runs::plot_results(&folder, &folder) {
            Ok(w) => {
                for p in w {
                    println!("{}.png, .svg", p.display());
                }
                ExitCode::SUCCESS
            }
            Err(e) => report(&e),
        },
        Command::Compare { a, b, tol, default_tol, ignore } => {
            let tols = match compare::parse_tolerances(&tol) {
                Ok(t) => t,
                Err(e) => return report(&Error::input(std::path::Path::new("--tol"), e)),
            };
            if !(default_tol.is_finite() && default_tol >= 0.0) {
                return report(&Error::input(
                    std::path::Path::new("--default-tol"),
                    "expected a finite tolerance >= 0",
                ));
            }
            let (ta, tb) = match (Table::read(&a), Table::read(&b)) {
                (Ok(x), Ok(y)) => (x, y),
                (Err(e), _) | (_, Err(e)) => return report(&e),
            };
            let r = match compare::compare(&a, &ta, &b, &tb, &tols, default_tol) {
                Ok(r) => r,
                Err(e) => return report(&e),
            };
            if let Some(c) = ignore.iter().find(|c| ta.column(c).is_none() && tb.column(c).is_none()) {
                return report(&Error::input(
                    std::path::Path::new("--ignore"),
                    format!("names channel '{c}', which neither file has"),
                ));
            }
            for line in r.lines(&ignore) {
                println!("{line}");
            }
            if let Some(w) = r.worst() {
                println!(
                    "worst channel: {} = {} at t = {} s (tolerance {})",
                    w.channel,
                    Sig(w.max_abs_error),
                    sig(w.at_t_s, 4),
                    Sig(w.tolerance)
                );
            }
            let failed = r.lines(&ignore).iter().filter(|l| l.starts_with("FAIL")).count();
            if r.passes(&ignore) {
                println!("within tolerance: {} channels", r.channels.len());
                ExitCode::SUCCESS
            } else {
                println!("FAILED: {failed} of {} lines", r.channels.len() + r.only_in_one.len());
                ExitCode::from(1)
            }
        }
        Command::Bench { file, runs, model, tyre_model, contact, tsv } => {
            let opts = crate::bench::Options { runs, model, tyre_model, contact };
            match crate::bench::bench(&file, &opts) {
                Ok(r) => {
                    println!("{}", if tsv { r.tsv() } else { r.line() });
                    ExitCode::SUCCESS
                }
                Err(e) => report(&e),
            }
        }
        Command::Envelope { file, out, jobs } => {
            if jobs == Some(0) {
                return report(&Error::input(std::path::Path::new("--jobs"), "expected at least 1 thread"));
            }
            match crate::envelope::load(&file).and_then(|e| crate::envelope::run_envelope(&e, &out, jobs)) {
                Ok((dir, rows)) => {
                    for r in &rows {
                        let what = if r.label.is_empty() { r.params.join(", ") } else { r.label.clone() };
                        let v = r.limit.value.map_or("none".into(), |v| format!("{v:.3}"));
                        println!("{what}: {v} ({} runs) {}", r.limit.runs, r.limit.note);
                    }
                    println!("-> {}", dir.display());
                    ExitCode::SUCCESS
                }
                Err(e) => report(&e),
            }
        }
        Command::Discover { vehicle, tyre, tyre_model, model, out, runs, quiet } => {
            crate::discover::cli_discover(vehicle, tyre, &tyre_model, model, out, runs, quiet)
        }
        Command::Synth { effect, params, vehicle, tyre_model, seed, out } => {
            crate::discover::cli_synth(&effect, &params, &vehicle, &tyre_model, seed, &out)
        }
        Command::ConvertStanford { dir, out, segment_s, segments } => {
            crate::discover::cli_convert(&dir, &out, segment_s, segments)
        }
    }
}
