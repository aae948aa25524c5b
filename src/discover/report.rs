//! Outputs of `vehsim discover`: `report.json`, `report.md`, `effects.toml` (the accepted effects
//! with their fitted parameters), `vehicle.toml` (the vehicle spec with the vehicle effects in its
//! `[lateral]` section and the instrument effects in its `[sensors]` section, runnable with
//! `vehsim run`), `surface.toml` (a named friction region, for the runs' sidecars) and per-run
//! plots (yaw rate and ay: measured, baseline and improved, disagreement windows of the baseline
//! shaded). Written atomically into the output folder.

use std::fmt::Write as _;
use std::path::Path;

use serde_json::json;

use super::effects::{Effect, InVehicleSpec};
use super::equivalence::Class;
use super::model::{ReplayModel, Simulated};
use super::select::{disagreement_windows, operating_regions, simulate_all, Dataset, Discovery, Rmse, Window};
use super::uncertainty::Interval;
use super::DiscoverOptions;
use crate::plot::{xy_chart, Series, XyChart};
use vehsim_core::error::{Error, Result};

fn rmse_json(r: &Rmse) -> serde_json::Value {
    json!({ "yaw_rate_radps": r.yaw_rate_radps, "ay_mps2": r.ay_mps2 })
}

/// Parameters as {name, value, unit}, with the 95 % interval and standard error beside when known
/// (null when the data do not determine the parameter).
fn params_json(ps: &[(String, f64, String)], iv: &[Interval]) -> Vec<serde_json::Value> {
    let fin = |x: f64| if x.is_finite() { json!(x) } else { serde_json::Value::Null };
    ps.iter()
        .enumerate()
        .map(|(i, (k, v, u))| match iv.get(i) {
            Some(c) => json!({"name": k, "value": v, "unit": u, "std_error": fin(c.std_error), "ci95_lo": fin(c.lo), "ci95_hi": fin(c.hi)}),
            None => json!({"name": k, "value": v, "unit": u}),
        })
        .collect()
}

/// `name = value unit [lo, hi]` for the terminal and report.md.
pub fn params_text(ps: &[(String, f64, String)], iv: &[Interval]) -> String {
    let v: Vec<String> = ps
        .iter()
        .enumerate()
        .map(|(i, (k, v, u))| match iv.get(i) {
            Some(c) => format!("{k} = {v:.4e} {u} (95 %: {:.3e} to {:.3e})", c.lo, c.hi),
            None => format!("{k} = {v:.4e} {u}"),
        })
        .collect();
    v.join(", ")
}

/// The largest remaining disagreement windows (by excess times duration), at most `n`.
pub fn largest_windows(windows: &[Window], n: usize) -> Vec<Window> {
    let mut w = windows.to_vec();
    let weight = |x: &Window| x.excess * (x.t1_s - x.t0_s);
    w.sort_by(|a, b| weight(b).total_cmp(&weight(a)).then(a.run.cmp(&b.run)).then(a.t0_s.total_cmp(&b.t0_s)));
    w.truncate(n);
    w
}

/// The accepted effects and their parameters as a TOML document.
pub fn effects_toml(opts: &DiscoverOptions, d: &Discovery) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Effects accepted by `vehsim discover` (baseline model '{}').", opts.model);
    let _ = writeln!(s, "# Vehicle: {}", opts.vehicle.display());
    let _ = writeln!(s, "verdict = \"{}\"", d.verdict);
    let _ = writeln!(s, "named_effects = {:?}", d.named_names());
    for c in &d.classes {
        let _ = writeln!(s, "# {} cannot be told apart on these runs: {}", c.named.label(), c.text());
    }
    // Final values (after any joint refit; see report.json `steps` for the values at acceptance).
    for fe in &d.final_effects {
        let _ = writeln!(s, "\n[{}]", fe.effect.name());
        if !fe.effect.form().is_empty() {
            let _ = writeln!(s, "form = \"{}\"", fe.effect.form());
        }
        for ((k, v, u), iv) in fe.params.iter().zip(&fe.intervals) {
            let _ = writeln!(s, "{k} = {v:e}  # {u}; 95 % interval [{:e}, {:e}]", iv.lo, iv.hi);
        }
    }
    s
}

