//! `vehsim bench`: time repeated runs of one manoeuvre spec (simulation only, no output files).
//!
//! The spec may be overridden before it is validated, so one spec file serves every vehicle model
//! and tyre provider: `--model bicycle|roll4dof` sets `vehicle_model`, `--tyre-model NAME` sets
//! `tyre_model`, `--contact isothermal|atiim` sets `[contact] model`. The run is simulated once
//! untimed (warm-up: page faults, caches, the ATIIM table cache), then `runs` times timed one by one
//! with a monotonic clock; the figures are the median and the minimum of those wall times.
//!
//! Output, one line, always in this form (numbers in fixed formats):
//!
//! ```text
//! NAME: MODEL + TYRE, contact CONTACT: RUNS runs of SIM s simulated (STEPS steps): median MED ms, min MIN ms, real-time factor RTF, peak memory MEM MiB
//! ```
//!
//! or with `--tsv` one tab-separated line with the columns of [`TSV_HEADER`] (no header line).
//! The real-time factor is simulated time over the median wall time. Peak memory is the process's
//! resident high-water mark (`VmHWM` in `/proc/self/status`, Linux only; `-` where unavailable);
//! each invocation is its own process, so it is the peak of this benchmark alone (the binary, the
//! spec, the vehicle, and one run's recorder and tables).
//!
//! `vehsim yardstick [--runs N] [--tsv]` times the naive single-track RK4 run of [`yardstick`]
//! the same way and prints the same line (name `yardstick`, model `single_track_rk4_1ms`, tyre
//! `simple_mf`, contact `-`): the wall-time unit beside which the README's medians are quoted.

use std::path::Path;
use std::time::Instant;

use vehsim_core::error::Result;
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::vehicle::VehicleModelKind;
use vehsim_spec::contact::ContactModelKind;
use vehsim_spec::run;
use vehsim_spec::ManeuverFile;

pub mod yardstick;

/// Column names of the `--tsv` line (documentation; the test below holds [`Report::tsv`] to it).
#[cfg_attr(not(test), allow(dead_code))]
pub const TSV_HEADER: &str =
    "name\tmodel\ttyre\tcontact\truns\tsim_s\tsteps\tmedian_ms\tmin_ms\trealtime_factor\tpeak_mem_kib";

/// What to run and how often.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Timed runs (at least 1).
    pub runs: usize,
    /// Vehicle model override.
    pub model: Option<VehicleModelKind>,
    /// Tyre provider override.
    pub tyre_model: Option<TyreModelKind>,
    /// Contact-temperature model override.
    pub contact: Option<ContactModelKind>,
}

/// Figures of one benchmark.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub name: String,
    pub model: &'static str,
    pub tyre: &'static str,
    pub contact: &'static str,
    pub runs: usize,
    /// Simulated time of one run, s.
    pub sim_s: f64,
    pub steps: u64,
    /// Median and minimum wall time per run, s.
    pub median_s: f64,
    pub min_s: f64,
    /// Resident-set high-water mark of the process, KiB (None off Linux).
    pub peak_mem_kib: Option<u64>,
}

impl Report {
    /// Simulated time over median wall time.
    pub fn realtime_factor(&self) -> f64 {
        self.sim_s / self.median_s
    }

    /// The one-line human-readable form (see the module docs).
    pub fn line(&self) -> String {
        format!(
            "{}: {} + {}, contact {}: {} runs of {:.2} s simulated ({} steps): median {:.3} ms, min {:.3} ms, \
             real-time factor {:.0}, peak memory {} MiB",
            self.name,
            self.model,
            self.tyre,
            self.contact,
            self.runs,
            self.sim_s,
            self.steps,
            self.median_s * 1e3,
            self.min_s * 1e3,
            self.realtime_factor(),
            self.peak_mem_kib.map_or("-".to_string(), |k| format!("{:.1}", k as f64 / 1024.0)),
        )
    }

    /// The tab-separated form (columns of [`TSV_HEADER`]).
    pub fn tsv(&self) -> String {
        format!(
            "{}\t{}\t{}\t{}\t{}\t{:.3}\t{}\t{:.4}\t{:.4}\t{:.1}\t{}",
            self.name,
            self.model,
            self.tyre,
            self.contact,
            self.runs,
            self.sim_s,
            self.steps,
            self.median_s * 1e3,
            self.min_s * 1e3,
            self.realtime_factor(),
            self.peak_mem_kib.map_or("-".to_string(), |k| k.to_string()),
        )
    }
}

