//! The replay model: a lateral single-track (bicycle) model driven by the measured steer and the
//! measured forward speed, with the candidate effects as optional extensions.
//!
//! The forward speed is prescribed exactly (interpolated measured vx), not tracked by a PID: the
//! discrepancy workflow must compare lateral dynamics, and a speed-tracking error would show up as a
//! spurious residual. Tyre forces come from the vehicle's tyre provider (`crate::tyre`), each axle
//! carrying two identical tyres. State (4): vy (m/s), r (rad/s), and the front and rear axle lateral
//! forces Fy_f, Fy_r (N) used when the tyre relaxation effect is on.
//!
//! Equations (body frame, ISO 8855, small longitudinal forces neglected):
//!
//!   m (dvy/dt + r vx) = Fy_f cos(delta_e) + Fy_r
//!   I_z dr/dt         = a Fy_f cos(delta_e) - b Fy_r
//!   alpha_f = delta_e - atan((vy + a r) / vx),  alpha_r = -atan((vy - b r) / vx)
//!
//! Effects (all off by default; each default gives the baseline exactly):
//! - `tyre_relaxation`: dFy/dt = (|vx| / sigma_y) (Fy_ss(alpha) - Fy), relaxation length sigma_y (m);
//!   sigma_y = 0 uses the steady-state force directly.
//! - `steer_compliance`: delta_e = delta - c_s Fy_f, c_s in rad/kN of front axle lateral force
//!   (solved by fixed-point iteration when relaxation is off, from the lagged force otherwise).
//! - `friction_change`: surface friction mu_e = s_mu mu on the whole run, s_mu dimensionless.
//! - `load_transfer`: lateral load transfer dFz = m ay_ss h_lt / track per axle in proportion to its
//!   static load, with ay_ss = vx r; each tyre of an axle is evaluated at its own load, so the tyre's
//!   load sensitivity lowers the axle force. h_lt is the effective transfer height (m).
//! - `sensor_bias`: constant offsets added to the simulated yaw-rate and lateral-acceleration
//!   sensors, b_r (rad/s) and b_ay (m/s^2).

use nalgebra::SVector;

use super::measured::MeasuredRun;
use crate::sim::integrator::rk4_step;
use crate::spec::vehicle::Vehicle;
use crate::tyre::TyreInput;

/// Parameters of every candidate effect; the default is the baseline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectParams {
    /// Lateral relaxation length, m (0 = off; typical 0.3-1.5 m).
    pub sigma_y_m: f64,
    /// Steer compliance, rad per kN of front axle lateral force (0 = off; typical 0.001-0.01).
    pub steer_compliance_rad_per_kn: f64,
    /// Friction scale on the nominal surface mu (1 = off; typical 0.3-1.5).
    pub mu_scale: f64,
    /// Effective lateral load-transfer height, m (0 = off; typical 0.3-0.8).
    pub load_transfer_height_m: f64,
    /// Yaw-rate sensor offset, rad/s (typical |b| < 0.05).
    pub bias_yaw_rate_radps: f64,
    /// Lateral-acceleration sensor offset, m/s^2 (typical |b| < 0.5).
    pub bias_ay_mps2: f64,
}

impl Default for EffectParams {
    fn default() -> Self {
        Self {
            sigma_y_m: 0.0,
            steer_compliance_rad_per_kn: 0.0,
            mu_scale: 1.0,
            load_transfer_height_m: 0.0,
            bias_yaw_rate_radps: 0.0,
            bias_ay_mps2: 0.0,
        }
    }
}

/// Simulated channels at the measured sample times.
#[derive(Debug, Clone, Default)]
pub struct Simulated {
    pub yaw_rate: Vec<f64>,
    pub ay: Vec<f64>,
    pub vy: Vec<f64>,
    /// Front axle slip angle, rad.
    pub alpha_f: Vec<f64>,
    /// False when the state went non-finite (the rest of the run is then held at the last value).
    pub ok: bool,
}

/// Floor on |vx| in slip denominators, m/s.
const V_FLOOR: f64 = 1.0;
/// Largest integration step, s.
const H_MAX: f64 = 0.005;

