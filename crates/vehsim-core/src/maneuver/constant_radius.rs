//! Steady-state circular driving, constant-radius method (ISO 4138 method 1).
//!
//! The driver follows a circle of radius R (a closed reference path starting at the origin,
//! heading +x, centre at (0, R) for a left turn and (0, -R) for a right turn). The speed is either
//! held at one value by the PID (the dissertation's section 6.2: 8 m/s, rear drive) or raised in
//! steps so that the nominal lateral acceleration v^2 / R rises by at most 0.5 m/s^2 per step. Each
//! step lasts `settle_s + window_s`: the speed target ramps to the step's speed at `speed_ramp_mps2`
//! and the vehicle settles; the last `window_s` seconds are the step's steady-state window, over
//! which [`crate::sim::steady_state`] averages the recorded rows. The run ends after the last window,
//! or as soon as the CG is farther than [`circle_tolerance_m`] (max(1 m, 5 % of R)) from the
//! circle, with end reason `left_path` and a `left_path` event: the later steps would not be
//! driven on the circle, so they are not measured.

use super::{Command, Maneuver, Outcome, Start, SteadyWindow};
use crate::control::{Driver, DriverParams};
use crate::event::{Event, EventKind};
use crate::path::RefPath;
use crate::vehicle::Kinematics;

/// Turn direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Counter-clockwise seen from above (yaw rate and lateral acceleration positive).
    Left,
    /// Clockwise seen from above (yaw rate and lateral acceleration negative).
    Right,
}

impl Direction {
    /// +1 for left (counter-clockwise), -1 for right.
    pub fn sign(self) -> f64 {
        match self {
            Direction::Left => 1.0,
            Direction::Right => -1.0,
        }
    }
}

/// Parameters of the manoeuvre (validated by the spec layer).
#[derive(Debug, Clone, PartialEq)]
pub struct ConstantRadiusParams {
    /// Circle radius, m.
    pub radius_m: f64,
    /// Turn direction.
    pub direction: Direction,
    /// Speed of each step, m/s (one entry: speed held all the way).
    pub step_speeds_mps: Vec<f64>,
    /// Settling time at the start of each step, s.
    pub settle_s: f64,
    /// Steady-state window at the end of each step, s.
    pub window_s: f64,
    /// Largest rate of change of the speed target between steps, m/s^2.
    pub speed_ramp_mps2: f64,
}

impl ConstantRadiusParams {
    /// Step speeds for nominal lateral accelerations ay_first, ay_first + step, ... <= ay_max
    /// (m/s^2) on radius `r`: v = sqrt(ay R).
    pub fn stepped_speeds(r: f64, ay_first: f64, ay_step: f64, ay_max: f64) -> Vec<f64> {
        let n = ((ay_max - ay_first) / ay_step + 1e-9).floor().max(0.0) as usize + 1;
        (0..n).map(|k| ((ay_first + k as f64 * ay_step) * r).sqrt()).collect()
    }

    /// Length of one step, s.
    pub fn step_s(&self) -> f64 {
        self.settle_s + self.window_s
    }

    /// Time from the start to the end of the last window, s.
    pub fn total_s(&self) -> f64 {
        self.step_s() * self.step_speeds_mps.len() as f64
    }
}

/// The running manoeuvre.
#[derive(Debug, Clone)]
pub struct ConstantRadius {
    /// The validated parameters.
    pub params: ConstantRadiusParams,
    /// The circle the driver follows.
    pub path: RefPath,
    driver: Driver,
    laps_done: usize,
    last_s: f64,
    left_path: bool,
}

impl ConstantRadius {
    /// The manoeuvre for a vehicle of wheelbase `wheelbase_m` (used by the driver).
    pub fn new(params: ConstantRadiusParams, driver: DriverParams, wheelbase_m: f64) -> Self {
        let r = params.radius_m;
        let sign = params.direction.sign();
        let n = ((2.0 * std::f64::consts::PI * r / 0.1).ceil() as usize).clamp(64, 200_000);
        let pts = (0..n)
            .map(|i| {
                let th = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
                (r * th.sin(), sign * r * (1.0 - th.cos()))
            })
            .collect();
        let path = RefPath::new(pts, true);
        let driver = Driver::new(driver, wheelbase_m);
        Self { params, path, driver, laps_done: 0, last_s: 0.0, left_path: false }
    }

