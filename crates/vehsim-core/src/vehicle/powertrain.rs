//! The powertrain: engine or electric-motor torque as a function of its speed (with a power limit),
//! a gearbox with a fixed gear or a shift schedule, the final drive, the driveline inertia
//! reflected to the wheels, and the axle differentials (open, locked or limited-slip).
//!
//! Units and signs: torques in N m, positive driving; speeds in rad/s (the spec gives engine
//! speeds in rpm and converts once); wheel speeds positive rolling forward. "Overall ratio" is
//! i = i_gear i_final, so the engine turns at omega_e = i omega_c, with omega_c the driven
//! wheels' carrier speed (below), and the torque at the driven wheels is
//! T_w = eta i T_e(omega_e), T_e = min(curve(omega_e), P_max / omega_e).
//!
//! - **Torque curve**: piecewise linear in engine speed through the given points. Below the first
//!   point the clutch slips (a launch) and the engine holds the first point's torque; above the
//!   last point (the rev limiter) it gives none. An electric motor is the curve "constant torque,
//!   then constant power" up to its top speed.
//! - **Gear**: a fixed gear, or the automatic schedule "the gear that gives the most wheel torque
//!   at the present wheel speed, below the rev limit" (full-throttle shift points; ties go to the
//!   lower gear). It is a function of the state, so a shift is instantaneous and the torque at the
//!   wheels is continuous across it; shift time and part-throttle schedules are not modelled.
//! - **Carrier speed** omega_c = sum_i s_i omega_i over the axles' mean wheel speeds omega_i with
//!   the drive shares s_i (front-wheel drive s = (1, 0); rear (0, 1); all-wheel drive a centre
//!   differential with the fixed torque split (s_f, 1 - s_f), whose kinematics are exactly that).
//! - **Reflected inertia**: the engine side J_e (engine, flywheel, gearbox input) appears at the
//!   carrier as J_r = J_e i^2. With the carrier equation J_r d(omega_c)/dt = T_w - T_out, the
//!   axles' mean equations I_i d(omega_i)/dt = s_i T_out - L_i (I_i the axle's spin inertia, L_i
//!   its tyre and brake load torque) give the closed form of `axle_accelerations`. With J_e = 0
//!   it is I_i d(omega_i)/dt = s_i T_w - L_i, the model without a powertrain. The clutch is taken
//!   as engaged for the inertia (a slipping clutch would decouple the engine; neglected).
//! - **Differential** (per driven axle of a four-wheel model; a bicycle's axle has one spin speed,
//!   so its differential has nothing to do): the axle's mean speed follows the equation above;
//!   the difference of its wheels d = omega_L - omega_R follows
//!   I_w dd/dt = -M - (L_L - L_R) (open: M = 0; limited-slip: the friction torque M, at most
//!   (TBR - 1)/(TBR + 1) |T_axle| with TBR the torque bias ratio, so that the slower wheel gets up
//!   to TBR times the faster one's torque, regularised linearly over |d| < omega_eps as the
//!   brakes are, [`super::wheel`]); locked: d stays 0 (both wheels get the axle's mean
//!   acceleration).
//!
//! The default (no `[powertrain]` in the vehicle file) is [`None`] in
//! [`crate::vehicle::Vehicle::powertrain`]: the engine is the torque source of the single
//! limit `drive_torque_max_nm` (the PID's clamp), no driveline inertia beyond the wheel's own, open
//! differentials; the models then take their unchanged code path, bit for bit.

use super::wheel::TORQUE_RATE_MAX;

/// Where the torque comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum TorqueSource {
    /// Combustion engine: the full-load curve as (engine speed rad/s, torque N m) points, speeds
    /// strictly increasing, and a power cap, W (infinite for none).
    Engine {
        /// Full-load curve as (engine speed rad/s, torque N m) points, speeds strictly increasing;
        /// the last speed is the rev limit.
        curve: Vec<(f64, f64)>,
        /// Power cap, W (infinite for none).
        power_max_w: f64,
    },
    /// Electric motor: constant torque up to the base speed P / T, then constant power, up to
    /// the top speed (rad/s).
    Motor {
        /// Torque up to the base speed, N m (> 0).
        torque_max_nm: f64,
        /// Power above the base speed, W (> 0).
        power_max_w: f64,
        /// Top speed, rad/s; no torque above it.
        speed_max_radps: f64,
    },
}

