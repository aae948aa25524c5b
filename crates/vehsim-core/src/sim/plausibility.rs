//! Plausibility of a run: checks that say when a result should not be trusted, with events at the
//! recorded row where a check starts and stops failing, and a verdict for the summary
//! (`plausible` and the reasons).
//!
//! The checks, on every recorded row (the output interval, `[output] interval_s`):
//! - **tyre force beyond the friction bound**: per axle, |F| = sqrt(Fx^2 + Fy^2) (sum over the
//!   axle, N) against the bound sum(mu_i Fz_i) over the axle's tyres, with mu_i the provider's peak
//!   friction coefficient at that tyre's load, slip, surface and contact temperature
//!   ([`TyreModel::peak_friction`]); a provider without a bound (the unsaturated linear tyre) is
//!   held to the surface's mu. Fails when |F| / bound > `FORCE_RATIO_LIMIT` (1.05): only an
//!   unsaturated tyre can get there.
//! - **lateral acceleration beyond the surface's friction**: |a_y| against mu_eff g, with mu_eff =
//!   (sum of the tyres' bounds) / (sum of their loads), the friction the provider realises on this
//!   surface (the spec's mu for the unsaturated linear tyre). Fails when |a_y| / (mu_eff g) >
//!   `AY_RATIO_LIMIT` (1.05).
//! - **leaving the path**: |lateral deviation of the CG from the reference path| beyond the
//!   manoeuvre's tolerance (the spec layer's `run::path_tolerance_m`): constant radius max(1 m, 5 % of R); lane change
//!   half the widest lane's width (the CG is then outside a lane-wide band around the path: the car
//!   has left the course, not merely clipped a cone).
//!
//! After the run, [`Plausibility::finish`] also folds in a constant-radius run that ended by
//! leaving the circle (end reason `left_path`) and the steady-state windows that were not steady
//! ([`crate::sim::steady_state`]). Each check gives one onset event when it starts failing and
//! one recovery event when it stops (the first `super::watch::MAX_ONSETS` times), so a summary
//! never floods.

use std::sync::Arc;

use crate::event::EndReason;

use super::engine::Summary;
use super::observer::Row;
use super::watch::MAX_ONSETS;
use crate::event::{Event, EventKind};
use crate::sim::steady_state::SteadyState;
use crate::tyre::{Prepared, TyreInput, TyreModel};
use crate::vehicle::Environment;
use crate::vehicle::GRAVITY;

/// Largest plausible |F| / (mu Fz) of an axle.
pub(crate) const FORCE_RATIO_LIMIT: f64 = 1.05;
/// Largest plausible |a_y| / (mu_eff g).
pub(crate) const AY_RATIO_LIMIT: f64 = 1.05;

/// The three row checks, in the order of [`CHECKS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Check {
    Force,
    LateralAcceleration,
    Path,
}

/// Onset and recovery event kinds of each check.
const CHECKS: [(Check, EventKind, EventKind); 3] = [
    (Check::Force, EventKind::TyreForceBeyondFriction, EventKind::TyreForceWithinFriction),
    (Check::LateralAcceleration, EventKind::AyBeyondFriction, EventKind::AyWithinFriction),
    (Check::Path, EventKind::PathExit, EventKind::PathReturn),
];

/// The worst excess of one check over the run.
#[derive(Debug, Clone, Copy, Default)]
struct Worst {
    /// Ratio (force, a_y) or deviation (path, m); 0 when never checked.
    value: f64,
    t_s: f64,
    /// Axle of the worst force (0 front, 1 rear).
    axle: usize,
    first_t_s: Option<f64>,
}

/// The running checker of one run.
#[derive(Debug)]
pub struct Plausibility {
    tyre: Arc<dyn TyreModel>,
    env: Environment,
    path_tolerance_m: Option<f64>,
    active: [bool; 3],
    onsets: [u32; 3],
    worst: [Worst; 3],
    events: Vec<Event>,
    /// The provider's coefficients prepared per tyre slot of a row (`fz_n` order) at the first
    /// load seen there ([`TyreModel::prepare`]): a model with static loads uses them whole; one
    /// with load transfer uses their load-independent part. Re-prepared only if the surface
    /// (friction, camber) changes.
    prepared: [Option<Prepared>; 4],
    /// Per axle: whether its two slots were prepared from the same input, bit for bit (so hold
    /// the same coefficients: the provider is pure). A row whose two loads on that axle are the
    /// same bits then gives both tyres the same input and the same floor, computed once.
    twin: [bool; 2],
    /// The bits of the input each slot was prepared from ([`input_bits`]).
    prepared_from: [Option<[u64; 8]>; 4],
    /// The tyre's declared ranges ([`super::range_check`]), when it declares any.
    ranges: Option<super::range_check::RangeCheck>,
}