/// The replay model for one vehicle.
#[derive(Debug, Clone)]
pub struct ReplayModel {
    pub vehicle: Vehicle,
    fz_axle: [f64; 2],
}

/// Inputs held over one integration step.
#[derive(Debug, Clone, Copy)]
struct Drive {
    steer: f64,
    vx: f64,
    mu: f64,
    temp_c: f64,
}

impl ReplayModel {
    pub fn new(vehicle: Vehicle) -> Self {
        let (ff, fr) = vehicle.static_axle_loads_n();
        Self { vehicle, fz_axle: [ff, fr] }
    }

    /// Steady-state axle lateral force (two tyres) at slip angle `alpha`, with load transfer `dfz`
    /// across the axle (N, added to the left tyre, taken from the right).
    fn axle_force(&self, axle: usize, alpha: f64, dfz: f64, d: &Drive, p: &EffectParams) -> f64 {
        let half = 0.5 * self.fz_axle[axle];
        let eval = |fz: f64| {
            let input = TyreInput {
                fz_n: fz.max(0.0),
                kappa: 0.0,
                alpha_rad: alpha,
                camber_rad: 0.0,
                vx_mps: d.vx.abs().max(V_FLOOR),
                mu_surface: d.mu * p.mu_scale,
                surface_temp_c: d.temp_c,
                contact_temp_c: d.temp_c,
            };
            if input.fz_n <= 0.0 {
                0.0
            } else {
                self.vehicle.tyre.model.forces(&input).fy_n
            }
        };
        if dfz == 0.0 {
            2.0 * eval(half)
        } else {
            let dz = dfz.clamp(-half, half);
            eval(half + dz) + eval(half - dz)
        }
    }

    fn load_transfer(&self, axle: usize, vx: f64, r: f64, p: &EffectParams) -> f64 {
        if p.load_transfer_height_m == 0.0 {
            return 0.0;
        }
        let v = &self.vehicle;
        let total = self.fz_axle[0] + self.fz_axle[1];
        v.mass_kg * vx * r * p.load_transfer_height_m / v.track_m * self.fz_axle[axle] / total
    }

    /// Steady-state axle forces and the effective steer for state (vy, r) and lagged forces.
    fn forces(&self, x: &SVector<f64, 4>, d: &Drive, p: &EffectParams) -> ([f64; 2], f64) {
        let v = &self.vehicle;
        let (vy, r) = (x[0], x[1]);
        let vxs = d.vx.abs().max(V_FLOOR);
        let beta_f = ((vy + v.a_m * r) / vxs).atan();
        let alpha_r = -((vy - v.b_m * r) / vxs).atan();
        let dfz = [self.load_transfer(0, d.vx, r, p), self.load_transfer(1, d.vx, r, p)];
        let fyr = self.axle_force(1, alpha_r, dfz[1], d, p);
        let c = p.steer_compliance_rad_per_kn * 1e-3;
        let mut delta_e = d.steer;
        let fyf = if c == 0.0 {
            self.axle_force(0, d.steer - beta_f, dfz[0], d, p)
        } else if p.sigma_y_m > 0.0 {
            delta_e = d.steer - c * x[2];
            self.axle_force(0, delta_e - beta_f, dfz[0], d, p)
        } else {
            // Fixed point on Fy_f = F(delta - c Fy_f - beta_f), damped.
            let mut f = self.axle_force(0, d.steer - beta_f, dfz[0], d, p);
            for _ in 0..4 {
                let de = d.steer - c * f;
                let g = self.axle_force(0, de - beta_f, dfz[0], d, p);
                f = 0.5 * (f + g);
            }
            delta_e = d.steer - c * f;
            f
        };
        ([fyf, fyr], delta_e)
    }

