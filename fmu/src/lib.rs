//! vehsim as an FMI 2.0 co-simulation FMU: the `fmi2*` C functions over the library's steppable
//! run ([`vehsim_spec::step::StepRun`]), the same engine `vehsim run` steps.
//!
//! Life cycle: `fmi2Instantiate` (checks the GUID and the co-simulation type, keeps the
//! resources folder) -> `fmi2Set*` of parameters -> `fmi2SetupExperiment` ->
//! `fmi2EnterInitializationMode` -> `fmi2ExitInitializationMode` (reads the spec, applies the
//! parameters, builds the run; a missing or bad file is an `fmi2Error` with the library's message
//! logged) -> `fmi2DoStep` (holds the inputs over the communication step and takes as many engine
//! steps as it spans; any step size, variable from call to call, rounded to whole engine steps)
//! -> `fmi2Get*` of outputs -> `fmi2Terminate` / `fmi2Reset` / `fmi2FreeInstance`.
//!
//! Inputs beyond the vehicle's limits or NaN make `fmi2DoStep` return `fmi2Error` with a logged
//! message naming the input and its range. When the run ends before the communication point
//! (the manoeuvre completed, spin-out, the spec's time limit) `fmi2DoStep` returns `fmi2Discard`
//! and `fmi2GetBooleanStatus(fmi2Terminated)` reports true. Every function catches panics and
//! checks its pointers, so no input can unwind into or crash the importing process.

