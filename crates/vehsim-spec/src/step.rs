//! Stepping a run from outside vehsim: inputs set by the caller, and [`StepRun`], a run that owns
//! everything it drives (vehicle model, manoeuvre, contact-temperature estimate, controller
//! limits) so that a caller that cannot hold borrows (the Python package, an FMI co-simulation
//! unit) keeps it between calls.
//!
//! The inputs the caller sets, their units and limits: [`vehsim_core::sim::external`].

use std::mem::ManuallyDrop;

use std::ptr::NonNull;
use vehsim_core::sim::external::{ExternalInputs, Limits};

use crate::maneuver::RunConfig;
use crate::run::{build_maneuver, controls};
use vehsim_core::contact::ContactTemperature;
use vehsim_core::error::{Error, Result};
use vehsim_core::event::EndReason;
use vehsim_core::event::Event;
use vehsim_core::maneuver::{Maneuver, Outcome};
use vehsim_core::sim::columns::{row_values, COLUMNS};
use vehsim_core::sim::engine::{Controls, Simulation};
use vehsim_core::sim::observer::{NoOutput, Row};
use vehsim_core::vehicle::VehicleModelKind;
use vehsim_core::vehicle::{bicycle, roll4dof, Bicycle, Environment, Inputs, Roll4Dof, VehicleModel};

/// What [`StepRun`] needs from an engine whatever its vehicle model.
trait Stepper: Send {
    fn step(&mut self) -> Option<EndReason>;
    fn set_external(&mut self, e: ExternalInputs);
    fn time_s(&self) -> f64;
    fn state(&self) -> &[f64];
    fn state_names(&self) -> Vec<&'static str>;
    fn row(&self) -> Row;
    fn inputs_now(&self) -> Inputs;
    fn events(&self) -> &[Event];
    fn outcome(&self) -> Outcome;
    fn maneuver_end_reason(&self) -> Option<EndReason>;
    fn end_reason(&self) -> Option<EndReason>;
}

/// Everything a [`Simulation`] borrows, kept on the heap by [`Owned`].
struct Parts<M> {
    model: M,
    maneuver: Box<dyn Maneuver>,
    contact: Box<dyn ContactTemperature>,
    controls: Controls,
    observer: NoOutput,
}

/// A [`Simulation`] together with the parts it borrows.
///
/// The parts live in one heap allocation that never moves and is freed only in `drop`, after
/// the simulation (their only borrower) has been dropped; every access to a part after
/// construction goes through the simulation (or through `model`, a shared borrow the simulation
/// holds too), so the borrows the simulation holds are never aliased by a mutable one.
struct Owned<const N: usize, M: VehicleModel<N> + Send + 'static> {
    sim: ManuallyDrop<Simulation<'static, N, M>>,
    model: &'static M,
    env: Environment,
    parts: NonNull<Parts<M>>,
}

// SAFETY: every part the simulation borrows is owned by this value and is Send (M: Send + Sync,
// `dyn Maneuver: Send`, `dyn ContactTemperature: Send`, `NoOutput`); moving the whole to another
// thread moves all borrowers and borrowed parts together.
unsafe impl<const N: usize, M: VehicleModel<N> + Send + 'static> Send for Owned<N, M> {}

impl<const N: usize, M: VehicleModel<N> + Send + 'static> Owned<N, M> {
    fn new(
        parts: Parts<M>,
        env: Environment,
        settings: &vehsim_core::sim::SimSettings,
        slip: &vehsim_core::sim::slip_control::SlipControlParams,
    ) -> Self {
        let raw = Box::into_raw(Box::new(parts));
        // SAFETY: `raw` comes from `Box::into_raw` (non-null, aligned, initialised) and is freed
        // only by `Drop`, after `sim` is dropped; see the type's docs.
        let p: &'static mut Parts<M> = unsafe { &mut *raw };
        let Parts { model, maneuver, contact, controls, observer } = p;
        let model: &'static M = model;
        let sim = Simulation::new(model, env, maneuver.as_mut(), contact.as_mut(), controls, settings, observer)
            .with_slip_control(slip);
        // SAFETY: `raw` is non-null (from a Box).
        let parts = unsafe { NonNull::new_unchecked(raw) };
        Owned { sim: ManuallyDrop::new(sim), model, env, parts }
    }
}

