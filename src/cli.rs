//! Command-line interface: parse arguments, validate every input before anything runs, call the
//! library, print results, and map errors to exit codes (0 success, 1 a run failed, 2 bad input).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::error::Error;
use crate::output::table::Table;
use crate::{batch, compare};

#[derive(Debug, Parser)]
#[command(name = "vehsim", version, about = "Vehicle-dynamics simulation for driving on ice")]
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
    },
    /// Join shard folders (results/<name>.shard-K-of-N) into results/<name>/.
    Merge {
        /// Every shard folder of one batch.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
    },
    /// Draw the standard charts of a results folder (one run or a batch) into <folder>/plots/.
    Plot {
        /// A results folder, e.g. results/dlc_ice.
        folder: PathBuf,
    },
    /// Compare two time-series CSV files channel by channel; exit 0 within tolerance, 1 outside.
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
    },
    /// Check manoeuvre specs, every sweep combination, and the vehicle and tyre files they name;
    /// run nothing.
    Validate {
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Sweep tyre forces over slip for the providers, loads and temperature rises of a tyre-curve
    /// spec; write CSV and PNG/SVG plots into <out>/<name>/.
    Tyre {
        file: PathBuf,
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Evaluate the ATIIM contact-patch model for a scenario spec; write grids, heat maps, the
    /// drawbar-pull curve and summary.json into <out>/<name>/.
    Atiim {
        file: PathBuf,
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Time repeated runs of one spec (simulation only, no output files); prints median and min
    /// wall time, real-time factor, steps and peak memory (format: src/bench.rs).
    Bench {
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

fn report(e: &Error) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(e.exit_code())
}

/// Entry point used by the binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    // Ctrl-C: finish nothing partial. Batches stop between runs and remove their temporary
    // folder; a second Ctrl-C ends the process at once (still leaving only hidden temporaries).
    let _ = ctrlc::set_handler(|| {
        if batch::INTERRUPTED.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    match cli.command {
        Command::Validate { files } => {
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
                        cfg.env.mu,
                        cfg.tyre_model.as_str(),
                        cfg.vehicle_model.as_str()
                    );
                }
            }
            code
        }
        Command::Run { files, out, jobs, shard, quiet } => {
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
            if jobs == Some(0) {
                return report(&Error::input(std::path::Path::new("--jobs"), "expected at least 1 thread"));
            }
            let mut code = ExitCode::SUCCESS;
            for b in &batches {
                let opts = batch::Options { jobs, shard, progress: !quiet };
                let result = match batch::execute(b, &out, opts) {
                    Ok(r) => r,
                    Err(e) => return report(&e),
                };
                if result.records.iter().any(|r| r.status != "ok") {
                    code = ExitCode::from(1);
                }
                if quiet {
                    for r in result.records.iter().filter(|r| r.status != "ok") {
                        eprintln!("{} {}: {} {}", b.name, batch::run_folder(r.index), r.status, r.message);
                    }
                    continue;
                }
                if b.is_sweep() {
                    println!("{}: {} runs -> {}", b.name, result.records.len(), result.dir.display());
                    print!("{}", batch::table(&b.keys, &result.records, 40));
                    for r in result.records.iter().filter(|r| r.status == "invalid") {
                        println!("{}: invalid: {}", batch::run_folder(r.index), r.message);
                    }
                } else if let Some(s) = result.records.first().and_then(|r| r.summary.as_ref()) {
                    let verdict = match s.passed {
                        Some(true) => "passed".to_string(),
                        Some(false) => format!("FAILED ({} cone boundaries hit)", s.cones_hit),
                        None => "no pass rule".to_string(),
                    };
                    println!(
                        "{}: {} at t = {:.2} s, {}; peak yaw rate {:.3} rad/s, peak sideslip {:.2} deg, peak ay {:.2} m/s^2 -> {}",
                        b.name,
                        s.end_reason,
                        s.end_time_s,
                        verdict,
                        s.peak_yaw_rate_radps,
                        s.peak_sideslip_rad.to_degrees(),
                        s.peak_ay_mps2,
                        result.dir.display()
                    );
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
        Command::Merge { shards } => match batch::merge(&shards) {
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
        Command::Compare { a, b, tol, default_tol } => {
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
            for c in &r.only_in_one {
                println!("note: channel '{c}' is in only one file; not compared");
            }
            if let Some(w) = r.worst() {
                println!(
                    "worst channel: {} = {:.3e} at t = {} s (tolerance {:.3e})",
                    w.channel, w.max_abs_error, w.at_t_s, w.tolerance
                );
            }
            let outside: Vec<_> = r.channels.iter().filter(|c| c.ratio() > 1.0).collect();
            if outside.is_empty() {
                println!("within tolerance: {} channels", r.channels.len());
                ExitCode::SUCCESS
            } else {
                for c in &outside {
                    println!(
                        "  outside: {} max error {:.3e} at t = {} s (tolerance {:.3e})",
                        c.channel, c.max_abs_error, c.at_t_s, c.tolerance
                    );
                }
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
