//! The discrepancy workflow (`vehsim discover`, `vehsim synth`): replay measured runs through a
//! baseline model, find where simulation and measurement disagree, name the missing effect from a
//! library of candidates, fit it, and show the gap shrink on held-out data.
//!
//! - [`measured`]: the measured-run format and its validation.
//! - [`model`]: the replay model (lateral bicycle, prescribed speed) with the candidate effects.
//! - [`effects`]: the candidate library; [`fit`]: Nelder–Mead fitting.
//! - [`select`]: noise estimate, residuals, scores, disagreement windows, the result types.
//! - [`search`]: the greedy search that names effects, round by round.
//! - [`synth`]: synthetic runs with one effect on; [`report`]: report.json, report.md, plots.
//! - [`uncertainty`]: confidence intervals of fitted parameters.
//! - [`sensors`]: the measurement chain (accelerometer position, channel latency).
//! - [`equivalence`]: what the data cannot tell apart, and the manoeuvre that would.
//! - [`stanford`]: conversion of the Stanford lap data to the run format.

pub mod coupling;
pub mod effects;
pub mod equivalence;
pub mod fit;
pub mod increments;
pub mod measured;
pub mod model;
pub mod region_starts;
pub mod replay;
pub mod report;
pub mod road_per_run;
pub mod search;
pub mod select;
pub mod sensors;
pub mod stanford;
pub mod synth;
pub mod uncertainty;
pub mod units;
pub mod vehicle_params;
pub mod why;

use std::path::{Path, PathBuf};

use vehsim_core::error::{Error, Result};
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::vehicle::Vehicle;
use vehsim_core::vehicle::VehicleModelKind;
use vehsim_spec::VehicleFile;

pub use effects::Effect;
pub use search::discover;
pub use select::{Dataset, Discovery};

/// Options of `vehsim discover`.
#[derive(Debug, Clone)]
pub struct DiscoverOptions {
    pub vehicle: PathBuf,
    /// Tyre file overriding the vehicle's.
    pub tyre: Option<PathBuf>,
    /// Tyre provider (default pacejka).
    pub tyre_model: TyreModelKind,
    /// The baseline vehicle model (default bicycle).
    pub model: VehicleModelKind,
    pub out: PathBuf,
    pub runs: Vec<PathBuf>,
    /// Print progress (per round and candidate) on stderr.
    pub progress: bool,
    /// Add leave-one-run-out (jackknife) intervals of the final effects ([`select::jackknife`]).
    pub jackknife: bool,
}

/// Load the vehicle (with an optional tyre override) for provider `kind`.
pub fn load_vehicle(path: &Path, tyre: Option<&Path>, kind: TyreModelKind) -> Result<Vehicle> {
    let mut vf = VehicleFile::load(path)?;
    if let Some(t) = tyre {
        let abs = std::fs::canonicalize(t).map_err(|_| Error::input(t, "tyre file not found"))?;
        vf.tyre = abs.to_string_lossy().to_string();
    }
    vf.build(path, kind)
}

/// Parse a tyre-provider name.
pub fn tyre_kind(name: &str) -> Result<TyreModelKind> {
    TyreModelKind::parse(name).ok_or_else(|| {
        Error::usage("--tyre-model", format!("'{name}' is not a tyre provider; allowed: {}", TyreModelKind::allowed()))
    })
}

/// Parse a baseline vehicle-model name.
pub fn model_kind(name: &str) -> Result<VehicleModelKind> {
    VehicleModelKind::parse(name).ok_or_else(|| {
        Error::usage("--model", format!("'{name}' is not a model; allowed: {}", VehicleModelKind::allowed()))
    })
}

/// The baseline parameters and the candidates for a baseline vehicle model.
pub fn baseline_for(model: VehicleModelKind, vehicle: &Vehicle) -> (model::EffectParams, Vec<Effect>) {
    match model {
        VehicleModelKind::Bicycle => (model::EffectParams::of_vehicle(vehicle), Effect::TRIED.to_vec()),
        // The 4-DOF baseline: quasi-static lateral load transfer at the vehicle's CG height.
        VehicleModelKind::Roll4Dof => {
            let p = model::EffectParams {
                load_transfer_height_m: vehicle.cg_height_m,
                ..model::EffectParams::of_vehicle(vehicle)
            };
            (p, Effect::TRIED.iter().copied().filter(|e| e.name() != Effect::LoadTransfer.name()).collect())
        }
    }
}

/// Most samples (summed over the runs) `vehsim discover` replays without `--force`: the search
/// costs about 1 ms of one core per sample (8 synthetic runs of 12 s at 100 Hz, 9 600 samples,
/// take 10 s), so this is a few minutes.
pub const MAX_SAMPLES: usize = 200_000;

