//! Command-line interface: parse arguments, validate every input before anything runs, call the
//! library, print results, and map errors to exit codes in one place (`report`, `EXIT_CODES`).
// The commands' doc comments are their `--help` text, written for a terminal: `<name>` there is a
// placeholder and `[sweep]` a TOML table, not HTML or a link.
#![allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Parser, Subcommand};

use crate::batch;
use crate::output::signals;
use vehsim_core::error::Result;
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::vehicle::VehicleModelKind;
use vehsim_spec::contact::ContactModelKind;

/// The exit codes, as `--help` shows them (README "Exit codes" says the same).
pub(crate) const EXIT_CODES: &str =
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
        /// Vehicle model instead of the spec's.
        #[arg(long, value_parser = choice(VehicleModelKind::ALL, VehicleModelKind::as_str))]
        model: Option<VehicleModelKind>,
        /// Tyre provider instead of the spec's.
        #[arg(long, value_parser = choice(TyreModelKind::ALL, TyreModelKind::as_str))]
        tyre_model: Option<TyreModelKind>,
        /// Contact-temperature model instead of the spec's.
        #[arg(long, value_parser = choice(ContactModelKind::ALL, ContactModelKind::as_str))]
        contact: Option<ContactModelKind>,
        /// One tab-separated line (columns: see src/bench.rs) instead of the sentence.
        #[arg(long)]
        tsv: bool,
    },
    /// Time the yardstick: a deliberately naive single-track model, RK4 at 1 ms over 10 s
    /// (src/bench/yardstick.rs); prints the same line as `bench`. Wall times of `bench` rows are
    /// quoted beside its median, timed the same hour on the same machine.
    Yardstick {
        /// Number of timed runs.
        #[arg(long, default_value_t = 200)]
        runs: usize,
        /// One tab-separated line (columns: see src/bench.rs) instead of the sentence.
        #[arg(long)]
        tsv: bool,
    },
    /// ISO 3888-2: the highest entry speed that clears the course; constant radius: the highest
    /// steady lateral acceleration; for every [sweep] combination. Writes <out>/<name>/envelope.csv
    /// and plots/envelope.png/.svg (spec keys: src/envelope/mod.rs, docs/iso3888-2.md).
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
        /// Tyre provider.
        #[arg(long, value_parser = choice(TyreModelKind::ALL, TyreModelKind::as_str), default_value = "pacejka")]
        tyre_model: TyreModelKind,
        /// Baseline vehicle model.
        #[arg(long, value_parser = choice(VehicleModelKind::ALL, VehicleModelKind::as_str), default_value = "bicycle")]
        model: VehicleModelKind,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Measured runs (RUN.csv, each with an optional RUN.toml sidecar).
        #[arg(required = true)]
        runs: Vec<PathBuf>,
        /// No progress and no summary (progress is shown only on a terminal anyway).
        #[arg(long)]
        quiet: bool,
        /// Also refit the final effects with each fitted run left out and report leave-one-run-out
        /// (jackknife) intervals beside the Jacobian ones (one joint refit per fitted run).
        #[arg(long)]
        jackknife: bool,
        /// Search runs holding more than 200 000 samples in all (refused without it: minutes of work).
        #[arg(long)]
        force: bool,
    },
    /// Generate measured-like runs (CSV + sidecar, seeded sensor noise) from the replay model with one
    /// effect switched on (or `none`).
    Synth {
        /// tyre_relaxation, load_transfer, thermal_friction, friction_change, steer_compliance,
        /// sensor_bias, sensor_latency, accelerometer_position, sensor_scale, clock_skew,
        /// accelerometer_orientation, axle_cornering_stiffness, axle_peak_friction, a vehicle
        /// parameter (yaw_inertia, mass, cg_to_front_axle, cg_to_rear_axle), road (bank_deg,
        /// grade_deg: the same road on every run, not written to the sidecars),
        /// longitudinal_coupling (longitudinal_transfer_height_m; acts where the speed changes,
        /// as in brake_sine_dry and brake_sine_ice) or none; the
        /// --params names pick the form (steer_lag_s: steering lag; stretch_*: a stretch; patch_*:
        /// a ground patch; relaxation_length_front_m: transient slip; load_sensitivity_*).
        #[arg(long)]
        effect: String,
        /// Effect parameters, name=value (repeatable); defaults per effect.
        #[arg(long = "params", num_args = 1..)]
        params: Vec<String>,
        /// With `--effect road` instead of --params: a different road per run, one
        /// bank_deg:grade_deg pair per manoeuvre in the order written (comma-separated, e.g.
        /// `3:4,-2:1,...`); not written to the sidecars.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        roads: Vec<String>,
        /// Vehicle spec file.
        #[arg(long, default_value = "vehicles/sedan.toml")]
        vehicle: PathBuf,
        /// Tyre provider.
        #[arg(long, value_parser = choice(TyreModelKind::ALL, TyreModelKind::as_str), default_value = "pacejka")]
        tyre_model: TyreModelKind,
        /// Noise seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Manoeuvres to write, comma-separated ids (default: the eight of the standard set;
        /// also gentle_sine_dry, gentle_sine_ice, and brake_sine_dry, brake_sine_ice with braking
        /// and driving; a discovery's separating manoeuvre is one).
        #[arg(long, value_delimiter = ',')]
        maneuvers: Vec<String>,
        /// Also log these optional channels, comma-separated: x, y (m), psi (rad, wrapped to
        /// within +-pi), vy (m/s): the replay's own pose and lateral velocity with white noise of
        /// 0.01 m, 5e-4 rad and 0.01 m/s (a survey-grade satellite and inertial system), untouched
        /// by the effect's sensor errors.
        #[arg(long, value_delimiter = ',')]
        log: Vec<String>,
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

/// A flag value parser for a spec choice, spelled as in spec files (`all` in declaration order,
/// `name` its spelling): `--help` lists the values and a wrong one is refused by name.
fn choice<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    name: fn(T) -> &'static str,
) -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(all.iter().map(|&k| PossibleValue::new(name(k))))
        .map(move |s| all.iter().copied().find(|&k| name(k) == s).unwrap_or(all[0]))
}