/// Gear selection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GearMode {
    /// This gear (index into the ratios, 0 = first) all the time.
    Fixed(usize),
    /// The gear with the most wheel torque at the present speed (see the module docs).
    Auto,
}

/// Differential of a driven axle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Differential {
    /// Open: the wheels of the axle share its torque equally and may turn at different speeds.
    Open,
    /// Locked: both wheels of the axle turn at the same speed.
    Locked,
    /// Torque-sensing limited slip with the torque bias ratio TBR >= 1.
    LimitedSlip {
        /// Torque bias ratio TBR: the slower wheel gets up to TBR times the faster one's torque (>= 1).
        torque_bias_ratio: f64,
    },
}

/// A validated powertrain.
#[derive(Debug, Clone, PartialEq)]
pub struct Powertrain {
    /// The torque source: engine curve or electric motor.
    pub source: TorqueSource,
    /// Gearbox ratios, first gear first (> 0); a motor with a single reduction has one.
    pub gear_ratios: Vec<f64>,
    /// Final-drive ratio (> 0); the overall ratio is gear ratio x final-drive ratio.
    pub final_drive_ratio: f64,
    /// Driveline efficiency from the engine to the wheels, (0, 1].
    pub efficiency: f64,
    /// Engine-side rotating inertia (engine, flywheel, gearbox input), kg m^2.
    pub engine_inertia_kgm2: f64,
    /// Gear selection: a fixed gear or the automatic schedule.
    pub gear: GearMode,
    /// Differential of each driven axle.
    pub differential: Differential,
    /// The automatic schedule as (carrier speed from which it holds, rad/s; gear), ascending;
    /// computed once by [`Powertrain::new`] (one entry for a fixed gear).
    schedule: Vec<(f64, usize)>,
}

impl TorqueSource {
    /// Full-load torque at engine speed `omega` (rad/s, >= 0), N m.
    pub fn torque_nm(&self, omega: f64) -> f64 {
        match self {
            TorqueSource::Engine { curve, power_max_w } => {
                let (w0, t0) = curve[0];
                let (wn, _) = curve[curve.len() - 1];
                let t = if omega <= w0 {
                    t0
                } else if omega > wn {
                    0.0
                } else {
                    let k = curve.partition_point(|p| p.0 < omega).clamp(1, curve.len() - 1);
                    let ((wa, ta), (wb, tb)) = (curve[k - 1], curve[k]);
                    ta + (tb - ta) * (omega - wa) / (wb - wa)
                };
                if omega > 0.0 {
                    t.min(power_max_w / omega)
                } else {
                    t
                }
            }
            TorqueSource::Motor { torque_max_nm, power_max_w, speed_max_radps } => {
                if omega > *speed_max_radps {
                    0.0
                } else if omega > 0.0 {
                    torque_max_nm.min(power_max_w / omega)
                } else {
                    *torque_max_nm
                }
            }
        }
    }

    /// Highest engine speed with torque (rev limiter or motor top speed), rad/s.
    pub fn speed_max_radps(&self) -> f64 {
        match self {
            TorqueSource::Engine { curve, .. } => curve[curve.len() - 1].0,
            TorqueSource::Motor { speed_max_radps, .. } => *speed_max_radps,
        }
    }

    /// Largest torque anywhere on the curve, N m.
    pub fn peak_torque_nm(&self) -> f64 {
        match self {
            TorqueSource::Engine { curve, .. } => curve.iter().map(|p| p.1).fold(0.0, f64::max),
            TorqueSource::Motor { torque_max_nm, .. } => *torque_max_nm,
        }
    }
}