/// The vehicle spec with the accepted vehicle effects in its `[lateral]` section (the engine's
/// bicycle model runs them; the tread state only `vehsim discover`'s replay) and the instrument
/// effects in its `[sensors]` section (`vehsim run` logs the measured channels through them),
/// merged into the sections the baseline spec already has; the tyre path made absolute, so that
/// `vehsim run` can use it from any folder. A friction change placed on the road is not the
/// vehicle's: it goes to surface.toml ([`surface_toml`]), and the header says so.
pub fn improved_vehicle_toml(opts: &DiscoverOptions, d: &Discovery) -> Result<String> {
    let path = &opts.vehicle;
    let text = vehsim_spec::files::read_input(path)?;
    let mut table: toml::Table = toml::from_str(&text).map_err(|e| Error::input(path, e.to_string()))?;
    let tyre = match &opts.tyre {
        Some(t) => t.clone(),
        None => vehsim_spec::files::resolve(path, table.get("tyre").and_then(|t| t.as_str()).unwrap_or("")),
    };
    let tyre_abs = std::fs::canonicalize(&tyre).unwrap_or(tyre);
    table.insert("tyre".into(), toml::Value::String(tyre_abs.to_string_lossy().to_string()));
    let section = |t: &toml::Table, name: &str| t.get(name).and_then(|v| v.as_table()).cloned().unwrap_or_default();
    let (mut lateral, mut sensors) = (section(&table, "lateral"), section(&table, "sensors"));
    let mut road = Vec::new();
    let mut body = Vec::new();
    // The effects still named at the end (a dropped one has a step but no final effect).
    for st in &d.final_effects {
        let effect = st.effect;
        let into = match effect.in_vehicle_spec() {
            InVehicleSpec::Lateral => &mut lateral,
            InVehicleSpec::Instruments => &mut sensors,
            InVehicleSpec::Body => {
                if let (Effect::VehicleParam(i), Some(p)) = (effect, st.params.first()) {
                    body.push((super::vehicle_params::TABLE[i].bound.key, p.1));
                }
                continue;
            }
            InVehicleSpec::Road | InVehicleSpec::RoadGeometry => {
                road.push(effect.label());
                continue;
            }
        };
        for (key, value, _) in &st.params {
            into.insert(key.clone(), toml::Value::Float(*value));
        }
        if matches!(effect, Effect::TransientSlip | Effect::TransientSlipSaturating) {
            let saturating = effect == Effect::TransientSlipSaturating;
            lateral.insert("slip_relaxation_saturating".into(), toml::Value::Boolean(saturating));
        }
    }
    for (name, t) in [("lateral", lateral), ("sensors", sensors)] {
        if !t.is_empty() {
            table.insert(name.into(), toml::Value::Table(t));
        }
    }
    // A vehicle parameter's key set to its fitted value: the spec's times the factor.
    for (key, f) in body {
        if let Some(x) = table.get(key).and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64))) {
            table.insert(key.into(), toml::Value::Float(x * f));
        }
    }
    let body = toml::to_string(&table).map_err(|e| Error::Run(e.to_string()))?;
    let mut s = format!(
        "# {} with the effects accepted by `vehsim discover` (verdict: {}; named: {}).\n",
        path.display(),
        d.verdict,
        d.named_text()
    );
    if !road.is_empty() {
        s.push_str(&format!(
            "# Not vehicle properties (the road's), so in surface.toml, not in this spec: {}.\n",
            road.join(", ")
        ));
    }
    if d.params.thermal_mu_per_k != 0.0 {
        s.push_str("# thermal_mu_per_k acts only in manoeuvres with [contact] model = \"atiim\".\n");
    }
    if d.params.tread() {
        s.push_str("# The tread state (tread_*) is the run's contact-temperature estimate: vehsim run needs [contact] model = \"isothermal\" (the default).\n");
    }
    s.push_str(&body);
    Ok(s)
}