/// Run `vehsim discover`: read and validate everything, discover, write the output folder.
/// Returns the discovery and the notices to print. No work limit (see [`run_discover_checked`]).
pub fn run_discover(opts: &DiscoverOptions) -> Result<(Discovery, Vec<String>)> {
    run_discover_checked(opts, true)
}

/// As [`run_discover`]; unless `force`, runs holding more than [`MAX_SAMPLES`] samples in all
/// are refused (bad input, exit 2) with the estimate, before any search.
pub fn run_discover_checked(opts: &DiscoverOptions, force: bool) -> Result<(Discovery, Vec<String>)> {
    let vehicle = load_vehicle(&opts.vehicle, opts.tyre.as_deref(), opts.tyre_model)?;
    let (base, candidates) = baseline_for(opts.model, &vehicle);
    if opts.runs.is_empty() {
        return Err(Error::input(Path::new("RUN.csv"), "no measured run given"));
    }
    let mut runs = Vec::new();
    let mut notices = Vec::new();
    for p in &opts.runs {
        let r = measured::read_run(p)?;
        notices.extend(r.notices.iter().cloned());
        runs.push(r);
    }
    let samples: usize = runs.iter().map(|r| r.t.len()).sum();
    if !force && samples > MAX_SAMPLES {
        return Err(Error::input(
            &opts.runs[0],
            format!(
                "{} runs hold {samples} samples, above the {MAX_SAMPLES} discover replays without --force (about \
                 {:.0} min of search at 1 ms per sample); resample the runs (100 Hz is plenty), give fewer, or \
                 use --force",
                runs.len(),
                samples as f64 * 1e-3 / 60.0
            ),
        ));
    }
    let model = model::ReplayModel::new(vehicle);
    let mut data = Dataset::new(runs);
    let say = |m: &str| eprintln!("discover: {m}");
    let mut d = search::discover_with(&model, &data, base, &candidates, opts.progress.then_some(&say as _));
    data.held = d.held.clone();
    if let Some(roads) = d.run_roads() {
        // Each run on its own fitted road from here on (the jackknife, the report's replays).
        data = road_per_run::with_roads(&data, roads);
    }
    if opts.jackknife {
        let finals: Vec<(Effect, Vec<f64>)> =
            d.final_effects.iter().map(|fe| (fe.effect, fe.params.iter().map(|p| p.1).collect())).collect();
        if opts.progress {
            say("jackknife: refitting the final effects with each fitted run left out");
        }
        d.jackknife = select::jackknife(&model, &data, &base, &finals);
    }
    report::write_all(&opts.out, opts, &model, &data, &d)?;
    Ok((d, notices))
}

fn fail(e: &Error) -> std::process::ExitCode {
    eprintln!("error: {e}");
    std::process::ExitCode::from(e.exit_code())
}

/// `vehsim discover` (called by the CLI): prints notices, the verdict and the RMS table.
#[allow(clippy::too_many_arguments)]
pub fn cli_discover(
    vehicle: PathBuf,
    tyre: Option<PathBuf>,
    tyre_model: TyreModelKind,
    model: VehicleModelKind,
    out: PathBuf,
    runs: Vec<PathBuf>,
    quiet: bool,
    jackknife: bool,
    force: bool,
) -> std::process::ExitCode {
    use std::io::IsTerminal as _;
    let progress = !quiet && std::io::stderr().is_terminal();
    let opts = DiscoverOptions { vehicle, tyre, tyre_model, model, out, runs, progress, jackknife };
    match run_discover_checked(&opts, force) {
        Ok(_) if quiet => std::process::ExitCode::SUCCESS,
        Ok((d, notices)) => {
            for n in notices {
                println!("note: {n}");
            }
            for st in &d.steps {
                let ps = report::params_text(&st.params, &st.intervals);
                println!("accepted {}: {ps} ({})", st.effect.label(), st.evidence);
            }
            for x in &d.dropped {
                println!("dropped {} (round {}): {}", x.effect.label(), x.dropped_round, x.reason);
            }
            for (i, f) in d.folds.iter().enumerate() {
                let [b, a] = [f.baseline_noise_ratio, f.final_noise_ratio];
                println!(
                    "fold {}: held-out RMS / noise (yaw rate, ay) {:.2}, {:.2} -> {:.2}, {:.2}",
                    i + 1,
                    b[0],
                    b[1],
                    a[0],
                    a[1]
                );
                let inc: Vec<String> = increments::CHANNELS
                    .iter()
                    .zip(f.baseline_increment_noise_ratio.iter().zip(&f.final_increment_noise_ratio))
                    .filter_map(|(name, r)| match r {
                        (Some(b), Some(a)) => Some(format!("{} {b:.2} -> {a:.2}", name.replace('_', " "))),
                        _ => None,
                    })
                    .collect();
                if !inc.is_empty() {
                    println!("        increments over {} s windows: {}", increments::WINDOW_S, inc.join(", "));
                }
            }
            let (b, f) = (d.baseline.rmse(true), d.final_scores.rmse(true));
            println!(
                "held-out RMS: yaw rate {:.5} -> {:.5} rad/s, ay {:.4} -> {:.4} m/s^2",
                b.yaw_rate_radps, f.yaw_rate_radps, b.ay_mps2, f.ay_mps2
            );
            println!("verdict: {} (named: {})", d.verdict, d.named_text());
            for line in report::classes_text(&d) {
                println!("{line}");
            }
            println!("wrote {}", opts.out.display());
            std::process::ExitCode::SUCCESS
        }
        Err(e) => fail(&e),
    }
}

