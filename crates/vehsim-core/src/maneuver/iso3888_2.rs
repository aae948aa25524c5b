//! ISO 3888-2:2011 severe lane change (obstacle avoidance), cone layout from the vehicle width.
//!
//! Layout (x along the course from the entry gate, y left, lane 1 centred on y = 0; the lane
//! widths are the standard's, as functions of the vehicle width):
//!
//! | section | x range (m)   | lane width                      | lateral position              |
//! |---------|---------------|---------------------------------|-------------------------------|
//! | 1 entry | 0 – 12        | 1.1 W + 0.25                    | centred on 0                  |
//! | 2       | 12 – 25.5     | no cones                        |                               |
//! | 3 side  | 25.5 – 36.5   | W + 1                           | right edge 1 m left of lane 1's left edge |
//! | 4       | 36.5 – 49     | no cones                        |                               |
//! | 5 exit  | 49 – 61       | max(1.3 W + 0.25, lane5_min)    | right edge = lane 1's right edge |
//!
//! W is the vehicle body width. The standard's table of cone positions was not available; a cone
//! strike is counted when a body corner crosses a gate's boundary line while it lies within that
//! section, once per (section, side). Strikes are found inside the step: each corner sweeps the
//! straight segment between its positions at the start and end of the step, and the strike is
//! the first point of that segment inside the section and beyond the boundary, with its time
//! interpolated along the segment; so the count does not depend on where the steps fall. The
//! course end (the whole body past the exit gate) and the run's end (the CG `exit_m` beyond it)
//! are interpolated the same way.
//!
//! The reference path for the CG is designed for the vehicle: straight lines in each lane joined by
//! two quintic (minimum-jerk) transitions. Centre-to-centre transitions over the 13.5 m and 12.5 m
//! gaps would need about 2 g at 60 km/h, so, like a driver, the path cuts the corners: among
//! transitions with different start and end points and lateral positions inside the lanes, it
//! takes the pair with the smallest peak curvature whose body outline, carried rigidly along the
//! path (heading = path tangent), clears every gate boundary by `clearance_m`.

use std::sync::Arc;

use super::{Command, Maneuver, Outcome, Start};
use crate::control::{Driver, DriverParams};
use crate::event::{Event, EventKind};
use crate::path::RefPath;
use crate::vehicle::Kinematics;

/// Speed behaviour through the course.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedMode {
    /// Hold the entry speed with the PID all the way (the dissertation: 10 m/s on mu 0.15).
    Hold,
    /// ISO procedure: hold the entry speed up to the entry gate, then release the throttle.
    Coast,
}

/// One cone-bounded section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gate {
    /// Name used in events: `lane 1`, `lane 3`, `lane 5`.
    pub name: &'static str,
    /// Start of the section along x, m from the entry gate (ground frame).
    pub x0_m: f64,
    /// End of the section along x, m from the entry gate.
    pub x1_m: f64,
    /// Right (low y) and left (high y) boundaries, m.
    pub y_right_m: f64,
    /// Left boundary (high y), m (ISO 8855: y positive left).
    pub y_left_m: f64,
}

impl Gate {
    /// Lateral position of the lane centre, m.
    pub fn centre_m(&self) -> f64 {
        0.5 * (self.y_right_m + self.y_left_m)
    }
    /// Lane width, left minus right boundary, m.
    pub fn width_m(&self) -> f64 {
        self.y_left_m - self.y_right_m
    }
}

/// The three gates for a vehicle of body width `w` and a lane-5 minimum width `lane5_min`.
pub fn layout(w: f64, lane5_min: f64) -> [Gate; 3] {
    let w1 = 1.1 * w + 0.25;
    let w3 = w + 1.0;
    let w5 = (1.3 * w + 0.25).max(lane5_min);
    let r1 = -0.5 * w1;
    let l1 = 0.5 * w1;
    [
        Gate { name: "lane 1", x0_m: 0.0, x1_m: 12.0, y_right_m: r1, y_left_m: l1 },
        Gate { name: "lane 3", x0_m: 25.5, x1_m: 36.5, y_right_m: l1 + 1.0, y_left_m: l1 + 1.0 + w3 },
        Gate { name: "lane 5", x0_m: 49.0, x1_m: COURSE_LENGTH_M, y_right_m: r1, y_left_m: r1 + w5 },
    ]
}