use std::ffi::{c_char, c_double, c_int, c_uint, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use vehsim_core::sim::external::{ExternalInputs, Torque};
use vehsim_core::Error;
use vehsim_spec::files::{parse_toml, read_input};
use vehsim_spec::step::StepRun;
use vehsim_spec::RunConfig;

mod variables;
use variables::{BOOL_IN, OUTPUT_VR0, REAL_IN, STRING_IN};

type Fmi2Status = c_int;
const OK: Fmi2Status = 0;
const WARNING: Fmi2Status = 1;
const DISCARD: Fmi2Status = 2;
const ERROR: Fmi2Status = 3;
const FATAL: Fmi2Status = 4;

/// `fmi2CallbackLogger`: (componentEnvironment, instanceName, status, category, message, ...).
type Logger = unsafe extern "C" fn(*mut c_void, *const c_char, Fmi2Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions` (only the logger and the environment are used).
#[repr(C)]
pub struct CallbackFunctions {
    logger: Option<Logger>,
    allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Fmi2Status)>,
    component_environment: *mut c_void,
}

/// Where the instance is in the FMI life cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Instantiated,
    Initialization,
    Stepping,
    Terminated,
}

/// One FMU instance.
struct Instance {
    name: CString,
    logger: Option<Logger>,
    env: *mut c_void,
    logging_on: bool,
    resources: Option<PathBuf>,
    phase: Phase,
    // parameters
    real: Vec<f64>,
    strings: Vec<String>,
    bools: Vec<bool>,
    start_time: f64,
    run: Option<StepRun>,
    /// The observation at the current communication point (outputs read from it).
    outputs: Vec<f64>,
    terminated: bool,
    warned_rounding: bool,
    /// C copies of the string parameters handed out by fmi2GetString.
    c_strings: Vec<CString>,
}

impl Instance {
    fn log(&self, status: Fmi2Status, msg: &str) {
        if status < ERROR && !self.logging_on {
            return;
        }
        let Some(logger) = self.logger else { return };
        let category = if status >= ERROR { c"logStatusError" } else { c"logStatusWarning" };
        let text = CString::new(msg.replace('\0', " ")).unwrap_or_default();
        // SAFETY: the logger is the importer's callback; every argument is a valid C string and
        // the message goes through "%s", so no '%' in it is read as a format.
        unsafe { logger(self.env, self.name.as_ptr(), status, category.as_ptr(), c"%s".as_ptr(), text.as_ptr()) };
    }

    fn error(&self, msg: &str) -> Fmi2Status {
        self.log(ERROR, msg);
        ERROR
    }

    fn real_param(&self, name: &str) -> f64 {
        REAL_IN.iter().position(|v| v.1 == name).map_or(f64::NAN, |i| self.real[i])
    }
    fn string_param(&self, name: &str) -> &str {
        STRING_IN.iter().position(|v| v.1 == name).map_or("", |i| self.strings[i].as_str())
    }
    fn bool_param(&self, name: &str) -> bool {
        BOOL_IN.iter().position(|v| v.1 == name).is_some_and(|i| self.bools[i])
    }

    /// A parameter path: absolute as given, relative to the resources folder otherwise.
    fn resolve(&self, p: &str) -> PathBuf {
        let p = Path::new(p);
        match &self.resources {
            Some(r) if p.is_relative() => r.join(p),
            _ => p.to_path_buf(),
        }
    }

    /// The validated run of the spec with the parameters applied.
    fn config(&self) -> Result<RunConfig, Error> {
        let file = self.resolve(self.string_param("spec"));
        let mut t: toml::Table = parse_toml(&file, &read_input(&file)?)?;
        let vehicle = self.string_param("vehicle");
        if !vehicle.is_empty() {
            let v = self.resolve(vehicle);
            t.insert("vehicle".into(), toml::Value::String(v.to_string_lossy().into_owned()));
        }
        let tyre = self.string_param("tyre_model");
        if !tyre.is_empty() {
            t.insert("tyre_model".into(), toml::Value::String(tyre.to_string()));
        }
        let surface = t.entry("surface").or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let Some(surface) = surface.as_table_mut() else {
            return Err(Error::key(&file, "surface", "expected a table"));
        };
        surface.insert("mu".into(), toml::Value::Float(self.real_param("mu")));
        surface.insert("temperature_c".into(), toml::Value::Float(self.real_param("surface_temperature_c")));
        let b = vehsim_spec::sweep::from_table(&file, t)?;
        if b.is_sweep() {
            return Err(Error::key(&file, "sweep", "an FMU runs one spec: drop [sweep]"));
        }
        let first = b.runs.into_iter().next().ok_or_else(|| Error::input(&file, "the spec has no run"))?;
        first.config.map_err(|m| Error::input(&file, m))
    }

    /// The external inputs the parameters select, from the input variables.
    fn external(&self) -> ExternalInputs {
        ExternalInputs {
            steer_rad: self.bool_param("external_steer").then(|| self.real_param("steer_cmd_rad")),
            torque_nm: self.bool_param("external_torque").then(|| Torque {
                drive_nm: self.real_param("drive_torque_cmd_nm"),
                brake_nm: self.real_param("brake_torque_cmd_nm"),
            }),
            ..Default::default()
        }
    }

    fn refresh_outputs(&mut self) {
        if let Some(run) = &self.run {
            self.outputs = run.observation()[1..].to_vec();
        }
    }

    fn exit_initialization(&mut self) -> Fmi2Status {
        let cfg = match self.config() {
            Ok(c) => c,
            Err(e) => return self.error(&e.to_string()),
        };
        let mut run = match StepRun::new(&cfg) {
            Ok(r) => r,
            Err(e) => return self.error(&e.to_string()),
        };
        if let Err(m) = run.set_inputs(self.external()) {
            return self.error(&m);
        }
        self.run = Some(run);
        self.refresh_outputs();
        self.phase = Phase::Stepping;
        OK
    }

    fn do_step(&mut self, current: f64, h: f64) -> Fmi2Status {
        if self.phase != Phase::Stepping {
            return self.error("fmi2DoStep: call fmi2ExitInitializationMode first");
        }
        if !(h.is_finite() && h > 0.0 && current.is_finite()) {
            return self
                .error(&format!("fmi2DoStep: communication step {h} at t = {current} is not a positive finite time"));
        }
        let e = self.external();
        let Some(run) = self.run.as_mut() else { return self.error("fmi2DoStep: no run") };
        if let Err(m) = run.set_inputs(e) {
            return self.error(&format!("fmi2DoStep at t = {current} s: {m}"));
        }
        if run.end_reason().is_some() {
            self.terminated = true;
            self.log(WARNING, "fmi2DoStep: the run has already ended");
            return DISCARD;
        }
        let hs = run.step_s();
        // the communication point in engine time, rounded to whole engine steps
        let target = current + h - self.start_time;
        let steps = (target / hs).round();
        let rounded = (steps * hs - target).abs() > 1e-9 * target.abs().max(1.0);
        let mut ended = None;
        while (run.steps() as f64) < steps {
            if let Some(r) = run.step() {
                ended = Some(r);
                break;
            }
        }
        let reached = run.steps() as f64 >= steps;
        let t_now = run.time_s();
        self.refresh_outputs();
        if rounded && !self.warned_rounding {
            self.warned_rounding = true;
            self.log(
                WARNING,
                &format!(
                    "communication point {} s is not a whole number of engine steps ({hs} s): rounded to {t_now} s",
                    current + h
                ),
            );
        }
        match ended {
            Some(r) if !reached => {
                self.terminated = true;
                self.log(
                    WARNING,
                    &format!("the run ended ({}) at t = {t_now} s, before the communication point", r.as_str()),
                );
                DISCARD
            }
            _ => OK,
        }
    }
}

/// Run `f` on the instance behind `c`, turning a null pointer into fmi2Error and a panic into
/// fmi2Fatal.
fn with_instance(c: *mut c_void, f: impl FnOnce(&mut Instance) -> Fmi2Status) -> Fmi2Status {
    if c.is_null() {
        return ERROR;
    }
    // SAFETY: a non-null component is one fmi2Instantiate returned and fmi2FreeInstance has not
    // freed (the FMI standard's contract with the importer).
    let inst = unsafe { &mut *(c as *mut Instance) };
    match catch_unwind(AssertUnwindSafe(|| f(inst))) {
        Ok(s) => s,
        Err(_) => {
            inst.log(FATAL, "internal error (a panic in vehsim); the instance cannot be used further");
            FATAL
        }
    }
}

/// The local path of a `file:` URI (percent-escapes decoded); None for other schemes.
fn file_uri_path(uri: &str) -> Option<PathBuf> {
    let rest = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:"))?;
    // file://host/path: only an empty host or localhost names this machine
    let rest = rest.strip_prefix("localhost").unwrap_or(rest);
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    Some(PathBuf::from(String::from_utf8(out).ok()?))
}

/// # Safety
/// Called by an FMI importer with C strings (or null) and a callback structure (or null).
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    let r = catch_unwind(|| {
        let text = |p: *const c_char| (!p.is_null()).then(|| CStr::from_ptr(p).to_string_lossy().into_owned());
        let (logger, env) = match functions.as_ref() {
            Some(f) => (f.logger, f.component_environment),
            None => (None, std::ptr::null_mut()),
        };
        let name = text(instance_name).unwrap_or_else(|| "vehsim".into());
        let inst = Instance {
            name: CString::new(name.replace('\0', " ")).unwrap_or_default(),
            logger,
            env,
            logging_on: logging_on != 0,
            resources: text(resource_location).and_then(|u| file_uri_path(&u)),
            phase: Phase::Instantiated,
            real: REAL_IN.iter().map(|v| v.3).collect(),
            strings: STRING_IN.iter().map(|v| v.2.to_string()).collect(),
            bools: BOOL_IN.iter().map(|v| v.2).collect(),
            start_time: 0.0,
            run: None,
            outputs: vec![f64::NAN; variables::outputs().len()],
            terminated: false,
            warned_rounding: false,
            c_strings: Vec::new(),
        };
        if fmu_type != 1 {
            inst.log(ERROR, "fmi2Instantiate: this FMU supports co-simulation only (fmi2CoSimulation)");
            return std::ptr::null_mut();
        }
        if text(guid).as_deref() != Some(variables::GUID) {
            inst.log(
                ERROR,
                &format!("fmi2Instantiate: GUID {:?} does not match this FMU's {}", text(guid), variables::GUID),
            );
            return std::ptr::null_mut();
        }
        Box::into_raw(Box::new(inst)) as *mut c_void
    });
    r.unwrap_or(std::ptr::null_mut())
}

/// # Safety
/// `c` is null or an instance from fmi2Instantiate, freed once.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        let _ = catch_unwind(|| drop(Box::from_raw(c as *mut Instance)));
    }
}

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// The text of modelDescription.xml (the packaging script writes it into the FMU).
#[no_mangle]
pub extern "C" fn vehsim_fmu_model_description() -> *const c_char {
    static XML: OnceLock<CString> = OnceLock::new();
    XML.get_or_init(|| CString::new(variables::model_description()).unwrap_or_default()).as_ptr()
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    on: c_int,
    _n: usize,
    _cats: *const *const c_char,
) -> Fmi2Status {
    with_instance(c, |i| {
        i.logging_on = on != 0;
        OK
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tol_defined: c_int,
    _tol: c_double,
    start: c_double,
    _stop_defined: c_int,
    _stop: c_double,
) -> Fmi2Status {
    with_instance(c, |i| {
        if !start.is_finite() {
            return i.error("fmi2SetupExperiment: the start time is not finite");
        }
        i.start_time = start;
        OK
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Fmi2Status {
    with_instance(c, |i| {
        i.phase = Phase::Initialization;
        OK
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Fmi2Status {
    with_instance(c, |i| {
        if i.phase != Phase::Initialization {
            return i.error("fmi2ExitInitializationMode: call fmi2EnterInitializationMode first");
        }
        i.exit_initialization()
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Fmi2Status {
    with_instance(c, |i| {
        i.phase = Phase::Terminated;
        OK
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Fmi2Status {
    with_instance(c, |i| {
        i.phase = Phase::Instantiated;
        i.run = None;
        i.terminated = false;
        i.real = REAL_IN.iter().map(|v| v.3).collect();
        i.strings = STRING_IN.iter().map(|v| v.2.to_string()).collect();
        i.bools = BOOL_IN.iter().map(|v| v.2).collect();
        i.outputs.iter_mut().for_each(|o| *o = f64::NAN);
        OK
    })
}

/// The slices behind an FMI (vr, n, values) triple; None if a pointer is null with n > 0.
unsafe fn slices<'a, T>(vr: *const c_uint, n: usize, v: *mut T) -> Option<(&'a [c_uint], &'a mut [T])> {
    if n == 0 {
        return Some((&[], &mut []));
    }
    if vr.is_null() || v.is_null() {
        return None;
    }
    Some((std::slice::from_raw_parts(vr, n), std::slice::from_raw_parts_mut(v, n)))
}

/// # Safety
/// `vr` and `value` point to `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(c: *mut c_void, vr: *const c_uint, n: usize, value: *mut c_double) -> Fmi2Status {
    with_instance(c, |i| {
        let Some((vr, out)) = slices(vr, n, value) else { return i.error("fmi2GetReal: null pointer") };
        for (r, o) in vr.iter().zip(out.iter_mut()) {
            *o = if let Some(k) = REAL_IN.iter().position(|v| v.0 == *r) {
                i.real[k]
            } else if let Some(v) = r.checked_sub(OUTPUT_VR0).and_then(|k| i.outputs.get(k as usize)) {
                *v
            } else {
                return i.error(&format!("fmi2GetReal: no Real variable has value reference {r}"));
            };
        }
        OK
    })
}

/// # Safety
/// `vr` and `value` point to `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *const c_double,
) -> Fmi2Status {
    with_instance(c, |i| {
        let Some((vr, vals)) = slices(vr, n, value as *mut c_double) else {
            return i.error("fmi2SetReal: null pointer");
        };
        for (r, v) in vr.iter().zip(vals.iter()) {
            let Some(k) = REAL_IN.iter().position(|x| x.0 == *r) else {
                return i.error(&format!("fmi2SetReal: value reference {r} is not a settable Real (an output?)"));
            };
            if REAL_IN[k].2 == "parameter" && i.phase == Phase::Stepping {
                return i.error(&format!(
                    "fmi2SetReal: {} is a fixed parameter; set it before initialization",
                    REAL_IN[k].1
                ));
            }
            i.real[k] = *v;
        }
        OK
    })
}

/// # Safety
/// `vr` and `value` point to `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(c: *mut c_void, vr: *const c_uint, n: usize, _v: *mut c_int) -> Fmi2Status {
    with_instance(c, |i| {
        if n == 0 || vr.is_null() {
            OK
        } else {
            i.error("fmi2GetInteger: this FMU has no Integer variables")
        }
    })
}