/// The friction regions named on the road (the `friction_change` forms placed on the ground or
/// along the path) as a sidecar `[surface]` fragment: `[[surface.patch]]`, `[[surface.band]]` or
/// `[[surface.stretch]]`, keys as [`super::effects::region_key`] names them. Added to a run's
/// sidecar (RUN.toml), it makes the region part of that run's baseline. None when no region was
/// named.
pub fn surface_toml(d: &Discovery) -> Option<String> {
    let mut s = String::from(
        "# Friction regions named by `vehsim discover`, each in a run's own ground frame (its logged pose, else\n\
         # the origin heading +X at its first sample; a stretch in distance travelled from it). Add these tables\n\
         # to a run's sidecar RUN.toml to replay them as part of its baseline.\n",
    );
    let mut any = false;
    for fe in d.final_effects.iter().filter(|fe| fe.effect.in_vehicle_spec() == InVehicleSpec::RoadGeometry) {
        // The road's bank and grade: the sidecar's `[road]`, keys named as the parameters.
        let _ = writeln!(s, "\n# The road's bank and grade, fitted as one pair for every run of the set.\n[road]");
        for (k, v, _) in &fe.params {
            let _ = writeln!(s, "{k} = {}", toml::Value::Float(*v));
        }
        any = true;
    }
    for fe in d.final_effects.iter().filter(|fe| fe.effect.in_vehicle_spec() == InVehicleSpec::Road) {
        let form = fe.effect.form();
        let _ = writeln!(s, "\n[[surface.{form}]]");
        for (k, v, _) in &fe.params {
            let _ = writeln!(s, "{} = {}", super::effects::region_key(form, k), toml::Value::Float(*v));
        }
        any = true;
    }
    any.then_some(s)
}

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| Error::Io { path: path.to_path_buf(), source: e })
}

/// Write every output into `out` (atomically).
/// Write report.json, report.md, effects.toml, vehicle.toml and the plots into `out`, atomically.
pub fn write_all(out: &Path, opts: &DiscoverOptions, model: &ReplayModel, data: &Dataset, d: &Discovery) -> Result<()> {
    let base_p = super::baseline_for(opts.model, &model.vehicle).0;
    let sims = Sims { base: simulate_all(model, data, &base_p), last: simulate_all(model, data, &d.params) };
    let windows = disagreement_windows(data, &sims.base);
    let windows_after = disagreement_windows(data, &sims.last);
    let regions = operating_regions(data, &sims.base);
    let why = super::why::above_noise(data, d, &sims.last, &windows_after);
    let mut report = report_json(opts, data, d, &sims, [&windows, &windows_after], &regions);
    report["above_noise"] = json!(why);
    let md = markdown(opts, data, d, [&windows, &windows_after], &regions, why.as_ref());
    let toml = effects_toml(opts, d);
    let vehicle_toml = improved_vehicle_toml(opts, d)?;
    let surface = surface_toml(d);
    let roads = d.road_per_run.as_ref().filter(|o| o.roads().is_some()).and_then(|o| o.comparison.as_ref());
    crate::run::write_dir_atomic(out, |tmp| {
        if let Some(c) = roads {
            write(&tmp.join("roads.toml"), &c.roads_toml())?;
        }
        if let Some(s) = &surface {
            write(&tmp.join("surface.toml"), s)?;
        }
        let text = serde_json::to_string_pretty(&report).map_err(|e| Error::Run(e.to_string()))?;
        write(&tmp.join("report.json"), &text)?;
        write(&tmp.join("report.md"), &md)?;
        write(&tmp.join("effects.toml"), &toml)?;
        write(&tmp.join("vehicle.toml"), &vehicle_toml)?;
        write_plots(&tmp.join("plots"), data, &sims, &windows)
    })
}

/// The replays of every run by the baseline and by the final model.
struct Sims {
    base: Vec<Simulated>,
    last: Vec<Simulated>,
}