/// Course length from the entry gate to the exit gate, m.
pub(crate) const COURSE_LENGTH_M: f64 = 61.0;

/// Parameters of the manoeuvre (validated by the spec layer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Iso3888_2Params {
    /// Entry speed, m/s (held up to the entry gate, then by [`SpeedMode`]).
    pub speed_mps: f64,
    /// Speed behaviour through the course: hold or coast.
    pub mode: SpeedMode,
    /// Straight run-up before the entry gate, m.
    pub approach_m: f64,
    /// Distance driven after the exit gate before the run ends, m.
    pub exit_m: f64,
    /// Lower bound on the lane-5 width, m (3.0 as we read the standard).
    pub lane5_min_width_m: f64,
    /// Clearance between the body outline on the reference path and the gate boundaries, m.
    pub clearance_m: f64,
}

impl Iso3888_2Params {
    /// Where the run ends: the CG `exit_m` beyond the exit gate, m from the entry gate.
    pub fn end_x_m(&self) -> f64 {
        COURSE_LENGTH_M + self.exit_m
    }

    /// Distance the CG drives from the start to the run's end: approach, course, exit, m (summed
    /// in that order).
    pub fn run_length_m(&self) -> f64 {
        self.approach_m + COURSE_LENGTH_M + self.exit_m
    }
}

/// Vehicle dimensions the manoeuvre needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Body width without mirrors, m; sets the lane widths.
    pub width_m: f64,
    /// CG to front bumper, m.
    pub front_m: f64,
    /// CG to rear bumper, m.
    pub rear_m: f64,
    /// Wheelbase, m (for the path-following driver).
    pub wheelbase_m: f64,
}

/// Quintic step from 0 to 1 over u in [0, 1] (zero slope and curvature at both ends); returns the
/// value and its derivative with respect to u.
fn smooth_step(u: f64) -> (f64, f64) {
    if u <= 0.0 {
        return (0.0, 0.0);
    }
    if u >= 1.0 {
        return (1.0, 0.0);
    }
    (u * u * u * (10.0 - 15.0 * u + 6.0 * u * u), 30.0 * u * u * (1.0 - u) * (1.0 - u))
}

/// Peak |d^2 s / du^2| of the quintic step (at u = 1/2 -+ sqrt(3)/6).
const QUINTIC_PEAK_CURVATURE: f64 = 5.773_502_691_896_258;

/// A lateral transition of the CG path from y0 to y1 between x0 and x1 (ground frame, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// Start x of the transition, m.
    pub x0: f64,
    /// End x of the transition, m.
    pub x1: f64,
    /// Lateral position at the start, m (positive left).
    pub y0: f64,
    /// Lateral position at the end, m (positive left).
    pub y1: f64,
}

impl Transition {
    /// Lateral position and slope dy/dx at x.
    pub fn at(&self, x: f64) -> (f64, f64) {
        let d = self.x1 - self.x0;
        let (v, dv) = smooth_step((x - self.x0) / d);
        (self.y0 + (self.y1 - self.y0) * v, (self.y1 - self.y0) * dv / d)
    }

    /// Peak |y''| of the transition, 1/m (about the path's peak curvature).
    pub fn peak_curvature(&self) -> f64 {
        QUINTIC_PEAK_CURVATURE * (self.y1 - self.y0).abs() / (self.x1 - self.x0).powi(2)
    }
}

/// The body's four corners on the ground, (x, y) in m in the ground frame.
pub(crate) type Corners = [(f64, f64); 4];

/// Body corners in the ground frame: front-left, front-right, rear-left, rear-right.
pub(crate) fn body_corners(body: &Body, kin: &Kinematics) -> Corners {
    let (f, r, hw) = (body.front_m, body.rear_m, 0.5 * body.width_m);
    let (s, c) = kin.yaw_rad.sin_cos();
    let at = |px: f64, py: f64| (kin.x_m + px * c - py * s, kin.y_m + px * s + py * c);
    [at(f, hw), at(f, -hw), at(-r, hw), at(-r, -hw)]
}