impl Powertrain {
    /// A powertrain, with the automatic schedule's shift speeds found once (where the gear of
    /// most wheel torque changes, located to 1e-9 relative by bisection between the points of a
    /// fine scan of the carrier speed up to the top gear's limit).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        source: TorqueSource,
        gear_ratios: Vec<f64>,
        final_drive_ratio: f64,
        efficiency: f64,
        engine_inertia_kgm2: f64,
        gear: GearMode,
        differential: Differential,
    ) -> Self {
        let mut p = Powertrain {
            source,
            gear_ratios,
            final_drive_ratio,
            efficiency,
            engine_inertia_kgm2,
            gear,
            differential,
            schedule: Vec::new(),
        };
        p.schedule = match gear {
            GearMode::Fixed(g) => vec![(0.0, g)],
            GearMode::Auto => {
                let top = (0..p.gear_ratios.len()).map(|g| p.overall_ratio(g)).fold(f64::INFINITY, f64::min);
                let w_max = p.source.speed_max_radps() / top;
                const SCAN: usize = 2_000;
                let mut schedule = vec![(0.0, p.best_gear(0.0))];
                let mut prev = 0.0;
                for k in 1..=SCAN + 1 {
                    let w = w_max * k as f64 / SCAN as f64;
                    let g = p.best_gear(w);
                    let last = schedule[schedule.len() - 1].1;
                    if g != last {
                        let (mut lo, mut hi) = (prev, w);
                        while hi - lo > 1e-9 * hi.max(1.0) {
                            let mid = 0.5 * (lo + hi);
                            if p.best_gear(mid) == last {
                                lo = mid;
                            } else {
                                hi = mid;
                            }
                        }
                        schedule.push((hi, p.best_gear(hi)));
                    }
                    prev = w;
                }
                schedule
            }
        };
        p
    }

    /// The gear with the most wheel torque at carrier speed `omega_c` below the rev limit (the
    /// top gear when every gear is beyond it); ties to the lower gear.
    fn best_gear(&self, omega_c: f64) -> usize {
        let w = omega_c.max(0.0);
        let mut best = (0, f64::NEG_INFINITY);
        for g in 0..self.gear_ratios.len() {
            let i = self.overall_ratio(g);
            if i * w > self.source.speed_max_radps() {
                continue;
            }
            let t = i * self.source.torque_nm(i * w);
            // a higher gear only for more torque beyond rounding (on the power cap every gear
            // gives P / omega_c: a tie, kept in the lower gear)
            if best.1 == f64::NEG_INFINITY || t > best.1 + 1e-9 * best.1.abs() {
                best = (g, t);
            }
        }
        if best.1 == f64::NEG_INFINITY {
            self.gear_ratios.len() - 1
        } else {
            best.0
        }
    }

    /// Overall ratio engine / carrier in gear `g`.
    pub fn overall_ratio(&self, g: usize) -> f64 {
        self.gear_ratios[g] * self.final_drive_ratio
    }

    /// The gear in use at carrier speed `omega_c` (rad/s): the fixed gear, or the automatic
    /// schedule's (precomputed by [`Powertrain::new`]).
    pub fn gear_at(&self, omega_c: f64) -> usize {
        let mut g = self.schedule[0].1;
        for &(w, gear) in &self.schedule[1..] {
            if omega_c < w {
                break;
            }
            g = gear;
        }
        g
    }

    /// Full-load torque at the driven wheels (sum over them), N m, and the engine-side inertia
    /// reflected to the carrier J_e i^2, kg m^2, at carrier speed `omega_c` (rad/s).
    pub fn at_carrier_speed(&self, omega_c: f64) -> (f64, f64) {
        let g = self.gear_at(omega_c);
        let i = self.overall_ratio(g);
        let te = self.source.torque_nm(i * omega_c.max(0.0));
        (self.efficiency * i * te, self.engine_inertia_kgm2 * i * i)
    }

    /// Largest torque the powertrain can put at the wheels (first gear, peak torque), N m.
    pub fn wheel_torque_max_nm(&self) -> f64 {
        let i_max = (0..self.gear_ratios.len()).map(|g| self.overall_ratio(g)).fold(0.0, f64::max);
        self.efficiency * i_max * self.source.peak_torque_nm()
    }

    /// Regularisation speed of a limited-slip differential's friction torque on an axle of
    /// wheels of inertia `wheel_inertia` (kg m^2) taking at most `axle_torque_max` (N m), rad/s:
    /// the coupling's rate on the wheels' speed difference stays below
    /// [`TORQUE_RATE_MAX`], as the brakes' does.
    pub fn lsd_omega_eps(&self, axle_torque_max: f64, wheel_inertia: f64) -> f64 {
        match self.differential {
            Differential::LimitedSlip { torque_bias_ratio } => {
                let m = axle_torque_max * bias_fraction(torque_bias_ratio);
                (m / (wheel_inertia * TORQUE_RATE_MAX)).max(1e-3)
            }
            _ => 1.0,
        }
    }
}