/// Entry point used by the binary: parse, dispatch to the command's function (next to the module it
/// drives), and turn an error into its message and exit code (`report`).
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let code = |done: Result<ExitCode>| done.unwrap_or_else(|e| signals::report(&e));
    match cli.command {
        Command::Validate { files, quiet } => code(batch::cli_validate(&files, quiet)),
        Command::Run { files, out, jobs, shard, quiet, force } => {
            code(batch::cli_run(&files, &batch::RunFlags { out, jobs, shard, quiet, force }))
        }
        Command::Merge { shards, remove_shards } => code(batch::cli_merge(&shards, remove_shards)),
        Command::Plot { folder } => code(plot(&folder)),
        Command::Compare { a, b, tol, default_tol, ignore } => {
            code(crate::compare::cli_compare(&a, &b, &tol, default_tol, &ignore))
        }
        Command::Tyre { file, out } => code(crate::tyre_sweep::cli_tyre(&file, &out)),
        Command::Atiim { file, out } => code(crate::atiim::cli_atiim(&file, &out)),
        Command::Bench { file, runs, model, tyre_model, contact, tsv } => {
            code(crate::bench::cli_bench(&file, &crate::bench::Options { runs, model, tyre_model, contact }, tsv))
        }
        Command::Yardstick { runs, tsv } => crate::bench::cli_yardstick(runs, tsv),
        Command::Envelope { file, out, jobs } => code(crate::envelope::cli_envelope(&file, &out, jobs)),
        Command::Discover { vehicle, tyre, tyre_model, model, out, runs, quiet, jackknife, force } => {
            crate::discover::cli_discover(vehicle, tyre, tyre_model, model, out, runs, quiet, jackknife, force)
        }
        Command::Synth { effect, params, roads, vehicle, tyre_model, seed, maneuvers, log, out } => {
            let opts = crate::discover::SynthOptions {
                params: &params,
                roads: &roads,
                seed,
                maneuvers: &maneuvers,
                log: &log,
            };
            crate::discover::cli_synth(&effect, &opts, &vehicle, tyre_model, &out)
        }
        Command::ConvertStanford { dir, out, segment_s, segments } => {
            crate::discover::cli_convert(&dir, &out, segment_s, segments)
        }
    }
}

/// `vehsim plot`: draw the charts of a results folder and print each file written.
fn plot(folder: &Path) -> Result<ExitCode> {
    for p in crate::plot::runs::plot_results(folder, folder)? {
        println!("{}.png, .svg", p.display());
    }
    Ok(ExitCode::SUCCESS)
}