/// # Safety
/// `vr` and `value` point to `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(c: *mut c_void, vr: *const c_uint, n: usize, _v: *const c_int) -> Fmi2Status {
    with_instance(c, |i| {
        if n == 0 || vr.is_null() {
            OK
        } else {
            i.error("fmi2SetInteger: this FMU has no Integer variables")
        }
    })
}

/// # Safety
/// `vr` and `value` point to `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(c: *mut c_void, vr: *const c_uint, n: usize, value: *mut c_int) -> Fmi2Status {
    with_instance(c, |i| {
        let Some((vr, out)) = slices(vr, n, value) else { return i.error("fmi2GetBoolean: null pointer") };
        for (r, o) in vr.iter().zip(out.iter_mut()) {
            let Some(k) = BOOL_IN.iter().position(|x| x.0 == *r) else {
                return i.error(&format!("fmi2GetBoolean: no Boolean variable has value reference {r}"));
            };
            *o = i.bools[k] as c_int;
        }
        OK
    })
}

/// # Safety
/// `vr` and `value` point to `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *const c_int,
) -> Fmi2Status {
    with_instance(c, |i| {
        let Some((vr, vals)) = slices(vr, n, value as *mut c_int) else {
            return i.error("fmi2SetBoolean: null pointer");
        };
        if i.phase == Phase::Stepping && n > 0 {
            return i
                .error("fmi2SetBoolean: the Boolean variables are fixed parameters; set them before initialization");
        }
        for (r, v) in vr.iter().zip(vals.iter()) {
            let Some(k) = BOOL_IN.iter().position(|x| x.0 == *r) else {
                return i.error(&format!("fmi2SetBoolean: no Boolean variable has value reference {r}"));
            };
            i.bools[k] = *v != 0;
        }
        OK
    })
}