/// Does the body outline, carried along `t` with heading along the tangent, keep `clearance`
/// from every gate boundary while its corners lie in that gate?
fn clears(t: &Transition, gates: &[Gate], body: &Body, clearance: f64) -> bool {
    let mut x = t.x0 - body.front_m - 0.5;
    while x <= t.x1 + body.rear_m + 0.5 {
        let (y, slope) = t.at(x);
        let kin = Kinematics { x_m: x, y_m: y, yaw_rad: slope.atan(), ..Kinematics::default() };
        for (cx, cy) in body_corners(body, &kin) {
            for g in gates {
                if cx >= g.x0_m && cx <= g.x1_m && (cy < g.y_right_m + clearance || cy > g.y_left_m - clearance) {
                    return false;
                }
            }
        }
        x += 0.2;
    }
    true
}

/// CG lateral positions that keep the straight body `clearance` inside gate `g` (5 values).
fn lane_positions(g: &Gate, body: &Body, clearance: f64) -> Vec<f64> {
    let lo = g.y_right_m + 0.5 * body.width_m + clearance;
    let hi = g.y_left_m - 0.5 * body.width_m - clearance;
    if hi <= lo {
        return vec![g.centre_m()];
    }
    (0..5).map(|i| lo + (hi - lo) * i as f64 / 4.0).collect()
}

/// The gentlest transition from gate `a` to gate `b` between lateral positions in `from` and `to`.
fn best_transition(a: &Gate, b: &Gate, from: &[f64], to: &[f64], body: &Body, clearance: f64) -> Option<Transition> {
    let mut cands = Vec::new();
    let x0s = (0..).map(|i| a.x1_m - 6.0 + 0.5 * i as f64).take_while(|x| *x <= a.x1_m + body.rear_m + 2.0);
    for x0 in x0s {
        let x1s = (0..).map(|i| b.x0_m - body.front_m - 2.0 + 0.5 * i as f64).take_while(|x| *x <= b.x0_m + 6.0);
        for x1 in x1s.filter(|x1| *x1 > x0 + 2.0) {
            for &y0 in from {
                for &y1 in to {
                    let t = Transition { x0, x1, y0, y1 };
                    cands.push((t.peak_curvature(), t));
                }
            }
        }
    }
    cands.sort_by(|p, q| p.0.total_cmp(&q.0));
    let gates = [*a, *b];
    cands.into_iter().map(|c| c.1).find(|t| clears(t, &gates, body, clearance))
}

/// The two transitions of the reference path (lane 1 -> 3, lane 3 -> 5) that minimise the larger
/// of their peak curvatures; falls back to centre-to-centre transitions across the gaps when no
/// candidate clears (a vehicle too large for its own lanes cannot occur with W-scaled lanes, but the
/// fallback keeps the manoeuvre defined).
pub(crate) fn design_path(gates: &[Gate; 3], body: &Body, clearance: f64) -> (Transition, Transition) {
    // The design depends only on the gates, the body and the clearance; batches repeat it with the
    // same inputs, so it is memoised (the result is the same whether computed or cached).
    type Key = [u64; 6];
    static CACHE: std::sync::OnceLock<std::sync::Mutex<std::collections::HashMap<Key, (Transition, Transition)>>> =
        std::sync::OnceLock::new();
    let key: Key = [
        body.width_m.to_bits(),
        body.front_m.to_bits(),
        body.rear_m.to_bits(),
        gates[2].y_left_m.to_bits(),
        gates[0].y_right_m.to_bits(),
        clearance.to_bits(),
    ];
    let cache = CACHE.get_or_init(Default::default);
    if let Some(t) = cache.lock().ok().and_then(|c| c.get(&key).copied()) {
        return t;
    }
    let t = search_path(gates, body, clearance);
    if let Ok(mut c) = cache.lock() {
        c.insert(key, t);
    }
    t
}