impl<const N: usize, M: VehicleModel<N> + Send + 'static> Drop for Owned<N, M> {
    fn drop(&mut self) {
        // SAFETY: the simulation is dropped exactly once, here, before the parts it borrows; the
        // parts were allocated by `Box` in `new` and are freed exactly once.
        unsafe {
            ManuallyDrop::drop(&mut self.sim);
            drop(Box::from_raw(self.parts.as_ptr()));
        }
    }
}

impl<const N: usize, M: VehicleModel<N> + Send + 'static> Stepper for Owned<N, M> {
    fn step(&mut self) -> Option<EndReason> {
        self.sim.step()
    }
    fn set_external(&mut self, e: ExternalInputs) {
        self.sim.set_external(e);
    }
    fn time_s(&self) -> f64 {
        self.sim.time_s()
    }
    fn state(&self) -> &[f64] {
        self.sim.state().as_slice()
    }
    fn state_names(&self) -> Vec<&'static str> {
        self.model.state_names().to_vec()
    }
    fn inputs_now(&self) -> Inputs {
        self.sim.inputs_now()
    }
    fn row(&self) -> Row {
        let inputs = self.sim.inputs_now();
        Row {
            t_s: self.sim.time_s(),
            obs: self.model.observe(self.sim.state(), &inputs, &self.env),
            inputs,
            speed_target_mps: self.sim.speed_target_mps(),
            path_error_m: self.sim.maneuver().path_error_m().unwrap_or(f64::NAN),
        }
    }
    fn events(&self) -> &[Event] {
        self.sim.events()
    }
    fn outcome(&self) -> Outcome {
        self.sim.maneuver().outcome()
    }
    fn maneuver_end_reason(&self) -> Option<EndReason> {
        self.sim.maneuver().end_reason()
    }
    fn end_reason(&self) -> Option<EndReason> {
        self.sim.end_reason()
    }
}

/// Names of the values of [`StepRun::observation`], units in the names: the columns of
/// `timeseries.csv` (see [`vehsim_core::sim::columns::COLUMNS`]).
pub const OBSERVATION: &[&str] = COLUMNS;

/// One run of a validated spec, stepped by the caller (see the module docs).
pub struct StepRun {
    inner: Box<dyn Stepper>,
    limits: Limits,
    external: ExternalInputs,
    step_s: f64,
    control_period_s: f64,
    duration_s: f64,
    /// Steps the run can take before its time limit.
    max_steps: u64,
}

impl StepRun {
    /// Set up the run `cfg` describes at its start (no step taken; every input from the spec's
    /// controllers). Fails only if the contact-temperature model cannot be built (`vehsim run`
    /// then goes on isothermal and says so in its events; a stepped run refuses instead).
    pub fn new(cfg: &RunConfig) -> Result<Self> {
        let maneuver = build_maneuver(cfg);
        let ctl = controls(cfg, maneuver.start().speed_mps);
        let s = &cfg.settings;
        let inner: Box<dyn Stepper> = match cfg.vehicle_model {
            VehicleModelKind::Bicycle => {
                let model = Bicycle::new(cfg.vehicle.clone()).prepared_for(&cfg.env);
                let contact = cfg.contact.build_for(
                    &cfg.spec_file,
                    &cfg.vehicle.lateral,
                    <Bicycle as VehicleModel<{ bicycle::N }>>::TYRES,
                    cfg.env.surface_temp_c,
                )?;
                let parts = Parts { model, maneuver, contact, controls: ctl, observer: NoOutput };
                Box::new(Owned::<{ bicycle::N }, Bicycle>::new(parts, cfg.env, s, &cfg.slip))
            }
            VehicleModelKind::Roll4Dof => {
                let roll = cfg.vehicle.roll.clone().ok_or_else(|| {
                    Error::key(&cfg.vehicle_file, "roll", "the 4-DOF model needs the vehicle's [roll] table")
                })?;
                let model = Roll4Dof::new(cfg.vehicle.clone(), roll).prepared_for(&cfg.env);
                let contact = cfg.contact.build_for(
                    &cfg.spec_file,
                    &cfg.vehicle.lateral,
                    <Roll4Dof as VehicleModel<{ roll4dof::N }>>::TYRES,
                    cfg.env.surface_temp_c,
                )?;
                let parts = Parts { model, maneuver, contact, controls: ctl, observer: NoOutput };
                Box::new(Owned::<{ roll4dof::N }, Roll4Dof>::new(parts, cfg.env, s, &cfg.slip))
            }
        };
        let max_steps = ((s.duration_s / s.step_s) - 1e-9).ceil().max(0.0) as u64;
        let ctrl_every = ((s.control_period_s / s.step_s).round()).max(1.0);
        Ok(StepRun {
            inner,
            limits: Limits::from(&ctl),
            external: ExternalInputs::default(),
            step_s: s.step_s,
            control_period_s: ctrl_every * s.step_s,
            duration_s: s.duration_s,
            max_steps,
        })
    }

