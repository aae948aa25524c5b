//! Command-line interface: parse arguments, validate every input before anything runs, call the
//! library, print results, and map errors to exit codes (0 success, 1 a run failed, 2 bad input).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand};
use rayon::prelude::*;

use crate::error::Error;
use crate::run;

#[derive(Debug, Parser)]
#[command(name = "vehsim", version, about = "Vehicle-dynamics simulation for driving on ice")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run manoeuvre specs and write results/<name>/timeseries.csv and summary.json.
    Run {
        /// Manoeuvre spec files (TOML).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Folder for the results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Print nothing but errors.
        #[arg(long)]
        quiet: bool,
    },
    /// Check manoeuvre specs (and the vehicle and tyre files they name); run nothing.
    Validate {
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Time repeated runs of one spec (simulation only, no output files); prints median and min.
    Bench {
        file: PathBuf,
        /// Number of timed runs.
        #[arg(long, default_value_t = 200)]
        runs: usize,
    },
}

fn report(e: &Error) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(e.exit_code())
}

/// Entry point used by the binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Validate { files } => {
            let mut code = ExitCode::SUCCESS;
            for f in &files {
                match run::load(f) {
                    Ok(cfg) => println!(
                        "{}: ok ({} with {} on {}, tyre model {}, vehicle model {})",
                        f.display(),
                        cfg.kind,
                        cfg.vehicle.name,
                        cfg.env.mu,
                        cfg.tyre_model.as_str(),
                        cfg.vehicle_model.as_str()
                    ),
                    Err(e) => code = report(&e),
                }
            }
            code
        }
        Command::Run { files, out, quiet } => {
            let mut configs = Vec::new();
            for f in &files {
                match run::load(f) {
                    Ok(c) => configs.push(c),
                    Err(e) => return report(&e),
                }
            }
            let mut names = std::collections::BTreeSet::new();
            for c in &configs {
                if !names.insert(c.name.clone()) {
                    return report(&Error::key(
                        &c.spec_file,
                        "name",
                        format!(
                            "'{}' is used by more than one spec in this call; results would overwrite each other",
                            c.name
                        ),
                    ));
                }
            }
            let outputs: Vec<_> = configs.par_iter().map(run::execute).collect();
            let mut code = ExitCode::SUCCESS;
            for (cfg, o) in configs.iter().zip(&outputs) {
                let dir = match run::write_results(&out, cfg, o) {
                    Ok(d) => d,
                    Err(e) => return report(&e),
                };
                let s = &o.summary;
                if s.failed() {
                    code = ExitCode::from(1);
                }
                if !quiet || s.failed() {
                    let verdict = match s.passed {
                        Some(true) => "passed".to_string(),
                        Some(false) => format!("FAILED ({} cone boundaries hit)", s.cones_hit),
                        None => "no pass rule".to_string(),
                    };
                    println!(
                        "{}: {} at t = {:.2} s, {}; peak yaw rate {:.3} rad/s, peak sideslip {:.2} deg, peak ay {:.2} m/s^2 -> {}",
                        cfg.name,
                        s.end_reason,
                        s.end_time_s,
                        verdict,
                        s.peak_yaw_rate_radps,
                        s.peak_sideslip_rad.to_degrees(),
                        s.peak_ay_mps2,
                        dir.display()
                    );
                }
            }
            code
        }
        Command::Bench { file, runs } => {
            let cfg = match run::load(&file) {
                Ok(c) => c,
                Err(e) => return report(&e),
            };
            let runs = runs.max(1);
            let _ = run::execute(&cfg);
            let mut times: Vec<f64> = (0..runs)
                .map(|_| {
                    let t0 = Instant::now();
                    let o = run::execute(&cfg);
                    std::hint::black_box(&o);
                    t0.elapsed().as_secs_f64()
                })
                .collect();
            times.sort_by(|a, b| a.total_cmp(b));
            let o = run::execute(&cfg);
            let sim_s = o.summary.end_time_s;
            let med = times[times.len() / 2];
            println!(
                "{}: {} runs of {:.2} s simulated ({} steps): median {:.3} ms, min {:.3} ms, real-time factor {:.0}",
                cfg.name,
                runs,
                sim_s,
                o.summary.steps,
                med * 1e3,
                times[0] * 1e3,
                sim_s / med
            );
            ExitCode::SUCCESS
        }
    }
}