fn search_path(gates: &[Gate; 3], body: &Body, clearance: f64) -> (Transition, Transition) {
    let p1 = lane_positions(&gates[0], body, clearance);
    let p3 = lane_positions(&gates[1], body, clearance);
    let p5 = lane_positions(&gates[2], body, clearance);
    let mut best: Option<(f64, Transition, Transition)> = None;
    for &y3 in &p3 {
        let t1 = best_transition(&gates[0], &gates[1], &p1, &[y3], body, clearance);
        let t2 = best_transition(&gates[1], &gates[2], &[y3], &p5, body, clearance);
        if let (Some(t1), Some(t2)) = (t1, t2) {
            let score = t1.peak_curvature().max(t2.peak_curvature());
            if best.as_ref().is_none_or(|b| score < b.0) {
                best = Some((score, t1, t2));
            }
        }
    }
    match best {
        Some((_, t1, t2)) => (t1, t2),
        None => (
            Transition { x0: gates[0].x1_m, x1: gates[1].x0_m, y0: gates[0].centre_m(), y1: gates[1].centre_m() },
            Transition { x0: gates[1].x1_m, x1: gates[2].x0_m, y0: gates[1].centre_m(), y1: gates[2].centre_m() },
        ),
    }
}

/// The CG's reference path from `x0` to `x1` (m) through the transitions `(t1, t2)`: straight,
/// then `t1`, then `t2` from `t1`'s end, sampled every 0.1 m. Runs of a batch or benchmark repeat
/// it with the same inputs, so the last few are kept (the same path whether built or kept).
fn reference_path(x0: f64, x1: f64, (t1, t2): (Transition, Transition)) -> Arc<RefPath> {
    type Key = [u64; 10];
    static CACHE: std::sync::OnceLock<std::sync::Mutex<std::collections::HashMap<Key, Arc<RefPath>>>> =
        std::sync::OnceLock::new();
    /// Paths kept at most (about 100 kB each at the default lengths).
    const KEEP: usize = 8;
    let key: Key = [x0, x1, t1.x0, t1.x1, t1.y0, t1.y1, t2.x0, t2.x1, t2.y0, t2.y1].map(f64::to_bits);
    let cache = CACHE.get_or_init(Default::default);
    if let Some(p) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
        return p;
    }
    let y = move |x: f64| if x < t1.x1 { t1.at(x).0 } else { t2.at(x).0 };
    let path = Arc::new(RefPath::from_fn(x0, x1, 0.1, y));
    if let Ok(mut c) = cache.lock() {
        if c.len() >= KEEP {
            c.clear();
        }
        c.insert(key, path.clone());
    }
    path
}

/// The running manoeuvre.
#[derive(Debug, Clone)]
pub struct Iso3888_2 {
    /// The validated parameters.
    pub params: Iso3888_2Params,
    /// The three gates (lanes 1, 3 and 5), laid out for the body width.
    pub gates: [Gate; 3],
    /// Vehicle dimensions checked against the gates.
    pub body: Body,
    /// The reference path the driver follows, designed to clear the gates by `clearance_m`.
    pub path: Arc<RefPath>,
    /// The two lateral transitions of the reference path.
    pub transitions: (Transition, Transition),
    driver: Driver,
    /// Struck (gate index, side 0 = right / 1 = left).
    struck: Vec<(usize, usize)>,
    course_done: bool,
    /// Time, body corners and the corners' x range (lowest, highest) at the end of the previous
    /// step (the start of the segments swept next).
    previous: Option<(f64, Corners, (f64, f64))>,
    /// CG x at the end of the previous step, m.
    previous_x: Option<f64>,
    /// Interpolated time at which the CG passed the end of the run, s.
    end_time: Option<f64>,
}