/// report.json (see docs/discover.md, Outputs); `windows` are the baseline's and the final
/// model's disagreement windows.
fn report_json(
    opts: &DiscoverOptions,
    data: &Dataset,
    d: &Discovery,
    sims: &Sims,
    [windows, windows_after]: [&[Window]; 2],
    regions: &[super::select::RegionBin],
) -> serde_json::Value {
    let (base_sims, final_sims) = (&sims.base, &sims.last);
    json!({
        "baseline_model": opts.model,
        "vehicle": opts.vehicle.display().to_string(),
        "runs": data.runs.iter().map(|r| r.path.display().to_string()).collect::<Vec<_>>(),
        "heldout_runs": data.heldout_runs(),
        "noise": data.runs.iter().zip(&data.noise).map(|(r, n)| {
            let mut j = json!({"run": r.name, "yaw_rate_radps": n.yaw_rate, "ay_mps2": n.ay});
            if let Some(p) = n.increments {
                for (key, v) in [("psi_rad", p.psi_rad), ("position_m", p.position_m), ("vy_mps", p.vy_mps)] {
                    if let Some(v) = v {
                        j[key] = json!(v);
                    }
                }
            }
            j
        }).collect::<Vec<_>>(),
        "baseline_rmse": { "fitted": rmse_json(&d.baseline.rmse(false)), "heldout": rmse_json(&d.baseline.rmse(true)) },
        "final_rmse": { "fitted": rmse_json(&d.final_scores.rmse(false)), "heldout": rmse_json(&d.final_scores.rmse(true)) },
        "steps": d.steps.iter().map(|s| json!({
            "effect": s.effect.name(), "form": s.effect.form(),
            "params": params_json(&s.params, &s.intervals),
            "rmse_before": rmse_json(&s.rmse_before),
            "rmse_after": rmse_json(&s.rmse_after),
            "heldout_rmse_before": rmse_json(&s.heldout_rmse_before),
            "heldout_rmse_after": rmse_json(&s.heldout_rmse_after),
            "evidence": s.evidence,
        })).collect::<Vec<_>>(),
        "rejected": d.rejected.iter().map(|t| json!({
            "effect": t.effect.name(), "form": t.effect.form(), "round": t.round, "delta_bic": t.delta_bic,
            "heldout_rss_ratio": t.heldout_rss_ratio,
            "params": params_json(&t.params, &t.intervals),
            "reason": t.reason,
        })).collect::<Vec<_>>(),
        "dropped": d.dropped.iter().map(|x| json!({
            "effect": x.effect.name(), "form": x.effect.form(),
            "accepted_round": x.accepted_round, "dropped_round": x.dropped_round,
            "params": params_json(&x.params, &x.intervals),
            "reason": x.reason,
        })).collect::<Vec<_>>(),
        "per_run": data.runs.iter().enumerate().map(|(i, r)| {
            let rms = |sim: &[f64], meas: &[f64]| (sim.iter().zip(meas).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / meas.len().max(1) as f64).sqrt();
            json!({
                "run": r.name,
                "heldout": data.held[i].iter().all(|h| *h),
                "baseline_yaw_rate_rmse_radps": rms(&base_sims[i].yaw_rate, &r.yaw_rate),
                "final_yaw_rate_rmse_radps": rms(&final_sims[i].yaw_rate, &r.yaw_rate),
                "baseline_ay_rmse_mps2": rms(&base_sims[i].ay, &r.ay),
                "final_ay_rmse_mps2": rms(&final_sims[i].ay, &r.ay),
                "baseline_replay_finite": base_sims[i].ok,
                "final_replay_finite": final_sims[i].ok,
            })
        }).collect::<Vec<_>>(),
        "final_effects": d.final_effects.iter().map(|fe| json!({
            "effect": fe.effect.name(), "form": fe.effect.form(),
            "params": params_json(&fe.params, &fe.intervals),
            "significant": fe.significant,
        })).collect::<Vec<_>>(),
        "folds": d.folds,
        "jackknife": d.jackknife.as_ref().map(|j| json!({
            "runs_left_out": j.runs_left_out,
            "effects": j.effects.iter().map(|e| json!({
                "effect": e.effect.name(), "form": e.effect.form(),
                "params": params_json(&e.params, &e.intervals),
                "leave_one_out": e.leave_one_out,
            })).collect::<Vec<_>>(),
        })),
        "largest_remaining_windows": largest_windows(windows_after, 10),
        "named_effects": d.named_names(),
        "named_classes": d.named.iter().map(|e| {
            let class = d.classes.iter().find(|c| c.named == *e);
            std::iter::once(e.label()).chain(class.into_iter().flat_map(|c| c.members.iter().map(|m| m.effect.label()))).collect::<Vec<_>>()
        }).collect::<Vec<_>>(),
        "equivalence_classes": d.classes.iter().map(class_json).collect::<Vec<_>>(),
        "road_per_run": d.road_per_run.as_ref().map(|o| o.to_json()),
        "verdict": d.verdict,
        "disagreement_windows_baseline": windows,
        "disagreement_windows_final": windows_after,
        "operating_regions_baseline": regions,
        "thresholds": { "bic_min": super::select::BIC_MIN, "min_gain": super::select::MIN_GAIN, "explained_chi2": super::select::EXPLAINED_NOISE_RATIO.powi(2), "explained_noise_ratio": super::select::EXPLAINED_NOISE_RATIO, "confidence": 0.95 },
    })
}