/// Resident-set high-water mark of this process, KiB (`VmHWM` of `/proc/self/status`).
pub fn peak_memory_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Load `file`, apply the overrides, validate, and time `opts.runs` runs.
pub fn bench(file: &Path, opts: &Options) -> Result<Report> {
    let mut spec = ManeuverFile::load(file)?;
    // The raw spec holds names; the overrides are written as the spec file would spell them.
    if let Some(m) = opts.model {
        spec.vehicle_model = Some(m.as_str().into());
    }
    if let Some(t) = opts.tyre_model {
        spec.tyre_model = t.as_str().into();
    }
    if let Some(c) = opts.contact {
        spec.contact.model = c.as_str().into();
    }
    let cfg = spec.build(file)?;
    let runs = opts.runs.max(1);
    // Warm-up, untimed; its summary gives the simulated time and steps (runs are deterministic).
    let first = run::execute(&cfg);
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t0 = Instant::now();
            let o = run::execute(&cfg);
            std::hint::black_box(&o);
            t0.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(|a, b| a.total_cmp(b));
    Ok(Report {
        name: cfg.name.clone(),
        model: cfg.vehicle_model.as_str(),
        tyre: cfg.tyre_model.as_str(),
        contact: cfg.contact.kind(file)?.as_str(),
        runs,
        sim_s: first.summary.end_time_s,
        steps: first.summary.steps,
        median_s: times[times.len() / 2],
        min_s: times[0],
        peak_mem_kib: peak_memory_kib(),
    })
}

/// Median and minimum of `runs` timed calls of `f` (after one untimed call), s.
fn time_runs<R>(runs: usize, mut f: impl FnMut() -> R) -> (f64, f64) {
    std::hint::black_box(f());
    let mut times: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let t0 = Instant::now();
            std::hint::black_box(f());
            t0.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(|a, b| a.total_cmp(b));
    (times[times.len() / 2], times[0])
}

/// Time `runs` runs of the [`yardstick`].
pub fn yardstick_bench(runs: usize) -> Report {
    let (median_s, min_s) = time_runs(runs, yardstick::run);
    Report {
        name: "yardstick".into(),
        model: "single_track_rk4_1ms",
        tyre: "simple_mf",
        contact: "-",
        runs: runs.max(1),
        sim_s: yardstick::DURATION_S,
        steps: yardstick::STEPS as u64,
        median_s,
        min_s,
        peak_mem_kib: peak_memory_kib(),
    }
}

/// `vehsim yardstick`: time the yardstick and print the sentence (or the `--tsv` line).
pub(crate) fn cli_yardstick(runs: usize, tsv: bool) -> std::process::ExitCode {
    let r = yardstick_bench(runs);
    println!("{}", if tsv { r.tsv() } else { r.line() });
    std::process::ExitCode::SUCCESS
}

/// `vehsim bench`: time the runs and print the sentence (or the `--tsv` line).
pub(crate) fn cli_bench(file: &Path, opts: &Options, tsv: bool) -> Result<std::process::ExitCode> {
    let r = bench(file, opts)?;
    println!("{}", if tsv { r.tsv() } else { r.line() });
    Ok(std::process::ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `--tsv` line has one field per column of [`TSV_HEADER`], in its order of kinds.
    #[test]
    fn tsv_line_matches_the_header() {
        let r = Report {
            name: "n".into(),
            model: "bicycle",
            tyre: "linear",
            contact: "isothermal",
            runs: 3,
            sim_s: 2.0,
            steps: 400,
            median_s: 0.004,
            min_s: 0.003,
            peak_mem_kib: None,
        };
        let line = r.tsv();
        let fields: Vec<&str> = line.split('\t').collect();
        assert_eq!(fields.len(), TSV_HEADER.split('\t').count(), "{line}");
        assert_eq!(
            fields,
            ["n", "bicycle", "linear", "isothermal", "3", "2.000", "400", "4.0000", "3.0000", "500.0", "-"]
        );
    }
}