/// (TBR - 1) / (TBR + 1): the largest friction torque of a limited-slip differential as a
/// fraction of its input torque.
pub(crate) fn bias_fraction(torque_bias_ratio: f64) -> f64 {
    (torque_bias_ratio - 1.0) / (torque_bias_ratio + 1.0)
}

/// The axles' mean spin accelerations d(omega_i)/dt, rad/s^2, with the driveline: torque `t_w`
/// (N m) at the carrier, drive shares `shares`, axle spin inertias `inertia` (kg m^2), the axles'
/// load torques `load` (N m: tyre force times radius plus brake and rolling resistance) and the
/// reflected engine inertia `j_r` (kg m^2). From J_r d(omega_c)/dt = T_w - T_out,
/// omega_c = sum s_i omega_i and I_i d(omega_i)/dt = s_i T_out - L_i:
/// T_out = (T_w + J_r sum s_i L_i / I_i) / (1 + J_r sum s_i^2 / I_i).
pub(crate) fn axle_accelerations(t_w: f64, shares: [f64; 2], inertia: [f64; 2], load: [f64; 2], j_r: f64) -> [f64; 2] {
    let (mut num, mut den) = (t_w, 1.0);
    for i in 0..2 {
        num += j_r * shares[i] * load[i] / inertia[i];
        den += j_r * shares[i] * shares[i] / inertia[i];
    }
    let t_out = num / den;
    [0, 1].map(|i| (shares[i] * t_out - load[i]) / inertia[i])
}