/// The measured, baseline and improved traces of every run and channel, the baseline's
/// disagreement windows shaded, into `plots`.
fn write_plots(plots: &Path, data: &Dataset, sims: &Sims, windows: &[Window]) -> Result<()> {
    let (base_sims, final_sims) = (&sims.base, &sims.last);
    std::fs::create_dir_all(plots).map_err(|e| Error::Io { path: plots.to_path_buf(), source: e })?;
    for (i, r) in data.runs.iter().enumerate() {
        let spans: Vec<(f64, f64)> = windows.iter().filter(|w| w.run == r.name).map(|w| (w.t0_s, w.t1_s)).collect();
        for (ch, unit, meas, b, f) in [
            ("yaw_rate", "rad/s", &r.yaw_rate, &base_sims[i].yaw_rate, &final_sims[i].yaw_rate),
            ("ay", "m/s^2", &r.ay, &base_sims[i].ay, &final_sims[i].ay),
        ] {
            let pts = |v: &Vec<f64>| r.t.iter().zip(v).map(|(t, y)| (*t, *y)).collect::<Vec<_>>();
            let chart = XyChart {
                title: format!("{} — {ch} (shaded: baseline disagreement)", r.name),
                x_label: "t (s)".into(),
                y_label: format!("{ch} ({unit})"),
                series: vec![
                    Series { label: "measured".into(), points: pts(meas) },
                    Series { label: "baseline".into(), points: pts(b) },
                    Series { label: "improved".into(), points: pts(f) },
                ],
                spans: spans.clone(),
                ..XyChart::default()
            };
            xy_chart(&plots.join(format!("{}_{ch}", r.name)), &chart)?;
        }
    }
    Ok(())
}

/// One equivalence class for report.json: the named effect, its equivalents with their fitted
/// parameters and held-out BIC, the proposed manoeuvre and every manoeuvre's separation.
fn class_json(c: &Class) -> serde_json::Value {
    json!({
        "named": { "effect": c.named.name(), "form": c.named.form() },
        "equivalents": c.members.iter().map(|m| json!({
            "effect": m.effect.name(), "form": m.effect.form(),
            "params": params_json(&m.params, &m.intervals),
            "delta_bic": m.delta_bic, "named_delta_bic": m.named_delta_bic,
        })).collect::<Vec<_>>(),
        "separating_maneuver": c.proposal().maneuver,
        "predicted_difference_over_noise": c.proposal().class,
        "separating_maneuver_with_heading": c.heading_proposal().maneuver,
        "predicted_heading_difference_over_noise": c.heading_proposal().class_heading,
        "separations": c.separations,
    })
}

