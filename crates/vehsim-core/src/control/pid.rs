//! PID controller with output limits and anti-windup, used for speed control.
//!
//! u = Kp e + Ki integral(e) - Kd d(measurement)/dt, clamped to [out_min, out_max]. The derivative acts
//! on the measurement (no kick when the set point jumps). Anti-windup by conditional integration:
//! the integral is frozen while the output is saturated and the error would drive it further
//! into saturation. For speed control the output is a wheel torque, N m: positive drives, negative
//! brakes.

/// PID gains (units of the output per unit of the error: for speed control N m per m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct PidParams {
    /// Proportional gain, N m per (m/s) (typical 500–3000 for a passenger car).
    pub kp: f64,
    /// Integral gain, N m per (m/s) per s (typical 100–2000).
    pub ki: f64,
    /// Derivative gain on the measurement, N m per (m/s^2) (typical 0–200).
    #[cfg_attr(feature = "serde", serde(default))]
    pub kd: f64,
}

impl Default for PidParams {
    fn default() -> Self {
        Self { kp: 2000.0, ki: 1000.0, kd: 0.0 }
    }
}

/// PID state.
#[derive(Debug, Clone, PartialEq)]
pub struct Pid {
    /// The gains.
    pub params: PidParams,
    /// Lower output limit (speed control: the largest brake torque, negative), N m.
    pub out_min: f64,
    /// Upper output limit (speed control: the largest drive torque), N m.
    pub out_max: f64,
    integral: f64,
    prev_measurement: Option<f64>,
    /// Error at the previous sample (the trapezoidal integral's other end).
    prev_error: Option<f64>,
}

impl Pid {
    /// A controller at rest (zero integral, no previous sample) with its output clamped to `out_min..=out_max`.
    pub fn new(params: PidParams, out_min: f64, out_max: f64) -> Self {
        Self { params, out_min, out_max, integral: 0.0, prev_measurement: None, prev_error: None }
    }

    /// Start with the integral preloaded so that the output equals `u0` at zero error (bumpless start).
    pub fn preload(&mut self, u0: f64) {
        if self.params.ki > 0.0 {
            self.integral = u0.clamp(self.out_min, self.out_max) / self.params.ki;
        }
    }

    /// One controller sample after `h` seconds; returns the clamped output.
    pub fn update(&mut self, setpoint: f64, measurement: f64, h: f64) -> f64 {
        let p = &self.params;
        let e = setpoint - measurement;
        let d = match self.prev_measurement {
            Some(prev) if h > 0.0 => -(measurement - prev) / h,
            _ => 0.0,
        };
        self.prev_measurement = Some(measurement);
        // Trapezoidal integral over the sample interval (the first sample: the rectangle).
        let candidate = self.integral + 0.5 * (e + self.prev_error.unwrap_or(e)) * h;
        self.prev_error = Some(e);
        let u_try = p.kp * e + p.ki * candidate + p.kd * d;
        let winding_up = (u_try > self.out_max && e > 0.0) || (u_try < self.out_min && e < 0.0);
        if !winding_up {
            self.integral = candidate;
        }
        (p.kp * e + p.ki * self.integral + p.kd * d).clamp(self.out_min, self.out_max)
    }

    /// Forget the history (used when the controller is switched off, e.g. ISO coast mode).
    pub fn reset(&mut self) {
        self.integral = 0.0;
        self.prev_measurement = None;
        self.prev_error = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// First-order plant dv/dt = u / m: PI control reaches the set point with no steady error.
    #[test]
    fn pi_reaches_setpoint_on_first_order_plant() {
        let mut pid = Pid::new(PidParams { kp: 2.0, ki: 1.0, kd: 0.0 }, -10.0, 10.0);
        let (mut v, h) = (0.0, 0.01);
        for _ in 0..3000 {
            let u = pid.update(1.0, v, h);
            v += h * (u - 0.5) / 1.0; // constant disturbance 0.5 needs integral action
        }
        assert!((v - 1.0).abs() < 1e-4, "v = {v}");
    }

    /// With the output saturated for a long time, the integral does not wind up: once the error
    /// changes sign the output leaves saturation immediately.
    #[test]
    fn anti_windup_releases_immediately() {
        let mut pid = Pid::new(PidParams { kp: 1.0, ki: 1.0, kd: 0.0 }, -1.0, 1.0);
        for _ in 0..10_000 {
            assert_eq!(pid.update(100.0, 0.0, 0.01), 1.0);
        }
        // Error now negative: the output must drop below the limit at once.
        let u = pid.update(0.0, 0.5, 0.01);
        assert!(u < 1.0, "u = {u}: integral wound up");
    }
}