    /// Advance one step; returns why the run ended if it did (further calls then do nothing).
    pub fn step(&mut self) -> Option<EndReason> {
        self.inner.step()
    }

    /// Set the external inputs for the coming steps, after checking them against the vehicle's
    /// limits (on failure nothing changes and the message says what is allowed).
    /// A steer rate starts from the steer angle in force now (so the angle is continuous) at the
    /// current time, stopping at the vehicle's lock.
    pub fn set_inputs(&mut self, mut e: ExternalInputs) -> std::result::Result<(), String> {
        e.check(&self.limits)?;
        if let Some(r) = e.steer_rate.as_mut() {
            r.from_rad = self.inner.inputs_now().steer_rad;
            r.t0_s = self.inner.time_s();
            r.lock_rad = self.limits.steer_max_rad;
        }
        self.external = e;
        self.inner.set_external(e);
        Ok(())
    }

    /// The external inputs in force.
    pub fn inputs(&self) -> ExternalInputs {
        self.external
    }

    /// The actuator limits external inputs are checked against.
    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// Time now, s (k h after k steps).
    pub fn time_s(&self) -> f64 {
        self.inner.time_s()
    }

    /// Integration step, s.
    pub fn step_s(&self) -> f64 {
        self.step_s
    }
    /// Controller sample period, s (a whole number of steps).
    pub fn control_period_s(&self) -> f64 {
        self.control_period_s
    }
    /// Time limit of the run, s (`duration_s`).
    pub fn duration_s(&self) -> f64 {
        self.duration_s
    }
    /// Steps taken so far (time now / step).
    pub fn steps(&self) -> u64 {
        (self.time_s() / self.step_s).round() as u64
    }
    /// Most steps the time limit allows.
    pub fn max_steps(&self) -> u64 {
        self.max_steps
    }

    /// The model's state vector now (its components named by [`Self::state_names`]).
    pub fn state(&self) -> &[f64] {
        self.inner.state()
    }