/// The classes for people (report.md and the terminal): what cannot be told apart, and which
/// runs to add.
pub fn classes_text(d: &Discovery) -> Vec<String> {
    d.classes
        .iter()
        .map(|c| {
            let (p, h) = (c.proposal(), c.heading_proposal());
            let fitted: Vec<String> = c
                .members
                .iter()
                .map(|m| format!("{}: {}", m.effect.label(), params_text(&m.params, &m.intervals)))
                .collect();
            format!(
                "the data cannot tell apart {} (held-out dBIC within {}; the equivalents fitted jointly with the \
                 effects named before, {}); runs of the manoeuvre {} would (predicted difference {:.1} x the \
                 noise; `vehsim synth --maneuvers {}` makes them); with the heading logged to 0.03 degrees, {} \
                 would ({:.1} x the heading increments' noise)",
                c.text(),
                super::equivalence::EQUIVALENCE_BIC,
                fitted.join("; "),
                p.maneuver,
                p.class,
                p.maneuver,
                h.maneuver,
                h.class_heading
            )
        })
        .collect()
}

fn markdown(
    opts: &DiscoverOptions,
    data: &Dataset,
    d: &Discovery,
    [windows, windows_after]: [&[Window]; 2],
    regions: &[super::select::RegionBin],
    why: Option<&super::why::AboveNoise>,
) -> String {
    let mut s = String::new();
    md_header(&mut s, opts, data, d);
    md_rms(&mut s, d);
    md_accepted(&mut s, d);
    md_folds(&mut s, d);
    if let Some(o) = &d.road_per_run {
        s.push_str(&o.markdown());
    }
    md_remaining(&mut s, d, windows_after);
    md_why(&mut s, why);
    md_jackknife(&mut s, d);
    md_dropped(&mut s, d);
    md_rejected(&mut s, d);
    md_noise(&mut s, data);
    md_windows(&mut s, windows);
    md_regions(&mut s, regions);
    s
}

/// report.md: The title, the runs, the verdict and any equivalent forms.
fn md_header(s: &mut String, opts: &DiscoverOptions, data: &Dataset, d: &Discovery) {
    let _ = writeln!(s, "# Discovery report\n");
    let _ = writeln!(s, "Baseline model: {} (vehicle {}).", opts.model, opts.vehicle.display());
    let _ = writeln!(s, "Runs: {}; held out: {}.\n", data.runs.len(), {
        let h = data.heldout_runs();
        if h.is_empty() {
            format!("alternate {} s blocks of the single run", super::select::BLOCK_S)
        } else {
            h.join(", ")
        }
    });
    let _ = writeln!(s, "**Verdict: {}.** Named effects: {}.\n", d.verdict, d.named_text());
    if !d.classes.is_empty() {
        let _ = writeln!(s, "## Equivalent forms\n");
        for line in classes_text(d) {
            let _ = writeln!(s, "- {}{}.", line[..1].to_uppercase(), &line[1..]);
        }
        let _ = writeln!(s);
    }
}

/// report.md: The RMS error per channel, baseline and final, on fitted and held-out data.
fn md_rms(s: &mut String, d: &Discovery) {
    let _ = writeln!(s, "## RMS error per channel\n");
    let _ = writeln!(s, "| data | channel | baseline | final |\n|---|---|---|---|");
    for (label, held) in [("fitted", false), ("held-out", true)] {
        let (b, f) = (d.baseline.rmse(held), d.final_scores.rmse(held));
        let _ = writeln!(s, "| {label} | yaw rate (rad/s) | {:.5} | {:.5} |", b.yaw_rate_radps, f.yaw_rate_radps);
        let _ = writeln!(s, "| {label} | ay (m/s^2) | {:.4} | {:.4} |", b.ay_mps2, f.ay_mps2);
    }
}