/// Where along the segment p0 -> p1 (as a fraction in [0, 1]) a point first lies inside gate `g`'s
/// x range and beyond its boundary `side` (0 right: y < y_right; 1 left: y > y_left), if anywhere.
fn first_beyond(p0: (f64, f64), p1: (f64, f64), g: &Gate, side: usize) -> Option<f64> {
    // Clip the segment to x0 <= x <= x1.
    let dx = p1.0 - p0.0;
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    if dx == 0.0 {
        if p0.0 < g.x0_m || p0.0 > g.x1_m {
            return None;
        }
    } else {
        let (a, b) = ((g.x0_m - p0.0) / dx, (g.x1_m - p0.0) / dx);
        lo = lo.max(a.min(b));
        hi = hi.min(a.max(b));
        if lo > hi {
            return None;
        }
    }
    // Signed distance beyond the boundary (positive beyond), linear along the segment.
    let beyond = |f: f64| {
        let y = p0.1 + f * (p1.1 - p0.1);
        if side == 0 {
            g.y_right_m - y
        } else {
            y - g.y_left_m
        }
    };
    let (d_lo, d_hi) = (beyond(lo), beyond(hi));
    if d_lo > 0.0 {
        Some(lo)
    } else if d_hi > 0.0 {
        Some(lo + (hi - lo) * d_lo / (d_lo - d_hi))
    } else {
        None
    }
}

/// Whether a corner sweeping from lateral position `y0` to `y1` stays between gate `g`'s
/// boundaries by more than a rounding margin, so that [`first_beyond`] finds nothing on either side
/// (the points it tests lie between `y0` and `y1` up to a few ulps). False for non-finite positions.
fn inside_band(y0: f64, y1: f64, g: &Gate) -> bool {
    let margin = 1e-9 * (1.0 + y0.abs() + y1.abs());
    let (lo, hi) = (g.y_right_m + margin, g.y_left_m - margin);
    y0 > lo && y1 > lo && y0 < hi && y1 < hi
}

/// Time at which a quantity moving linearly from `v0` (at `t0`) to `v1` (at `t1`) passes `level`.
fn crossing_time(t0: f64, t1: f64, v0: f64, v1: f64, level: f64) -> f64 {
    if v1 > v0 && v0 <= level {
        t0 + (t1 - t0) * (level - v0) / (v1 - v0)
    } else {
        t1
    }
}

impl Iso3888_2 {
    /// The manoeuvre for `body`: lays out the gates, designs the reference path and builds the driver.
    pub fn new(params: Iso3888_2Params, body: Body, driver: DriverParams) -> Self {
        let gates = layout(body.width_m, params.lane5_min_width_m);
        let transitions = design_path(&gates, &body, params.clearance_m);
        let path = reference_path(-params.approach_m - 50.0, params.end_x_m() + 100.0, transitions);
        let driver = Driver::new(driver, body.wheelbase_m);
        Self {
            params,
            gates,
            body,
            path,
            transitions,
            driver,
            struck: Vec::new(),
            course_done: false,
            previous: None,
            previous_x: None,
            end_time: None,
        }
    }

    /// Body corners in the ground frame: front-left, front-right, rear-left, rear-right.
    pub fn corners(&self, kin: &Kinematics) -> Corners {
        body_corners(&self.body, kin)
    }
}

impl Maneuver for Iso3888_2 {
    fn start(&self) -> Start {
        Start {
            x_m: -self.params.approach_m,
            y_m: self.transitions.0.y0,
            yaw_rad: 0.0,
            speed_mps: self.params.speed_mps,
        }
    }

    fn command(&mut self, _t: f64, kin: &Kinematics) -> Command {
        // The yaw's sine and cosine once, for the driver and the front of the body.
        let (s, c) = kin.yaw_rad.sin_cos();
        let steer_rad = self.driver.steer_with(&self.path, kin, (s, c));
        // x of the body point (front_m, 0), as [`Kinematics::body_point`] computes it
        let front_x = kin.x_m + self.body.front_m * c - 0.0 * s;
        let speed_target_mps = match self.params.mode {
            SpeedMode::Hold => Some(self.params.speed_mps),
            SpeedMode::Coast if front_x < 0.0 => Some(self.params.speed_mps),
            SpeedMode::Coast => None,
        };
        Command { steer_rad, speed_target_mps }
    }

    fn path_error_m(&self) -> Option<f64> {
        Some(self.driver.lateral_error_m)
    }