    fn derivatives(&self, x: &SVector<f64, 4>, d: &Drive, p: &EffectParams) -> SVector<f64, 4> {
        let v = &self.vehicle;
        let (fss, delta_e) = self.forces(x, d, p);
        let (fyf, fyr) = if p.sigma_y_m > 0.0 { (x[2], x[3]) } else { (fss[0], fss[1]) };
        let cf = delta_e.cos();
        let mut dx = SVector::<f64, 4>::zeros();
        dx[0] = (fyf * cf + fyr) / v.mass_kg - x[1] * d.vx;
        dx[1] = (v.a_m * fyf * cf - v.b_m * fyr) / v.yaw_inertia_kgm2;
        if p.sigma_y_m > 0.0 {
            let rate = d.vx.abs().max(V_FLOOR) / p.sigma_y_m;
            dx[2] = rate * (fss[0] - x[2]);
            dx[3] = rate * (fss[1] - x[3]);
        }
        dx
    }

    /// Lateral acceleration (body frame, at the CG) of a state, m/s^2.
    fn ay(&self, x: &SVector<f64, 4>, d: &Drive, p: &EffectParams) -> (f64, f64) {
        let (fss, delta_e) = self.forces(x, d, p);
        let (fyf, fyr) = if p.sigma_y_m > 0.0 { (x[2], x[3]) } else { (fss[0], fss[1]) };
        (
            (fyf * delta_e.cos() + fyr) / self.vehicle.mass_kg,
            delta_e - ((x[0] + self.vehicle.a_m * x[1]) / d.vx.abs().max(V_FLOOR)).atan(),
        )
    }

    /// Replay a measured run: steer and vx interpolated linearly between samples (held over each
    /// sub-step at its midpoint), starting from the first sample's measured yaw rate and lateral
    /// velocity (vy from the optional channel, else 0).
    pub fn simulate(&self, run: &MeasuredRun, p: &EffectParams) -> Simulated {
        let n = run.t.len();
        let mut out = Simulated { ok: true, ..Default::default() };
        out.yaw_rate.reserve(n);
        out.ay.reserve(n);
        let mut x = SVector::<f64, 4>::zeros();
        x[0] = run.channel("vy").map_or(0.0, |v| v[0]);
        x[1] = run.yaw_rate[0] - p.bias_yaw_rate_radps;
        let drive_at = |k: usize, frac: f64| {
            let k1 = (k + 1).min(n - 1);
            Drive {
                steer: run.steer[k] + frac * (run.steer[k1] - run.steer[k]),
                vx: run.vx[k] + frac * (run.vx[k1] - run.vx[k]),
                mu: run.mu,
                temp_c: run.ice_temp_c,
            }
        };
        if p.sigma_y_m > 0.0 {
            let (f, _) = self.forces(&x, &drive_at(0, 0.0), p);
            x[2] = f[0];
            x[3] = f[1];
        }
        for k in 0..n {
            let d = drive_at(k, 0.0);
            let (ay, af) = self.ay(&x, &d, p);
            out.yaw_rate.push(x[1] + p.bias_yaw_rate_radps);
            out.ay.push(ay + p.bias_ay_mps2);
            out.vy.push(x[0]);
            out.alpha_f.push(af);
            if k + 1 == n {
                break;
            }
            let dt = run.t[k + 1] - run.t[k];
            // Keep h below the relaxation time sigma / vx (RK4 stability with margin).
            let vmax = run.vx[k].abs().max(run.vx[(k + 1).min(n - 1)].abs()).max(V_FLOOR);
            let hmax = if p.sigma_y_m > 0.0 { H_MAX.min(p.sigma_y_m / vmax) } else { H_MAX };
            let m = ((dt / hmax).ceil() as usize).clamp(1, 10_000);
            let h = dt / m as f64;
            for j in 0..m {
                let dj = drive_at(k, (j as f64 + 0.5) / m as f64);
                let (next, _) = rk4_step(|s: &SVector<f64, 4>| self.derivatives(s, &dj, p), &x, h);
                x = next;
            }
            if !x.iter().all(|v| v.is_finite()) || x[0].abs() > 1e3 || x[1].abs() > 1e2 {
                out.ok = false;
                // Hold the last good values so the residual stays finite (and large).
                let (lr, la, lv, lf) = (out.yaw_rate[k], out.ay[k], out.vy[k], out.alpha_f[k]);
                while out.yaw_rate.len() < n {
                    out.yaw_rate.push(lr);
                    out.ay.push(la);
                    out.vy.push(lv);
                    out.alpha_f.push(lf);
                }
                break;
            }
        }
        out
    }
}