/// report.md: The accepted effects with their evidence, and the final joint values.
fn md_accepted(s: &mut String, d: &Discovery) {
    let _ = writeln!(s, "\n## Accepted effects\n");
    if d.steps.is_empty() {
        let _ = writeln!(s, "None.");
    }
    for st in &d.steps {
        let _ = writeln!(
            s,
            "- **{}** ({}): {}. Held-out yaw-rate RMS {:.5} -> {:.5} rad/s. {}",
            st.effect.label(),
            st.effect.describe(),
            params_text(&st.params, &st.intervals),
            st.heldout_rmse_before.yaw_rate_radps,
            st.heldout_rmse_after.yaw_rate_radps,
            st.evidence
        );
    }
    if d.final_effects.len() >= 2 {
        let _ = writeln!(s, "\nFinal parameters, all accepted effects refitted together:\n");
        for fe in &d.final_effects {
            let _ = writeln!(s, "- {}: {}", fe.effect.label(), params_text(&fe.params, &fe.intervals));
        }
    }
}

/// report.md: The held-out gap per fold.
fn md_folds(s: &mut String, d: &Discovery) {
    let _ = writeln!(
        s,
        "\n## Held-out gap per fold (RMS residual / noise, yaw rate and ay; explained at <= {})\n",
        super::select::EXPLAINED_NOISE_RATIO
    );
    let _ = writeln!(s, "| fold | held-out runs | baseline | final |\n|---|---|---|---|");
    for (i, f) in d.folds.iter().enumerate() {
        let h = if f.heldout_runs.is_empty() { "alternate blocks".to_string() } else { f.heldout_runs.join(", ") };
        let _ = writeln!(
            s,
            "| {} | {h} | {:.2}, {:.2} | {:.2}, {:.2} |",
            i + 1,
            f.baseline_noise_ratio[0],
            f.baseline_noise_ratio[1],
            f.final_noise_ratio[0],
            f.final_noise_ratio[1]
        );
    }
    if d.folds.iter().any(|f| f.final_increment_noise_ratio.iter().any(Option::is_some)) {
        let _ = writeln!(
            s,
            "\nThe channels scored on their increments over {} s windows (held-out RMS / noise per fold and \
             logged channel; at the noise within the limit of its window count):\n",
            super::increments::WINDOW_S
        );
        let _ = writeln!(s, "| fold | channel | windows | limit | baseline | final |\n|---|---|---|---|---|---|");
        for (i, f) in d.folds.iter().enumerate() {
            for (c, name) in super::increments::CHANNELS.iter().enumerate() {
                let (Some(b), Some(a)) = (f.baseline_increment_noise_ratio[c], f.final_increment_noise_ratio[c]) else {
                    continue;
                };
                let n = f.increment_windows[c];
                let lim = super::select::increment_noise_limit(n);
                let _ = writeln!(s, "| {} | {name} | {n} | {lim:.2} | {b:.2} | {a:.2} |", i + 1);
            }
        }
    }
}

/// report.md: The largest windows the final model leaves, when the data are not explained.
fn md_remaining(s: &mut String, d: &Discovery, windows_after: &[Window]) {
    if !d.verdict.at_noise() {
        let _ = writeln!(s, "\n## Largest remaining disagreement windows (final model)\n");
        let w = largest_windows(windows_after, 10);
        if w.is_empty() {
            let _ = writeln!(s, "None over 0.2 s.");
        }
        for w in w {
            let _ = writeln!(s, "- {}: {:.2}–{:.2} s (excess {:.1})", w.run, w.t0_s, w.t1_s, w.excess);
        }
    }
}

/// report.md: why the data are left above the noise ([`super::why`]), when they are.
fn md_why(s: &mut String, why: Option<&super::why::AboveNoise>) {
    if let Some(w) = why {
        let _ = writeln!(s, "\n## Why the data are left above the noise\n");
        for line in &w.sentences {
            let _ = writeln!(s, "- {line}");
        }
    }
}

/// report.md: The leave-one-run-out intervals, when asked for.
fn md_jackknife(s: &mut String, d: &Discovery) {
    if let Some(j) = &d.jackknife {
        let _ = writeln!(
            s,
            "\n## Leave-one-run-out (jackknife) intervals\n\nEach of {} fitted runs ({}) left out in turn, the final effects refitted jointly; 95 % = value +- t(0.975, n - 1) x se.\n",
            j.runs_left_out.len(),
            j.runs_left_out.join(", ")
        );
        for e in &j.effects {
            let _ = writeln!(s, "- {}: {}", e.effect.label(), params_text(&e.params, &e.intervals));
        }
    }
}