/// # Safety
/// `vr` and `value` point to `n` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *mut *const c_char,
) -> Fmi2Status {
    with_instance(c, |i| {
        let Some((vr, out)) = slices(vr, n, value) else { return i.error("fmi2GetString: null pointer") };
        // the returned pointers stay valid until the next fmi2GetString or fmi2SetString
        for (r, o) in vr.iter().zip(out.iter_mut()) {
            let Some(k) = STRING_IN.iter().position(|x| x.0 == *r) else {
                return i.error(&format!("fmi2GetString: no String variable has value reference {r}"));
            };
            *o = i.string_cache(k);
        }
        OK
    })
}

impl Instance {
    /// A C copy of string parameter `k`, kept in the instance until the strings change.
    fn string_cache(&mut self, k: usize) -> *const c_char {
        let s = CString::new(self.strings[k].replace('\0', " ")).unwrap_or_default();
        self.c_strings.resize_with(STRING_IN.len(), CString::default);
        self.c_strings[k] = s;
        self.c_strings[k].as_ptr()
    }
}

/// # Safety
/// `vr` and `value` point to `n` elements, each value a C string.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *const *const c_char,
) -> Fmi2Status {
    with_instance(c, |i| {
        let Some((vr, vals)) = slices(vr, n, value as *mut *const c_char) else {
            return i.error("fmi2SetString: null pointer");
        };
        if i.phase == Phase::Stepping && n > 0 {
            return i.error("fmi2SetString: the String variables are fixed parameters; set them before initialization");
        }
        for (r, v) in vr.iter().zip(vals.iter()) {
            let Some(k) = STRING_IN.iter().position(|x| x.0 == *r) else {
                return i.error(&format!("fmi2SetString: no String variable has value reference {r}"));
            };
            if v.is_null() {
                return i.error(&format!("fmi2SetString: {} is a null pointer", STRING_IN[k].1));
            }
            i.strings[k] = CStr::from_ptr(*v).to_string_lossy().into_owned();
        }
        OK
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(c: *mut c_void, current: c_double, h: c_double, _no_prior: c_int) -> Fmi2Status {
    with_instance(c, |i| i.do_step(current, h))
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> Fmi2Status {
    with_instance(c, |i| i.error("fmi2CancelStep: steps are synchronous; nothing to cancel"))
}

/// # Safety
/// `value` points to one fmi2Status.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(c: *mut c_void, _kind: c_int, value: *mut Fmi2Status) -> Fmi2Status {
    with_instance(c, |i| {
        if value.is_null() {
            return i.error("fmi2GetStatus: null pointer");
        }
        *value = OK;
        OK
    })
}

/// # Safety
/// `value` points to one fmi2Real.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut c_double) -> Fmi2Status {
    with_instance(c, |i| {
        // fmi2LastSuccessfulTime = 2
        if kind != 2 || value.is_null() {
            return DISCARD;
        }
        *value = i.start_time + i.run.as_ref().map_or(0.0, |r| r.time_s());
        OK
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(c: *mut c_void, _kind: c_int, _value: *mut c_int) -> Fmi2Status {
    with_instance(c, |_| DISCARD)
}

/// # Safety
/// `value` points to one fmi2Boolean.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: *mut c_void, kind: c_int, value: *mut c_int) -> Fmi2Status {
    with_instance(c, |i| {
        // fmi2Terminated = 3
        if kind != 3 || value.is_null() {
            return DISCARD;
        }
        *value = i.terminated as c_int;
        OK
    })
}

/// # Safety
/// FMI calling convention.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(c: *mut c_void, _kind: c_int, _value: *mut *const c_char) -> Fmi2Status {
    with_instance(c, |_| DISCARD)
}

macro_rules! unsupported {
    ($name:ident ( $($arg:ident : $ty:ty),* )) => {
        /// Not supported by this FMU (its modelDescription.xml says so): fmi2Error.
        ///
        /// # Safety
        /// FMI calling convention.
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: *mut c_void, $($arg: $ty),*) -> Fmi2Status {
            $(let _ = $arg;)*
            with_instance(c, |i| i.error(concat!(stringify!($name), ": not supported by this FMU")))
        }
    };
}

unsupported!(fmi2GetFMUstate(s: *mut *mut c_void));
unsupported!(fmi2SetFMUstate(s: *mut c_void));
unsupported!(fmi2FreeFMUstate(s: *mut *mut c_void));
unsupported!(fmi2SerializedFMUstateSize(s: *mut c_void, size: *mut usize));
unsupported!(fmi2SerializeFMUstate(s: *mut c_void, bytes: *mut c_char, size: usize));
unsupported!(fmi2DeSerializeFMUstate(bytes: *const c_char, size: usize, s: *mut *mut c_void));
unsupported!(fmi2GetDirectionalDerivative(
    unknown: *const c_uint,
    n_unknown: usize,
    known: *const c_uint,
    n_known: usize,
    dv_known: *const c_double,
    dv_unknown: *mut c_double
));
unsupported!(fmi2SetRealInputDerivatives(vr: *const c_uint, n: usize, order: *const c_int, value: *const c_double));
unsupported!(fmi2GetRealOutputDerivatives(vr: *const c_uint, n: usize, order: *const c_int, value: *mut c_double));