    /// Signed radial error of the CG at `kin`, m: distance from the centre minus R (outside > 0).
    pub fn radial_error_m(&self, kin: &Kinematics) -> f64 {
        let r = self.params.radius_m;
        let cy = self.params.direction.sign() * r;
        kin.x_m.hypot(kin.y_m - cy) - r
    }

    /// Speed target at time t, m/s: continuous in t. Each step ramps at `speed_ramp_mps2` from the
    /// target reached at the end of the previous step toward the step's speed (validation makes
    /// sure a ramp ends within `settle_s`, so in specs that pass it the reached target is the step
    /// speed).
    pub fn speed_target(&self, t: f64) -> f64 {
        let p = &self.params;
        let speeds = &p.step_speeds_mps;
        let k = ((t / p.step_s()).floor().max(0.0) as usize).min(speeds.len().saturating_sub(1));
        let Some(&first) = speeds.first() else { return 0.0 };
        let toward = |from: f64, to: f64, dt: f64| {
            let dv = p.speed_ramp_mps2 * dt;
            if to >= from {
                to.min(from + dv)
            } else {
                to.max(from - dv)
            }
        };
        let mut reached = first;
        for &v in &speeds[1..k.max(1).min(speeds.len())] {
            reached = toward(reached, v, p.step_s());
        }
        if k == 0 {
            return first;
        }
        toward(reached, speeds[k], t - k as f64 * p.step_s())
    }
}

impl Maneuver for ConstantRadius {
    fn start(&self) -> Start {
        Start {
            x_m: 0.0,
            y_m: 0.0,
            yaw_rad: 0.0,
            speed_mps: self.params.step_speeds_mps.first().copied().unwrap_or(0.0),
        }
    }

    fn command(&mut self, t: f64, kin: &Kinematics) -> Command {
        let steer_rad = self.driver.steer(&self.path, kin);
        Command { steer_rad, speed_target_mps: Some(self.speed_target(t)) }
    }

    fn path_error_m(&self) -> Option<f64> {
        Some(self.driver.lateral_error_m)
    }

    fn after_step(&mut self, t: f64, kin: &Kinematics, events: &mut Vec<Event>) -> bool {
        // Count laps from the driver's arc-length cursor wrapping around.
        let (s, _) = self.path.closest(kin.x_m, kin.y_m, self.last_s);
        let len = self.path.length();
        if self.last_s > 0.75 * len && s < 0.25 * len {
            self.laps_done += 1;
            events.push(Event { t_s: t, kind: EventKind::LapComplete, detail: format!("lap {}", self.laps_done) });
        }
        self.last_s = s;
        let err = self.radial_error_m(kin);
        let tol = circle_tolerance_m(self.params.radius_m);
        if err.abs() > tol {
            self.left_path = true;
            events.push(Event {
                t_s: t,
                kind: EventKind::LeftPath,
                detail: format!("CG {err:+.2} m from the circle (tolerance {tol:.2} m); the run ends"),
            });
            return true;
        }
        t >= self.params.total_s() - 1e-9
    }

    fn end_reason(&self) -> Option<crate::event::EndReason> {
        self.left_path.then_some(crate::event::EndReason::LeftPath)
    }

    fn outcome(&self) -> Outcome {
        Outcome { passed: None, cones_hit: 0 }
    }

    fn steady_state_windows(&self) -> Vec<SteadyWindow> {
        let p = &self.params;
        p.step_speeds_mps
            .iter()
            .enumerate()
            .map(|(k, &v)| {
                let t1 = (k + 1) as f64 * p.step_s();
                SteadyWindow {
                    step: k + 1,
                    t0_s: t1 - p.window_s,
                    t1_s: t1,
                    speed_target_mps: v,
                    nominal_ay_mps2: p.direction.sign() * v * v / p.radius_m,
                }
            })
            .collect()
    }
}

