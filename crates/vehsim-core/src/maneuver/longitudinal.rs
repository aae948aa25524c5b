//! Straight-line longitudinal manoeuvres with the pedal held at its stop: braking from a speed to
//! standstill (or to a lower speed), with the braking distance and the mean deceleration, and the
//! launch from standstill to a speed, with its time and distance.
//!
//! Both steer straight ahead (road-wheel angle 0, open loop) and ask for the pedal itself
//! ([`Maneuver::pedal`]): the brake pedal reaches its stop within one control period of
//! `brake_at_s` (before that the PID holds the start speed); the throttle is at its stop from the
//! start. With ABS or traction control (`[abs]`, `[tcs]`) the controllers modulate what reaches
//! the wheels.
//!
//! Results (`summary.json`'s `results`), positions along the path travelled (the sum of the CG's
//! displacements over the steps, m), times in s, speeds in m/s, decelerations in m/s^2:
//! - braking: the speed at brake onset v0, the braking distance d and time from onset until the
//!   speed falls to the end speed (standstill: `STOP_SPEED_MPS`, the last 5 mm or so; crossings
//!   interpolated linearly within the step), the mean deceleration (v0^2 - v_end^2) / (2 d) and
//!   the mean fully developed deceleration of UN ECE R13-H (between 0.8 v0 and 0.1 v0:
//!   (v_b^2 - v_e^2) / (2 (s_e - s_b))).
//! - launch: the time and the distance from the start to the target speed.

#[cfg(feature = "serde")]
use serde_json::json;

use super::{Command, Maneuver, Outcome, Start};

use crate::event::Event;
use crate::vehicle::Kinematics;

/// Speed that counts as standstill for a stop, m/s.
pub(crate) const STOP_SPEED_MPS: f64 = 0.1;

/// Braking parameters (validated by the spec layer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrakingParams {
    /// Start speed, m/s.
    pub speed_mps: f64,
    /// End speed, m/s (0: standstill).
    pub end_speed_mps: f64,
    /// Brake onset, s.
    pub brake_at_s: f64,
}

/// Launch parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaunchParams {
    /// Target speed, m/s.
    pub speed_mps: f64,
}

/// The crossings the results need, recorded as (time s, distance m).
#[derive(Debug, Clone, Copy, Default)]
struct Marks {
    onset: Option<(f64, f64, f64)>,
    v80: Option<(f64, f64)>,
    v10: Option<(f64, f64)>,
    end: Option<(f64, f64)>,
}

/// Straight braking or launch, the common path keeping.
#[derive(Debug, Clone)]
pub struct Longitudinal {
    mode: Mode,
    /// Distance travelled so far, m, and the last position and speed.
    s_m: f64,
    last: Option<(f64, f64, f64, f64)>,
    marks: Marks,
}

#[derive(Debug, Clone, Copy)]
enum Mode {
    Braking(BrakingParams),
    Launch(LaunchParams),
}

impl Longitudinal {
    /// Straight braking from `p.speed_mps` with the brake pedal at its stop from `p.brake_at_s`.
    pub fn braking(p: BrakingParams) -> Self {
        Self { mode: Mode::Braking(p), s_m: 0.0, last: None, marks: Marks::default() }
    }

    /// Straight launch from standstill to `p.speed_mps` with the throttle at its stop.
    pub fn launch(p: LaunchParams) -> Self {
        Self { mode: Mode::Launch(p), s_m: 0.0, last: None, marks: Marks::default() }
    }

    /// The speed at which the run ends, m/s, and whether it is reached from above (braking).
    fn end_speed(&self) -> (f64, bool) {
        match self.mode {
            Mode::Braking(p) => (p.end_speed_mps.max(STOP_SPEED_MPS), true),
            Mode::Launch(p) => (p.speed_mps, false),
        }
    }
}

/// (time, distance) where the speed crosses `level` between (t0, s0, v0) and (t1, s1, v1).
fn crossing(level: f64, (t0, s0, v0): (f64, f64, f64), (t1, s1, v1): (f64, f64, f64)) -> (f64, f64) {
    let w = if v1 != v0 { ((level - v0) / (v1 - v0)).clamp(0.0, 1.0) } else { 1.0 };
    (t0 + w * (t1 - t0), s0 + w * (s1 - s0))
}

impl Maneuver for Longitudinal {
    fn start(&self) -> Start {
        let v = match self.mode {
            Mode::Braking(p) => p.speed_mps,
            Mode::Launch(_) => 0.0,
        };
        Start { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0, speed_mps: v }
    }

    fn command(&mut self, _t: f64, _kin: &Kinematics) -> Command {
        match self.mode {
            Mode::Braking(p) => Command { steer_rad: 0.0, speed_target_mps: Some(p.speed_mps) },
            Mode::Launch(p) => Command { steer_rad: 0.0, speed_target_mps: Some(p.speed_mps) },
        }
    }

    fn steer_at(&self, _t: f64) -> Option<f64> {
        Some(0.0)
    }

    fn pedal(&self, t: f64) -> Option<f64> {
        match self.mode {
            Mode::Braking(p) => (t > p.brake_at_s + 1e-9).then_some(-1.0),
            Mode::Launch(_) => Some(1.0),
        }
    }

    fn path_error_m(&self) -> Option<f64> {
        None
    }