/// The spin accelerations of an axle's left and right wheels (rad/s^2) from its mean acceleration
/// `mean` (rad/s^2, [`axle_accelerations`]), its differential, the wheels' load torques
/// `(l_left, l_right)` (N m), their speeds `(w_left, w_right)` (rad/s), the wheel inertia
/// `wheel_inertia` (kg m^2), the torque into the axle `axle_torque` (N m; 0 for an undriven axle,
/// whose wheels turn freely) and the limited-slip regularisation speed `omega_eps` (rad/s).
#[allow(clippy::too_many_arguments)]
pub(crate) fn wheel_accelerations(
    mean: f64,
    diff: Differential,
    driven: bool,
    (l_left, l_right): (f64, f64),
    (w_left, w_right): (f64, f64),
    wheel_inertia: f64,
    axle_torque: f64,
    omega_eps: f64,
) -> (f64, f64) {
    let friction = match (driven, diff) {
        (true, Differential::Locked) => return (mean, mean),
        (true, Differential::LimitedSlip { torque_bias_ratio }) => {
            axle_torque.abs() * bias_fraction(torque_bias_ratio) * ((w_left - w_right) / omega_eps).clamp(-1.0, 1.0)
        }
        _ => 0.0,
    };
    let diff_rate = (-friction - (l_left - l_right)) / wheel_inertia;
    (mean + 0.5 * diff_rate, mean - 0.5 * diff_rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn engine() -> Powertrain {
        let rpm = std::f64::consts::PI / 30.0;
        Powertrain::new(
            TorqueSource::Engine {
                curve: vec![(1000.0 * rpm, 150.0), (4000.0 * rpm, 250.0), (6500.0 * rpm, 200.0)],
                power_max_w: 110e3,
            },
            vec![3.5, 2.0, 1.3, 1.0],
            4.0,
            0.9,
            0.2,
            GearMode::Auto,
            Differential::Open,
        )
    }

    #[test]
    fn curve_power_cap_and_limits() {
        let rpm = std::f64::consts::PI / 30.0;
        let p = engine();
        // below the first point: held (clutch slip); between: linear; above the last: none
        assert_eq!(p.source.torque_nm(0.0), 150.0);
        assert!((p.source.torque_nm(2500.0 * rpm) - 200.0).abs() < 1e-9);
        assert_eq!(p.source.torque_nm(7000.0 * rpm), 0.0);
        // the power cap: at 6000 rpm the curve gives 210 N m, 132 kW > 110 kW
        let w = 6000.0 * rpm;
        assert!((p.source.torque_nm(w) - 110e3 / w).abs() < 1e-9);
        let m = TorqueSource::Motor { torque_max_nm: 300.0, power_max_w: 150e3, speed_max_radps: 1500.0 };
        assert_eq!(m.torque_nm(100.0), 300.0);
        assert!((m.torque_nm(1000.0) - 150.0).abs() < 1e-12);
        assert_eq!(m.torque_nm(1600.0), 0.0);
    }

    #[test]
    fn auto_gear_takes_the_most_wheel_torque_and_stays_below_the_limiter() {
        let p = engine();
        assert_eq!(p.gear_at(0.0), 0);
        let mut last = 0;
        for k in 0..400 {
            let w = k as f64 * 0.5;
            let g = p.gear_at(w);
            assert!(g >= last, "downshift while accelerating at {w}");
            last = g;
            let i = p.overall_ratio(g);
            assert!(i * w <= p.source.speed_max_radps() || g == 3);
            for h in 0..4 {
                let ih = p.overall_ratio(h);
                if ih * w <= p.source.speed_max_radps() {
                    let (t, th) = (i * p.source.torque_nm(i * w), ih * p.source.torque_nm(ih * w));
                    assert!(t >= th * (1.0 - 1e-9), "{w}: gear {g} {t}, gear {h} {th}");
                }
            }
        }
        assert_eq!(last, 3);
        assert!(p.schedule.len() <= 4, "{:?}", p.schedule);
        // the precomputed schedule is the scan's argmax away from the shift points
        for k in 0..4000 {
            let w = k as f64 * 0.0537;
            let near = p.schedule.iter().any(|s| (s.0 - w).abs() < 1e-6);
            assert!(near || p.gear_at(w) == p.best_gear(w), "at {w}");
        }
        // wheel torque continuous across the shifts (max of continuous functions)
        let f = |w: f64| p.at_carrier_speed(w).0;
        for k in 1..4000 {
            let w = k as f64 * 0.05;
            assert!((f(w + 1e-6) - f(w)).abs() < 1.0, "jump at {w}");
        }
    }

    #[test]
    fn reflected_inertia_closed_forms() {
        // one driven axle: (I + J_r) dw = T - L
        let a = axle_accelerations(1000.0, [1.0, 0.0], [2.4, 2.4], [300.0, 50.0], 40.0);
        assert!((a[0] - 700.0 / 42.4).abs() < 1e-12);
        assert!((a[1] + 50.0 / 2.4).abs() < 1e-12);
        // no engine inertia: each axle its share
        let a = axle_accelerations(1000.0, [0.4, 0.6], [2.0, 3.0], [100.0, 200.0], 0.0);
        assert!((a[0] - 300.0 / 2.0).abs() < 1e-12 && (a[1] - 400.0 / 3.0).abs() < 1e-12);
        // split drive with inertia: the carrier balance J_r dwc = T - T_out holds
        let (s, ii, l, j) = ([0.4, 0.6], [2.0, 3.0], [100.0, 200.0], 30.0);
        let a = axle_accelerations(1000.0, s, ii, l, j);
        let t_out0 = (ii[0] * a[0] + l[0]) / s[0];
        let t_out1 = (ii[1] * a[1] + l[1]) / s[1];
        assert!((t_out0 - t_out1).abs() < 1e-9);
        assert!((j * (s[0] * a[0] + s[1] * a[1]) - (1000.0 - t_out0)).abs() < 1e-9);
    }

    #[test]
    fn differentials_split_as_stated() {
        // split mu: the left wheel's tyre carries 100 N m, the right one 600 N m
        let (l, w) = ((100.0, 600.0), (50.0, 50.0));
        let (a, b) = wheel_accelerations(10.0, Differential::Locked, true, l, w, 1.2, 1000.0, 2.0);
        assert_eq!((a, b), (10.0, 10.0));
        let (a, b) = wheel_accelerations(10.0, Differential::Open, true, l, w, 1.2, 1000.0, 2.0);
        assert!((a - b - 500.0 / 1.2).abs() < 1e-9 && (0.5 * (a + b) - 10.0).abs() < 1e-12);
        // LSD with the left wheel spinning faster: friction moves torque to the right wheel
        let tbr = Differential::LimitedSlip { torque_bias_ratio: 3.0 };
        let (a, b) = wheel_accelerations(10.0, tbr, true, l, (60.0, 50.0), 1.2, 1000.0, 2.0);
        // friction 1000 * 0.5 = 500 at full lock: T_L = 250, T_R = 750, ratio 3 = TBR
        assert!((a - b - (-500.0 - (100.0 - 600.0)) / 1.2).abs() < 1e-9);
        assert!((bias_fraction(3.0) - 0.5).abs() < 1e-15 && bias_fraction(1.0) == 0.0);
    }
}