/// The bits of every field of a tyre input (equal bits: the same input to a pure provider).
fn input_bits(i: &TyreInput) -> [u64; 8] {
    [
        i.fz_n.to_bits(),
        i.kappa.to_bits(),
        i.alpha_rad.to_bits(),
        i.camber_rad.to_bits(),
        i.vx_mps.to_bits(),
        i.mu_surface.to_bits(),
        i.surface_temp_c.to_bits(),
        i.contact_temp_c.to_bits(),
    ]
}

impl Plausibility {
    /// A checker for a run with tyre provider `tyre` on `env`, path tolerance `path_tolerance_m`
    /// (m; `None`: no path check).
    pub fn new(tyre: Arc<dyn TyreModel>, env: Environment, path_tolerance_m: Option<f64>) -> Self {
        Self {
            tyre,
            env,
            path_tolerance_m,
            active: [false; 3],
            onsets: [0; 3],
            worst: [Worst::default(); 3],
            events: Vec::new(),
            prepared: [None; 4],
            twin: [false; 2],
            prepared_from: [None; 4],
            ranges: None,
        }
    }

    /// The same checker, also flagging operating points outside the ranges the tyre data
    /// declares as measured (none declared: unchanged).
    pub fn with_ranges(mut self, ranges: crate::tyre::ranges::TyreRanges) -> Self {
        if ranges.any() {
            self.ranges = Some(super::range_check::RangeCheck::new(ranges));
        }
        self
    }

    /// The friction bound of axle `axle` (N) and its tyres' load (N) at `row`.
    fn axle_bound(&mut self, row: &Row, axle: usize) -> (f64, f64) {
        let o = &row.obs;
        let mut bound = 0.0;
        let mut load = 0.0;
        // The first tyre's peak friction, kept for its twin (the same prepared input and load: the
        // same coefficients, matched or not alike, and the same value).
        let mut first = None;
        for slot in 2 * axle..2 * axle + 2 {
            let fz = o.fz_n[slot];
            if fz.is_nan() || fz <= 0.0 {
                continue;
            }
            if let Some(mu) = first.filter(|_| self.twin[axle] && fz.to_bits() == o.fz_n[slot - 1].to_bits()) {
                bound += if f64::is_finite(mu) { mu } else { self.env.mu } * fz;
                load += fz;
                continue;
            }
            let input = self.input(row, axle, fz);
            if !matches!(&self.prepared[slot], Some(p) if p.matches_surface(&input)) {
                self.prepared[slot] = Some(self.tyre.prepare(&input));
                self.prepared_from[slot] = Some(input_bits(&input));
                let (a, b) = (self.prepared_from[2 * axle], self.prepared_from[2 * axle + 1]);
                self.twin[axle] = a.is_some() && a == b;
            }
            let mu = match &self.prepared[slot] {
                Some(p) => self.tyre.peak_friction_prepared(p, &input),
                None => self.tyre.peak_friction(&input),
            };
            bound += if mu.is_finite() { mu } else { self.env.mu } * fz;
            load += fz;
            first = Some(mu);
        }
        (bound, load)
    }