    fn after_step(&mut self, t: f64, kin: &Kinematics, _events: &mut Vec<Event>) -> bool {
        let v = kin.speed_mps();
        let Some((t0, x0, y0, v0)) = self.last else {
            self.last = Some((t, kin.x_m, kin.y_m, v));
            return false;
        };
        let s0 = self.s_m;
        let (dx, dy) = (kin.x_m - x0, kin.y_m - y0);
        self.s_m += (dx * dx + dy * dy).sqrt();
        self.last = Some((t, kin.x_m, kin.y_m, v));
        let (a, b) = ((t0, s0, v0), (t, self.s_m, v));
        if let Mode::Braking(p) = self.mode {
            if self.marks.onset.is_none() && t >= p.brake_at_s - 1e-9 {
                // the step that reaches the onset (the onset is a step time)
                self.marks.onset = Some((t, self.s_m, v));
            }
            if let Some((_, _, vb)) = self.marks.onset {
                for (frac, mark) in [(0.8, &mut self.marks.v80), (0.1, &mut self.marks.v10)] {
                    if mark.is_none() && v <= frac * vb && v0 > frac * vb {
                        *mark = Some(crossing(frac * vb, a, b));
                    }
                }
            }
        }
        let (level, falling) = self.end_speed();
        let armed = match self.mode {
            Mode::Braking(_) => self.marks.onset.is_some(),
            Mode::Launch(_) => true,
        };
        let crossed = if falling { v <= level && v0 > level } else { v >= level && v0 < level };
        if armed && crossed {
            self.marks.end = Some(crossing(level, a, b));
            return true;
        }
        false
    }

    fn end_time_s(&self) -> Option<f64> {
        self.marks.end.map(|e| e.0)
    }

    fn outcome(&self) -> Outcome {
        Outcome::default()
    }

    #[cfg(feature = "serde")]
    fn results(&self) -> Option<serde_json::Value> {
        let m = &self.marks;
        Some(match self.mode {
            Mode::Braking(p) => {
                let (onset, end) = (m.onset, m.end);
                let distance = onset.zip(end).map(|((_, sb, _), (_, se))| se - sb);
                let time = onset.zip(end).map(|((tb, _, _), (te, _))| te - tb);
                let v_end = p.end_speed_mps.max(STOP_SPEED_MPS);
                let mean = onset.zip(distance).map(|((_, _, v0), d)| (v0 * v0 - v_end * v_end) / (2.0 * d));
                let mfdd = onset.zip(m.v80.zip(m.v10)).map(|((_, _, v0), ((_, sb), (_, se)))| {
                    let (vb, ve) = (0.8 * v0, 0.1 * v0);
                    (vb * vb - ve * ve) / (2.0 * (se - sb))
                });
                json!({
                    "kind": "braking",
                    "brake_onset_s": onset.map(|o| o.0),
                    "speed_at_onset_mps": onset.map(|o| o.2),
                    "end_speed_mps": v_end,
                    "stopped": end.is_some(),
                    "braking_distance_m": distance,
                    "braking_time_s": time,
                    "mean_deceleration_mps2": mean,
                    "mfdd_mps2": mfdd,
                })
            }
            Mode::Launch(p) => json!({
                "kind": "launch",
                "target_speed_mps": p.speed_mps,
                "reached": m.end.is_some(),
                "time_to_speed_s": m.end.map(|e| e.0),
                "distance_m": m.end.map(|e| e.1),
            }),
        })
    }
}

// Every test reads the manoeuvre's result figures, which come with the `serde` feature.
#[cfg(all(test, feature = "serde"))]
mod tests {
    use super::*;

    fn kin(x: f64, v: f64) -> Kinematics {
        Kinematics { x_m: x, vx_mps: v, ..Kinematics::default() }
    }

    /// A constant deceleration a from v0 at onset gives d = v0^2 / (2 a) (to the stop speed) and
    /// mean deceleration and MFDD a, from the crossings interpolated within the steps.
    #[test]
    fn constant_deceleration_closed_form() {
        let (v0, a, tb, h) = (13.0, 1.5, 0.5, 0.005);
        let mut m = Longitudinal::braking(BrakingParams { speed_mps: v0, end_speed_mps: 0.0, brake_at_s: tb });
        let mut ev = Vec::new();
        let mut k = 0;
        loop {
            let t = k as f64 * h;
            let (x, v) = if t <= tb {
                (v0 * t, v0)
            } else {
                let d = t - tb;
                (v0 * tb + v0 * d - 0.5 * a * d * d, v0 - a * d)
            };
            if m.after_step(t, &kin(x, v), &mut ev) {
                break;
            }
            k += 1;
            assert!(k < 100_000);
        }
        let r = m.results().unwrap();
        let d = r["braking_distance_m"].as_f64().unwrap();
        let want = (v0 * v0 - STOP_SPEED_MPS * STOP_SPEED_MPS) / (2.0 * a);
        assert!((d - want).abs() < 1e-3, "{d} vs {want}");
        assert!((r["mean_deceleration_mps2"].as_f64().unwrap() - a).abs() < 1e-3);
        assert!((r["mfdd_mps2"].as_f64().unwrap() - a).abs() < 1e-3);
        assert!((r["braking_time_s"].as_f64().unwrap() - (v0 - STOP_SPEED_MPS) / a).abs() < 1e-6);
        assert_eq!(m.pedal(tb), None);
        assert_eq!(m.pedal(tb + 0.01), Some(-1.0));
    }

    #[test]
    fn launch_time_and_distance() {
        let (a, v1, h) = (0.8, 10.0, 0.01);
        let mut m = Longitudinal::launch(LaunchParams { speed_mps: v1 });
        let mut ev = Vec::new();
        let mut k = 0;
        while !m.after_step(k as f64 * h, &kin(0.5 * a * (k as f64 * h).powi(2), a * k as f64 * h), &mut ev) {
            k += 1;
        }
        let r = m.results().unwrap();
        assert!((r["time_to_speed_s"].as_f64().unwrap() - v1 / a).abs() < 1e-9);
        assert!((r["distance_m"].as_f64().unwrap() - v1 * v1 / (2.0 * a)).abs() < 1e-3);
    }
}