    fn after_step(&mut self, t: f64, kin: &Kinematics, events: &mut Vec<Event>) -> bool {
        let corners = self.corners(kin);
        let range1 = corners.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| (lo.min(c.0), hi.max(c.0)));
        // The previous step's corners; on the first call the segment degenerates to a point.
        let (t0, prev, range0) = self.previous.unwrap_or((t, corners, range1));
        self.previous = Some((t, corners, range1));
        let mut strikes: Vec<(f64, usize, usize, usize, f64, f64)> = Vec::new();
        // The x range the body swept in this step: a gate outside it cannot be struck (the swept
        // segments' clipping to the gate's x range would be empty), so most steps test no gate.
        // (The range of both steps' corners: each step's range is kept for the next.)
        let (x_lo, x_hi) = (range0.0.min(range1.0), range0.1.max(range1.1));
        let far = |g: &Gate| g.x1_m < x_lo || g.x0_m > x_hi;
        let any_near = !self.gates.iter().all(far);
        for (ci, (&p0, &p1)) in prev.iter().zip(corners.iter()).enumerate().filter(|_| any_near) {
            for (gi, g) in self.gates.iter().enumerate() {
                if far(g) || inside_band(p0.1, p1.1, g) {
                    continue;
                }
                for side in 0..2 {
                    if self.struck.contains(&(gi, side)) {
                        continue;
                    }
                    if let Some(f) = first_beyond(p0, p1, g, side) {
                        let (x, y) = (p0.0 + f * (p1.0 - p0.0), p0.1 + f * (p1.1 - p0.1));
                        strikes.push((t0 + f * (t - t0), gi, side, ci, x, y));
                    }
                }
            }
        }
        // In time order; one strike per (gate, side).
        strikes.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (ts, gi, side, ci, cx, cy) in strikes {
            if self.struck.contains(&(gi, side)) {
                continue;
            }
            self.struck.push((gi, side));
            let corner = ["front-left", "front-right", "rear-left", "rear-right"][ci];
            let side_name = ["right", "left"][side];
            events.push(Event {
                t_s: ts,
                kind: EventKind::ConeStrike,
                detail: format!(
                    "{} {} boundary struck by the {corner} corner at x = {cx:.2} m, y = {cy:.3} m",
                    self.gates[gi].name, side_name
                ),
            });
        }
        // The rearmost corner's x at the start and end of the step (the x ranges' lower ends).
        let (rear0, rear1) = (range0.0, range1.0);
        if !self.course_done && rear1 > COURSE_LENGTH_M {
            self.course_done = true;
            events.push(Event {
                t_s: crossing_time(t0, t, rear0, rear1, COURSE_LENGTH_M),
                kind: EventKind::CourseComplete,
                detail: "the whole body passed the exit gate".into(),
            });
        }
        let x_end = self.params.end_x_m();
        if kin.x_m > x_end {
            self.end_time = Some(crossing_time(t0, t, self.previous_x.unwrap_or(kin.x_m), kin.x_m, x_end));
            return true;
        }
        self.previous_x = Some(kin.x_m);
        false
    }

    fn end_time_s(&self) -> Option<f64> {
        self.end_time
    }

    fn outcome(&self) -> Outcome {
        Outcome { passed: Some(self.course_done && self.struck.is_empty()), cones_hit: self.struck.len() }
    }

    #[cfg(feature = "serde")]
    fn layout(&self) -> Option<serde_json::Value> {
        let gates: Vec<_> = self
            .gates
            .iter()
            .map(|g| serde_json::json!({"name": g.name, "x0_m": g.x0_m, "x1_m": g.x1_m, "y_right_m": g.y_right_m, "y_left_m": g.y_left_m}))
            .collect();
        let x_end = self.params.end_x_m();
        let (t1, t2) = self.transitions;
        // [x, y] pairs every 0.5 m, built as the values serde_json makes of a Vec<[f64; 2]>
        let path: Vec<serde_json::Value> = (0..)
            .map(|i| -self.params.approach_m + 0.5 * i as f64)
            .take_while(|x| *x <= x_end)
            .map(|x| serde_json::Value::Array(vec![x.into(), (if x < t1.x1 { t1.at(x).0 } else { t2.at(x).0 }).into()]))
            .collect();
        // The object json!({"kind", "gates", "body", "reference_path"}) makes, in that order,
        // without serialising the arrays a second time.
        let mut layout = serde_json::Map::new();
        layout.insert("kind".into(), "iso3888_2".into());
        layout.insert("gates".into(), serde_json::Value::Array(gates));
        let body =
            serde_json::json!({"front_m": self.body.front_m, "rear_m": self.body.rear_m, "width_m": self.body.width_m});
        layout.insert("body".into(), body);
        layout.insert("reference_path".into(), serde_json::Value::Array(path));
        Some(serde_json::Value::Object(layout))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn course() -> Iso3888_2 {
        let params = Iso3888_2Params {
            speed_mps: 10.0,
            mode: SpeedMode::Hold,
            approach_m: 30.0,
            exit_m: 20.0,
            lane5_min_width_m: 3.0,
            clearance_m: 0.1,
        };
        let body = Body { width_m: 1.8, front_m: 2.3, rear_m: 2.2, wheelbase_m: 2.7 };
        Iso3888_2::new(params, body, DriverParams::default())
    }

    #[cfg(feature = "serde")]
    /// The layout is the object `json!` makes of the gates, the body and the path as a
    /// `Vec<[f64; 2]>`, to the byte.
    #[test]
    fn layout_is_the_json_of_its_parts() {
        let m = course();
        let gates: Vec<_> = m
            .gates
            .iter()
            .map(|g| serde_json::json!({"name": g.name, "x0_m": g.x0_m, "x1_m": g.x1_m, "y_right_m": g.y_right_m, "y_left_m": g.y_left_m}))
            .collect();
        let (t1, t2) = m.transitions;
        let path: Vec<[f64; 2]> = (0..)
            .map(|i| -30.0 + 0.5 * i as f64)
            .take_while(|x| *x <= COURSE_LENGTH_M + 20.0)
            .map(|x| [x, if x < t1.x1 { t1.at(x).0 } else { t2.at(x).0 }])
            .collect();
        let want = serde_json::json!({
            "kind": "iso3888_2",
            "gates": gates,
            "body": {"front_m": 2.3, "rear_m": 2.2, "width_m": 1.8},
            "reference_path": path,
        });
        let got = m.layout().unwrap();
        assert_eq!(got, want);
        assert_eq!(serde_json::to_string_pretty(&got).unwrap(), serde_json::to_string_pretty(&want).unwrap());
    }

    /// The kept reference path is the one built afresh.
    #[test]
    fn kept_path_is_the_built_one() {
        let (a, b) = (course(), course());
        assert!(Arc::ptr_eq(&a.path, &b.path));
        let (t1, t2) = a.transitions;
        let fresh =
            RefPath::from_fn(-80.0, COURSE_LENGTH_M + 120.0, 0.1, |x| if x < t1.x1 { t1.at(x).0 } else { t2.at(x).0 });
        assert_eq!(*a.path, fresh);
    }

    /// A corner sweep inside a gate's band finds no strike on either side, for sweeps ending at
    /// up to a few ulps from the boundaries (where the band test gives way to the full one).
    #[test]
    fn inside_the_band_no_side_is_struck() {
        let g = layout(1.8, 3.0)[1];
        let mut inside = 0;
        for k in 0..2000 {
            let f = k as f64 / 1999.0;
            for (y0, y1) in [
                (g.y_right_m + f * g.width_m(), g.y_left_m - f * g.width_m()),
                (g.y_right_m, g.y_right_m + f * 1e-12),
                (g.y_left_m - f * 1e-9, g.y_left_m - 2e-9),
                (g.y_right_m + 1e-8 * f, g.centre_m()),
            ] {
                let (p0, p1) = ((g.x0_m + 3.0 * f, y0), (g.x0_m + 3.0 * f + 0.1, y1));
                if inside_band(y0, y1, &g) {
                    inside += 1;
                    assert_eq!((first_beyond(p0, p1, &g, 0), first_beyond(p0, p1, &g, 1)), (None, None), "{y0} {y1}");
                }
            }
        }
        assert!(inside > 2000, "{inside}");
        assert!(!inside_band(f64::NAN, 0.0, &g) && !inside_band(g.centre_m(), f64::INFINITY, &g));
    }
}