    /// Whether the tyre-force and lateral-acceleration checks are sure to pass at `row` without
    /// their exact bounds: neither is failing now, and every tyre has a cheap floor under its
    /// bound ([`TyreModel::peak_force_floor_prepared`]) that each axle's |F| and |a_y| (against
    /// the floors' mu_eff) do not exceed. Their ratios are then at most 1 (< the 1.05 limits) and
    /// would neither start an event nor become a reported worst (only a failing ratio is
    /// reported, and it exceeds every passing one).
    fn well_within(&mut self, row: &Row) -> bool {
        if self.active[Check::Force as usize] || self.active[Check::LateralAcceleration as usize] {
            return false;
        }
        let o = &row.obs;
        let (mut floor_sum, mut load_sum) = (0.0, 0.0);
        for axle in 0..2 {
            let mut floor = 0.0;
            // The first tyre's floor, kept for its twin (the same prepared input and load).
            let mut first = None;
            for slot in 2 * axle..2 * axle + 2 {
                let fz = o.fz_n[slot];
                let Some(p) = &self.prepared[slot] else { return false };
                if fz.is_nan() || fz <= 0.0 {
                    return false;
                }
                let f = match first {
                    Some(f) if self.twin[axle] && fz.to_bits() == o.fz_n[slot - 1].to_bits() => f,
                    _ => match self.tyre.peak_force_floor_prepared(p, &self.input(row, axle, fz)) {
                        Some(f) => f,
                        None => return false,
                    },
                };
                floor += f;
                first = Some(f);
                load_sum += fz;
            }
            // |F| <= floor, squared (false for a NaN force; rounding is far inside the 5 % margin)
            let f2 = o.fx_n[axle] * o.fx_n[axle] + o.fy_n[axle] * o.fy_n[axle];
            if !matches!(f2.partial_cmp(&(floor * floor)), Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)) {
                return false;
            }
            floor_sum += floor;
        }
        o.ay_mps2.abs() * load_sum <= floor_sum * GRAVITY
    }

    /// The tyre input of axle `axle`'s tyre with load `fz` at `row`.
    fn input(&self, row: &Row, axle: usize, fz: f64) -> TyreInput {
        let o = &row.obs;
        TyreInput {
            fz_n: fz,
            kappa: o.kappa[axle],
            alpha_rad: o.alpha_rad[axle],
            camber_rad: 0.0,
            vx_mps: o.kin.vx_mps.abs(),
            mu_surface: self.env.mu,
            surface_temp_c: self.env.surface_temp_c,
            contact_temp_c: o.contact_temp_axle_c[axle],
        }
    }

    /// Check one recorded row.
    pub fn check(&mut self, row: &Row) {
        if let Some(r) = &mut self.ranges {
            r.check(row);
        }
        if !self.well_within(row) {
            self.check_friction(row);
        }
        if let Some(tol) = self.path_tolerance_m {
            if row.path_error_m.is_finite() {
                self.update(Check::Path, row.t_s, row.path_error_m.abs(), tol, 0);
            }
        }
    }

    /// The tyre-force and lateral-acceleration checks of `row` against the exact bounds.
    fn check_friction(&mut self, row: &Row) {
        let o = &row.obs;
        let mut force = (0.0_f64, 0);
        let (mut bound_sum, mut load_sum) = (0.0, 0.0);
        for axle in 0..2 {
            let (bound, load) = self.axle_bound(row, axle);
            bound_sum += bound;
            load_sum += load;
            let f = o.fx_n[axle].hypot(o.fy_n[axle]);
            if bound > 0.0 && f.is_finite() && f / bound > force.0 {
                force = (f / bound, axle);
            }
        }
        self.update(Check::Force, row.t_s, force.0, FORCE_RATIO_LIMIT, force.1);
        if bound_sum > 0.0 && o.ay_mps2.is_finite() {
            let mu_eff = bound_sum / load_sum;
            self.update(Check::LateralAcceleration, row.t_s, o.ay_mps2.abs() / (mu_eff * GRAVITY), AY_RATIO_LIMIT, 0);
        }
    }

    fn update(&mut self, check: Check, t_s: f64, value: f64, limit: f64, axle: usize) {
        let i = check as usize;
        let w = &mut self.worst[i];
        if value > w.value {
            *w = Worst { value, t_s, axle, first_t_s: w.first_t_s };
        }
        let failing = value > limit;
        if failing && w.first_t_s.is_none() {
            w.first_t_s = Some(t_s);
        }
        if failing == self.active[i] {
            return;
        }
        self.active[i] = failing;
        if failing {
            self.onsets[i] += 1;
        }
        if self.onsets[i] > MAX_ONSETS {
            return;
        }
        let (_, onset, recovery) = CHECKS[i];
        let detail = match check {
            Check::Force => format!(
                "{} axle: |F| = {value:.2} x its friction bound (allowed {limit})",
                if axle == 0 { "front" } else { "rear" }
            ),
            Check::LateralAcceleration => format!("|a_y| = {value:.2} x mu_eff g (allowed {limit})"),
            Check::Path => format!("CG {value:.2} m from the reference path (tolerance {limit:.2} m)"),
        };
        self.events.push(Event { t_s, kind: if failing { onset } else { recovery }, detail });
    }

    /// The reasons found by the row checks so far.
    fn reasons(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (i, (check, _, _)) in CHECKS.iter().enumerate() {
            let w = &self.worst[i];
            let Some(t0) = w.first_t_s else { continue };
            out.push(match check {
                Check::Force => format!(
                    "tyre force beyond the friction bound from t = {t0:.2} s: up to {:.2} x (mu Fz) on the {} axle at \
                     t = {:.2} s (the tyre does not saturate)",
                    w.value,
                    if w.axle == 0 { "front" } else { "rear" },
                    w.t_s
                ),
                Check::LateralAcceleration => format!(
                    "lateral acceleration beyond the surface's friction from t = {t0:.2} s: up to {:.2} x mu g at t = \
                     {:.2} s",
                    w.value, w.t_s
                ),
                Check::Path => format!(
                    "left the path from t = {t0:.2} s: CG up to {:.2} m from it at t = {:.2} s (tolerance {:.2} m)",
                    w.value,
                    w.t_s,
                    self.path_tolerance_m.unwrap_or(f64::NAN)
                ),
            });
        }
        out
    }

    /// Fold the checks into `summary`: the events (merged in time order, stable), `plausible` and
    /// the reasons, including a run ended by leaving the path and the steady-state windows that
    /// were not steady.
    pub fn finish(self, summary: &mut Summary, steady: &[SteadyState]) {
        let mut reasons = self.reasons();
        if let Some(r) = &self.ranges {
            reasons.extend(r.reasons());
        }
        if summary.end_reason == EndReason::LeftPath && self.worst[Check::Path as usize].first_t_s.is_none() {
            reasons.push(format!("left the path: the run ended at t = {:.2} s", summary.end_time_s));
        }
        for s in steady.iter().filter(|s| !s.steady) {
            reasons.push(format!("steady-state window of step {} not steady: {}", s.step, s.not_steady));
        }
        summary.events.extend(self.events);
        if let Some(r) = self.ranges {
            summary.events.extend(r.into_events());
        }
        summary.events.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        summary.plausible = reasons.is_empty();
        summary.implausible = reasons;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::maneuver::constant_radius::circle_tolerance_m;
    use crate::tyre::LinearTyre;
    use crate::vehicle::{Inputs, Kinematics, Observation};

    const ENV: Environment = Environment {
        mu: 0.15,
        surface_temp_c: -3.0,
        regions: crate::vehicle::ground::GroundRegions::NONE,
        road: crate::vehicle::road::Road::FLAT,
    };

    /// A row at time t with axle forces (front, rear) and lateral acceleration ay; 4000 N per tyre.
    fn row(t: f64, fy: [f64; 2], ay: f64, path: f64) -> Row {
        Row {
            t_s: t,
            obs: Observation {
                kin: Kinematics { vx_mps: 10.0, ..Kinematics::default() },
                ay_mps2: ay,
                fy_n: fy,
                fz_n: [4000.0; 4],
                contact_temp_axle_c: [-3.0; 2],
                ..Observation::default()
            },
            inputs: Inputs::default(),
            speed_target_mps: 10.0,
            path_error_m: path,
        }
    }

    fn linear(saturate: bool) -> Arc<dyn TyreModel> {
        Arc::new(LinearTyre {
            cornering_stiffness_n_per_rad: 69000.0,
            longitudinal_stiffness_n: 80000.0,
            nominal_load_n: 4000.0,
            load_exponent: 0.8,
            saturate,
        })
    }

    fn empty_summary() -> Summary {
        Summary {
            passed: None,
            cones_hit: 0,
            peak_yaw_rate_radps: 0.0,
            peak_sideslip_rad: 0.0,
            peak_ay_mps2: 0.0,
            max_path_deviation_m: None,
            min_speed_mps: 0.0,
            max_speed_mps: 0.0,
            max_speed_error_mps: None,
            steps: 0,
            end_time_s: 10.0,
            end_reason: crate::event::EndReason::Completed,
            events: Vec::new(),
            plausible: true,
            implausible: Vec::new(),
        }
    }

    /// The unsaturated linear tyre: the bound is mu Fz = 0.15 x 8000 = 1200 N per axle. A force
    /// ramp crosses 1.05 x 1200 = 1260 N at row 13 (1300 N) and falls back at row 30: one onset at
    /// row 13, one recovery at row 30; a_y is checked against mu g = 1.471 m/s^2 in the same way.
    #[test]
    fn force_and_ay_events_fire_at_the_right_row() {
        let mut p = Plausibility::new(linear(false), ENV, Some(1.5));
        for k in 0..40 {
            let f = if k < 30 { 100.0 * k as f64 } else { 0.0 };
            let ay = if (20..25).contains(&k) { 1.6 } else { 1.5 };
            p.check(&row(k as f64 * 0.01, [f, 0.5 * f], ay, 0.0));
        }
        let mut s = empty_summary();
        p.finish(&mut s, &[]);
        let ev: Vec<(String, EventKind)> = s.events.iter().map(|e| (format!("{:.2}", e.t_s), e.kind)).collect();
        assert_eq!(
            ev,
            [
                ("0.13".to_string(), EventKind::TyreForceBeyondFriction),
                ("0.20".to_string(), EventKind::AyBeyondFriction),
                ("0.25".to_string(), EventKind::AyWithinFriction),
                ("0.30".to_string(), EventKind::TyreForceWithinFriction),
            ]
        );
        assert!(!s.plausible);
        assert_eq!(s.implausible.len(), 2, "{:?}", s.implausible);
        // Worst force ratio: 2900 N / 1200 N at row 29 on the front axle.
        assert!(s.implausible[0].contains("2.42 x") && s.implausible[0].contains("front"), "{:?}", s.implausible);
        // 1.6 / (0.15 g) = 1.088 (1.5 / 1.471 = 1.0197 stays inside the 5 %).
        assert!(s.implausible[1].contains("1.09 x"), "{:?}", s.implausible);
    }

    /// A saturating tyre at its bound and a_y at exactly mu g: nothing fires.
    #[test]
    fn a_run_at_the_friction_limit_is_plausible() {
        let mut p = Plausibility::new(linear(true), ENV, Some(1.5));
        for k in 0..50 {
            p.check(&row(k as f64 * 0.01, [1200.0, 1200.0], 0.15 * GRAVITY, 1.49));
        }
        let mut s = empty_summary();
        p.finish(&mut s, &[]);
        assert!(s.plausible && s.implausible.is_empty() && s.events.is_empty(), "{:?}", s);
    }

    /// Leaving the path fires at the first row beyond the tolerance; a run ended by leaving the
    /// circle is implausible even when no recorded row shows it; a check that flaps is capped.
    #[test]
    fn path_exit_and_end_reason_and_cap() {
        let mut p = Plausibility::new(linear(true), ENV, Some(2.0));
        for k in 0..10 {
            p.check(&row(k as f64, [0.0; 2], 0.0, 0.5 * k as f64));
        }
        let mut s = empty_summary();
        p.finish(&mut s, &[]);
        assert_eq!((s.events[0].t_s, s.events[0].kind), (5.0, EventKind::PathExit));
        assert!(s.implausible[0].contains("4.50 m"), "{:?}", s.implausible);

        let p = Plausibility::new(linear(true), ENV, Some(2.0));
        let mut s = empty_summary();
        s.end_reason = crate::event::EndReason::LeftPath;
        p.finish(&mut s, &[]);
        assert!(!s.plausible && s.implausible[0].starts_with("left the path"), "{:?}", s.implausible);

        let mut p = Plausibility::new(linear(true), ENV, None);
        for k in 0..1000 {
            p.check(&row(k as f64, [0.0; 2], if k % 2 == 0 { 2.0 } else { 0.0 }, 99.0));
        }
        let mut s = empty_summary();
        p.finish(&mut s, &[]);
        assert_eq!(s.events.len(), 2 * MAX_ONSETS as usize, "no path check without a tolerance, capped onsets");
    }

    #[test]
    fn tolerances() {
        assert_eq!(circle_tolerance_m(0.5), 1.0);
        assert_eq!(circle_tolerance_m(40.0), 2.0);
        assert_eq!(circle_tolerance_m(100.0), 5.0);
    }

    /// A provider without a cheap floor: every row takes the exact bounds.
    #[derive(Debug)]
    struct NoFloor(Arc<dyn TyreModel>);

    impl TyreModel for NoFloor {
        fn name(&self) -> &'static str {
            self.0.name()
        }
        fn forces(&self, i: &TyreInput) -> crate::tyre::TyreForces {
            self.0.forces(i)
        }
        fn peak_friction(&self, i: &TyreInput) -> f64 {
            self.0.peak_friction(i)
        }
        fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
            self.0.longitudinal_stiffness(i)
        }
        fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
            self.0.cornering_stiffness(i)
        }
        fn prepare(&self, i: &TyreInput) -> Prepared {
            self.0.prepare(i)
        }
        fn peak_friction_prepared(&self, p: &Prepared, i: &TyreInput) -> f64 {
            self.0.peak_friction_prepared(p, i)
        }
    }

    #[test]
    fn floor_pretest_changes_no_event_or_reason() {
        let tyre: Arc<dyn TyreModel> = Arc::new(crate::tyre::srtt_for_tests());
        let (mut with, mut without) = (
            Plausibility::new(tyre.clone(), ENV, Some(1.0)),
            Plausibility::new(Arc::new(NoFloor(tyre)), ENV, Some(1.0)),
        );
        // Forces, slips and a_y swept through and beyond the friction bounds and back: onsets,
        // recoveries and worst values on both checks, rows near the limits included.
        let mut skipped = 0;
        for k in 0..400 {
            let t = k as f64 * 0.01;
            let w = (0.05 * k as f64).sin();
            let mut r = row(t, [2600.0 * w, -1800.0 * w], 3.6 * w, 1.2 * w);
            r.obs.fx_n = [300.0 * w, -500.0 * (0.07 * k as f64).cos()];
            r.obs.kappa = [0.02 * w, -0.05 * w];
            r.obs.alpha_rad = [0.1 * w, 0.2 * (0.03 * k as f64).sin()];
            skipped += usize::from(with.well_within(&r));
            with.check(&r);
            without.check(&r);
        }
        assert!(skipped > 50 && skipped < 350, "{skipped} rows of 400 took the floor");
        assert_eq!(with.events, without.events);
        assert_eq!(with.reasons(), without.reasons());
        assert!(with.events.len() >= 4 && with.reasons().len() == 3, "{:?}", with.events);
    }

    /// Two tyres of an axle prepared from the same input share their floor and their peak
    /// friction when their loads are the same bits: the pre-test and the exact checks say the
    /// same as with every value computed, row by row, for rows on both sides of the floor and of
    /// the limits, with equal and unequal loads, for a provider with a floor (ATIIM Pacejka) and
    /// one without (the unsaturated linear tyre: every row checked exactly).
    #[test]
    fn twin_tyres_share_their_floor_and_bound() {
        use crate::tyre::atiim::{AtiimPacejkaTyre, AxisLaw, KShift, MeltLaw};
        // the SRTT tyre file's [atiim_pacejka] law
        let law = MeltLaw {
            k_shift: KShift::Srtt,
            x: AxisLaw { peak_at_melt: 0.5, stiffness_at_melt: 1.0 },
            y: AxisLaw { peak_at_melt: 0.9, stiffness_at_melt: 1.0 },
            floor: 0.1,
        };
        let atiim: Arc<dyn TyreModel> = Arc::new(AtiimPacejkaTyre { base: crate::tyre::srtt_for_tests(), law });
        for (tyre, with_floor) in [(atiim, true), (linear(false), false)] {
            let (mut shared, mut each) =
                (Plausibility::new(tyre.clone(), ENV, None), Plausibility::new(tyre, ENV, None));
            let (mut reused, mut within) = (0, 0);
            for k in 0..300 {
                let w = (0.05 * k as f64).sin();
                let mut r = row(k as f64 * 0.01, [2600.0 * w, -1800.0 * w], 1.8 * w, 0.0);
                r.obs.kappa = [0.02 * w, -0.05 * w];
                r.obs.contact_temp_axle_c = [-3.0 + 2.0 * w.abs(), -3.0 + w.abs()];
                if k % 3 == 1 {
                    r.obs.fz_n[1] = 4100.0; // unequal loads on the front axle: no sharing there
                }
                each.twin = [false; 2];
                let (a, b) = (shared.well_within(&r), each.well_within(&r));
                assert_eq!(a, b, "row {k}");
                reused += usize::from(shared.twin == [true; 2] && k % 3 != 1);
                within += usize::from(a);
                shared.check(&r);
                each.twin = [false; 2];
                each.check(&r);
                let bits =
                    |p: &Plausibility| p.worst.map(|w| (w.value.to_bits(), w.t_s.to_bits(), w.axle, w.first_t_s));
                assert_eq!(bits(&shared), bits(&each), "row {k}");
            }
            assert!(reused > 100, "{reused} rows shared");
            assert!(!with_floor || (within > 50 && within < 250), "{within} rows within the floor");
            assert!(shared.events.len() >= 4, "{:?}", shared.events);
            assert_eq!(shared.events, each.events);
            assert_eq!(shared.reasons(), each.reasons());
        }
    }
}