/// report.md: The effects named, then dropped.
fn md_dropped(s: &mut String, d: &Discovery) {
    if !d.dropped.is_empty() {
        let _ = writeln!(s, "\n## Named, then dropped\n");
        for x in &d.dropped {
            let _ = writeln!(
                s,
                "- {} (accepted in round {}, dropped in round {}): {}; {}",
                x.effect.label(),
                x.accepted_round,
                x.dropped_round,
                params_text(&x.params, &x.intervals),
                x.reason
            );
        }
    }
}

/// report.md: Every candidate tried and not accepted, with its reason.
fn md_rejected(s: &mut String, d: &Discovery) {
    let _ = writeln!(s, "\n## Candidates tried and rejected\n");
    let _ = writeln!(
        s,
        "| round | effect | held-out dBIC | held-out RSS ratio | parameters | reason |\n|---|---|---|---|---|---|"
    );
    for t in &d.rejected {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.3} | {} | {} |",
            t.round,
            t.effect.label(),
            t.delta_bic,
            t.heldout_rss_ratio,
            params_text(&t.params, &t.intervals),
            t.reason
        );
    }
}

/// report.md: The noise estimate per run and channel.
fn md_noise(s: &mut String, data: &Dataset) {
    let _ = writeln!(s, "\n## Noise estimate (from second differences of the measured signals)\n");
    let logged = data.noise.iter().any(|n| n.increments.is_some());
    if logged {
        let _ = writeln!(
            s,
            "| run | yaw rate (rad/s) | ay (m/s^2) | heading (rad) | position (m) | vy (m/s) |\n|---|---|---|---|---|---|"
        );
    } else {
        let _ = writeln!(s, "| run | yaw rate (rad/s) | ay (m/s^2) |\n|---|---|---|");
    }
    for (r, n) in data.runs.iter().zip(&data.noise) {
        let mut row = format!("| {} | {:.2e} | {:.2e} |", r.name, n.yaw_rate, n.ay);
        if logged {
            let p = n.increments.unwrap_or_default();
            for v in [p.psi_rad, p.position_m, p.vy_mps] {
                row.push_str(&v.map_or(" - |".to_string(), |v| format!(" {v:.2e} |")));
            }
        }
        let _ = writeln!(s, "{row}");
    }
}

/// report.md: The baseline's disagreement windows.
fn md_windows(s: &mut String, windows: &[Window]) {
    let _ = writeln!(s, "\n## Baseline disagreement windows (residual mean square > 2x noise over 0.5 s)\n");
    if windows.is_empty() {
        let _ = writeln!(s, "None.");
    }
    for w in windows.iter().take(50) {
        let _ = writeln!(s, "- {}: {:.2}–{:.2} s (excess {:.1})", w.run, w.t0_s, w.t1_s, w.excess);
    }
    if windows.len() > 50 {
        let _ = writeln!(s, "- ... {} more in report.json", windows.len() - 50);
    }
}

/// report.md: The baseline's residual by operating region, and where the plots are.
fn md_regions(s: &mut String, regions: &[super::select::RegionBin]) {
    let _ = writeln!(s, "\n## Baseline residual by operating region (1 = noise level)\n");
    let _ = writeln!(s, "| variable | range | samples | excess | disagrees |\n|---|---|---|---|---|");
    for b in regions {
        let _ = writeln!(
            s,
            "| {} | {}–{} | {} | {:.2} | {} |",
            b.variable,
            b.lo,
            if b.hi > 1e8 { "inf".to_string() } else { b.hi.to_string() },
            b.samples,
            b.excess,
            b.disagrees
        );
    }
    let _ = writeln!(s, "\nPlots: `plots/<run>_yaw_rate.png` and `plots/<run>_ay.png`.");
}