/// Radial tolerance of a constant-radius run on a circle of radius `radius_m`, m: max(1, 0.05 R).
pub fn circle_tolerance_m(radius_m: f64) -> f64 {
    (0.05 * radius_m).max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The run ends at the first step whose CG is beyond the tolerance, with its own end reason.
    #[test]
    fn leaving_the_circle_ends_the_run() {
        let p = ConstantRadiusParams {
            radius_m: 20.0,
            direction: Direction::Right,
            step_speeds_mps: vec![5.0],
            settle_s: 1.0,
            window_s: 1.0,
            speed_ramp_mps2: 0.5,
        };
        let mut m = ConstantRadius::new(p, DriverParams::default(), 2.8);
        let mut ev = Vec::new();
        // Right circle: centre (0, -20). Drifting outward along +y: 0.5 m per step.
        for k in 0..10 {
            let kin = Kinematics { x_m: 0.0, y_m: 0.5 * k as f64, ..Kinematics::default() };
            assert!((m.radial_error_m(&kin) - 0.5 * k as f64).abs() < 1e-12);
            let done = m.after_step(0.1 * k as f64, &kin, &mut ev);
            // Tolerance max(1, 0.05 x 20) = 1 m: 1.5 m (k = 3) is the first error beyond it.
            assert_eq!(done, k >= 3, "step {k}");
            if done {
                break;
            }
        }
        assert_eq!(m.end_reason(), Some(crate::event::EndReason::LeftPath));
        assert_eq!(ev.last().map(|e| e.kind), Some(EventKind::LeftPath));
    }

    #[test]
    fn stepped_speeds_give_half_metre_steps_of_lateral_acceleration() {
        let v = ConstantRadiusParams::stepped_speeds(40.0, 0.5, 0.5, 2.0);
        assert_eq!(v.len(), 4);
        for (k, s) in v.iter().enumerate() {
            assert!((s * s / 40.0 - 0.5 * (k + 1) as f64).abs() < 1e-12);
        }
    }

    #[test]
    fn right_circle_mirrors_left() {
        let mk = |d| {
            let p = ConstantRadiusParams {
                radius_m: 40.0,
                direction: d,
                step_speeds_mps: vec![8.0],
                settle_s: 1.0,
                window_s: 1.0,
                speed_ramp_mps2: 0.5,
            };
            ConstantRadius::new(p, DriverParams::default(), 2.8)
        };
        let (l, r) = (mk(Direction::Left), mk(Direction::Right));
        let (pl, pr) = (l.path.point_at(30.0), r.path.point_at(30.0));
        assert!((pl.0 - pr.0).abs() < 1e-12 && (pl.1 + pr.1).abs() < 1e-12 && pl.1 > 0.0);
    }

    /// The speed target never jumps, even when a ramp cannot finish within its step (such specs
    /// fail validation, but the manoeuvre must still behave): it moves at most ramp x dt.
    #[test]
    fn speed_target_is_continuous_and_rate_limited() {
        let p = ConstantRadiusParams {
            radius_m: 100.0,
            direction: Direction::Left,
            step_speeds_mps: vec![5.0, 7.0, 9.0],
            settle_s: 5.0,
            window_s: 1.0,
            speed_ramp_mps2: 0.1,
        };
        let m = ConstantRadius::new(p, DriverParams::default(), 2.8);
        let dt = 0.01;
        let mut prev = m.speed_target(0.0);
        for i in 1..2000 {
            let v = m.speed_target(i as f64 * dt);
            assert!((v - prev).abs() <= 0.1 * dt + 1e-12, "jump at t = {}: {prev} -> {v}", i as f64 * dt);
            prev = v;
        }
        // Six seconds per step, 0.6 m/s per step at 0.1 m/s^2: 5.0 -> 5.6 -> 6.2 (not the nominal 9).
        assert!((m.speed_target(18.0) - 6.2).abs() < 1e-9, "{}", m.speed_target(18.0));
    }
}