    /// Names of the state components, in order.
    pub fn state_names(&self) -> Vec<&'static str> {
        self.inner.state_names()
    }

    /// The observation now, in the order of [`OBSERVATION`]: what `vehsim run` would record as a
    /// row at this instant, with the inputs the next step starts from (one model evaluation).
    pub fn observation(&self) -> [f64; 32] {
        row_values(&self.inner.row())
    }

    /// Events so far (cone strikes, spin-out, ...).
    pub fn events(&self) -> &[Event] {
        self.inner.events()
    }

    /// The manoeuvre's verdict so far (pass/fail, cones struck).
    pub fn outcome(&self) -> Outcome {
        self.inner.outcome()
    }

    /// Why the run ended, once it has (the manoeuvre's own reason, such as `left_path`, where it
    /// gives one, as in `summary.json`).
    pub fn end_reason(&self) -> Option<EndReason> {
        let end = self.inner.end_reason()?;
        if end == EndReason::Completed {
            return Some(self.inner.maneuver_end_reason().unwrap_or(end));
        }
        Some(end)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use vehsim_core::sim::external::{SteerRate, Torque};

    fn dlc() -> RunConfig {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../maneuvers/dlc.toml");
        crate::run::load(&path).expect("maneuvers/dlc.toml loads")
    }

    #[test]
    fn stepping_without_external_inputs_reproduces_execute_bit_for_bit() {
        steps_reproduce_execute(&dlc());
        // a run with ABS: the slip controllers step with it
        let abs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../maneuvers/traction/braking_50kmh_ice_abs.toml");
        let cfg = crate::run::load(&abs).expect("the ABS stop loads");
        assert!(!cfg.slip.is_off());
        steps_reproduce_execute(&cfg);
    }

    fn steps_reproduce_execute(cfg: &RunConfig) {
        let cfg = cfg.clone();
        let out = crate::run::execute(&cfg);
        let mut run = StepRun::new(&cfg).unwrap();
        let every = (cfg.settings.output_interval_s / cfg.settings.step_s).round() as u64;
        let (x, vy, r) = (COLUMNS.iter().position(|c| *c == "x_m").unwrap(), 5, 6);
        let mut k = 0u64;
        let mut rows = out.rows.iter();
        loop {
            if k % every == 0 {
                let row = rows.next().unwrap();
                let want = row_values(row);
                let got = run.observation();
                assert_eq!(got[0].to_bits(), want[0].to_bits(), "time at step {k}");
                for i in [x, x + 1, x + 2, x + 3, vy, r] {
                    assert_eq!(got[i].to_bits(), want[i].to_bits(), "{} at step {k}", COLUMNS[i]);
                }
            }
            if run.step().is_some() {
                break;
            }
            k += 1;
        }
        assert_eq!(run.end_reason(), Some(out.summary.end_reason));
        assert_eq!(run.outcome().cones_hit, out.summary.cones_hit);
    }

    #[test]
    fn external_inputs_out_of_the_limits_are_refused_and_change_nothing() {
        let mut run = StepRun::new(&dlc()).unwrap();
        let lim = run.limits();
        for bad in [
            ExternalInputs { steer_rad: Some(lim.steer_max_rad * 1.01), ..Default::default() },
            ExternalInputs { steer_rad: Some(f64::NAN), ..Default::default() },
            ExternalInputs { torque_nm: Some(Torque { drive_nm: -1.0, brake_nm: 0.0 }), ..Default::default() },
            ExternalInputs {
                torque_nm: Some(Torque { drive_nm: 0.0, brake_nm: lim.brake_max_nm + 1.0 }),
                ..Default::default()
            },
        ] {
            let msg = run.set_inputs(bad).unwrap_err();
            assert!(msg.contains("is not allowed; expected a finite number in ["), "{msg}");
            assert_eq!(run.inputs(), ExternalInputs::default());
        }
    }

    #[test]
    fn a_held_steer_rate_ramps_the_angle_exactly_and_stops_at_the_lock() {
        let mut run = StepRun::new(&dlc()).unwrap();
        let lim = run.limits();
        let rate = 0.5 * lim.steer_rate_max_radps;
        let e = ExternalInputs {
            steer_rate: Some(SteerRate { rate_radps: rate, ..Default::default() }),
            ..Default::default()
        };
        run.set_inputs(e).unwrap();
        let steer = COLUMNS.iter().position(|c| *c == "steer_rad").unwrap();
        for _ in 0..10 {
            run.step();
        }
        let t = run.time_s();
        assert!((run.observation()[steer] - rate * t).abs() < 1e-15);
        // long enough to reach the lock: it stays there
        while run.time_s() < 2.0 * lim.steer_max_rad / rate && run.step().is_none() {}
        assert_eq!(run.observation()[steer], lim.steer_max_rad);
        let too_fast = SteerRate { rate_radps: 1.01 * lim.steer_rate_max_radps, ..Default::default() };
        let msg = run.set_inputs(ExternalInputs { steer_rate: Some(too_fast), ..Default::default() }).unwrap_err();
        assert!(msg.starts_with("steer_rate_radps = "), "{msg}");
    }

    #[test]
    fn a_held_external_steer_is_what_the_model_sees() {
        let mut run = StepRun::new(&dlc()).unwrap();
        let e = ExternalInputs {
            steer_rad: Some(0.02),
            torque_nm: Some(Torque { drive_nm: 100.0, brake_nm: 0.0 }),
            ..Default::default()
        };
        run.set_inputs(e).unwrap();
        for _ in 0..50 {
            run.step();
        }
        let o = run.observation();
        let col = |n: &str| o[COLUMNS.iter().position(|c| *c == n).unwrap()];
        assert_eq!(col("steer_rad"), 0.02);
        assert_eq!(col("drive_torque_nm"), 100.0);
        assert_eq!(col("brake_torque_nm"), 0.0);
        // turning left: positive yaw rate (ISO 8855)
        assert!(col("yaw_rate_radps") > 0.0);
    }
}