/// The options of `vehsim synth` besides the effect, the vehicle and the output folder.
#[derive(Debug, Clone, Copy)]
pub struct SynthOptions<'a> {
    /// `--params`: the effect's parameters, name=value.
    pub params: &'a [String],
    /// `--roads`: one bank_deg:grade_deg pair per manoeuvre (with `--effect road` only).
    pub roads: &'a [String],
    /// `--seed`: the noise seed.
    pub seed: u64,
    /// `--maneuvers`: the manoeuvre ids (empty: the standard set).
    pub maneuvers: &'a [String],
    /// `--log`: optional channels to log as well ([`synth::LOGGABLE`]).
    pub log: &'a [String],
}

/// `vehsim synth` (called by the CLI).
pub fn cli_synth(
    effect: &str,
    opts: &SynthOptions,
    vehicle: &Path,
    tyre_model: TyreModelKind,
    out: &Path,
) -> std::process::ExitCode {
    let (params, seed, maneuvers) = (opts.params, opts.seed, opts.maneuvers);
    let r = (|| -> Result<usize> {
        let plan = synth::select(maneuvers)?;
        let log = synth::parse_log(opts.log)?;
        if !opts.roads.is_empty() {
            if effect != "road" || !params.is_empty() {
                return Err(Error::usage(
                    "--roads",
                    format!(
                        "per-run roads go with --effect road and no --params (given: --effect {effect}{})",
                        if params.is_empty() { "" } else { " with --params" }
                    ),
                ));
            }
            let roads = synth::parse_roads(opts.roads, &plan)?;
            let v = load_vehicle(vehicle, None, tyre_model)?;
            let p = model::EffectParams::default();
            let runs = synth::generate_plan_roads(&model::ReplayModel::new(v), &p, seed, &plan, &roads, &log);
            synth::write_runs(out, &runs)?;
            return Ok(runs.len());
        }
        let v = load_vehicle(vehicle, None, tyre_model)?;
        let mut p = model::EffectParams::default();
        if effect != "none" {
            let given: Vec<&str> = params.iter().map(|g| g.split_once('=').map_or(g.as_str(), |(k, _)| k)).collect();
            let e = match Effect::from_name(effect) {
                None => {
                    return Err(Error::usage(
                        "--effect",
                        format!("'{effect}' is not an effect; allowed: none, {}", Effect::names().join(", ")),
                    ))
                }
                Some(_) => Effect::from_name_and_params(effect, &given).ok_or_else(|| {
                    let names: Vec<&str> = Effect::ALL
                        .iter()
                        .filter(|e| e.name() == effect)
                        .flat_map(|e| e.params().iter().map(|d| d.name))
                        .collect();
                    Error::usage(
                        "--params",
                        format!(
                            "no form of {effect} has all of {}; its parameters: {} (one form at a time)",
                            given.join(", "),
                            names.join(", ")
                        ),
                    )
                })?,
            };
            let vals = synth::parse_params(e, params)?;
            e.apply(&mut p, &vals);
            if let Some(road) = p.road {
                // A grade the tyres of a manoeuvre's surface cannot climb at a held speed.
                for m in &plan {
                    if let Some(why) = road.too_steep(m.mu) {
                        return Err(Error::usage("--params", format!("on {} (mu {}): {why}", m.id, m.mu)));
                    }
                }
            }
        } else if !params.is_empty() {
            return Err(Error::usage("--params", "effect 'none' takes no parameters"));
        }
        let runs = synth::generate_plan_logging(&model::ReplayModel::new(v), &p, seed, &plan, &log);
        synth::write_runs(out, &runs)?;
        Ok(runs.len())
    })();
    match r {
        Ok(n) => {
            println!("wrote {n} runs into {}", out.display());
            std::process::ExitCode::SUCCESS
        }
        Err(e) => fail(&e),
    }
}

/// `vehsim convert-stanford` (called by the CLI).
pub fn cli_convert(dir: &Path, out: &Path, segment_s: f64, segments: usize) -> std::process::ExitCode {
    match stanford::convert(dir, out, segment_s, segments) {
        Ok(files) => {
            println!("wrote {} runs into {}", files.len(), out.display());
            std::process::ExitCode::SUCCESS
        }
        Err(e) => fail(&e),
    }
}
