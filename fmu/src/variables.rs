//! The FMU's variables (value references, causality, start values) and its
//! `modelDescription.xml`, generated from the same table the C functions read, so the two cannot
//! disagree.
//!
//! Units are SI, angles in rad, ISO 8855 axes (x forward, y left, z up; steer and yaw positive
//! counter-clockwise seen from above), as in `vehsim run`'s timeseries.csv, whose column names
//! (units in the names) the outputs carry.

use std::fmt::Write as _;

use vehsim_spec::step::OBSERVATION;

/// Model identifier: the shared library is `binaries/<platform>/vehsim.so`.
pub const MODEL_IDENTIFIER: &str = "vehsim";

/// Identifies this interface (variables and their meaning); changes whenever they change.
pub const GUID: &str = "{6d2f3c1e-7a51-4b8e-9c3a-0f4e5d6c7b8a}";

/// Real parameters and inputs (value reference, name, causality, start, description).
pub const REAL_IN: &[(u32, &str, &str, f64, &str)] = &[
    (0, "mu", "parameter", 0.15, "peak friction coefficient of the surface (replaces the spec's [surface] mu)"),
    (
        1,
        "surface_temperature_c",
        "parameter",
        -3.0,
        "bulk ice temperature, degC (replaces the spec's [surface] temperature_c)",
    ),
    (2, "steer_cmd_rad", "input", 0.0, "front road-wheel steer angle, rad, positive left (used when external_steer)"),
    (3, "drive_torque_cmd_nm", "input", 0.0, "total drive torque at the wheels, N m, >= 0 (used when external_torque)"),
    (4, "brake_torque_cmd_nm", "input", 0.0, "total brake torque at the wheels, N m, >= 0 (used when external_torque)"),
];

/// Value reference of the first output; output k (0-based) is `OUTPUT_VR0 + k`.
pub const OUTPUT_VR0: u32 = 10;

/// The outputs: the observation's values after its time column (`t_s` is the FMU's own time).
pub fn outputs() -> &'static [&'static str] {
    &OBSERVATION[1..]
}

/// String parameters (value reference, name, start, description).
pub const STRING_IN: &[(u32, &str, &str, &str)] = &[
    (
        100,
        "spec",
        "maneuvers/sine_steer.toml",
        "manoeuvre spec (TOML) that sets the vehicle, tyre model, integrator and manoeuvre; a relative path is read from the FMU's resources folder",
    ),
    (101, "vehicle", "", "vehicle file replacing the spec's (empty: the spec's); relative paths as for spec"),
    (102, "tyre_model", "", "tyre provider replacing the spec's: linear, polynomial, pacejka, atiim_pacejka, dugoff (empty: the spec's)"),
];

/// Boolean parameters (value reference, name, start, description).
pub const BOOL_IN: &[(u32, &str, bool, &str)] = &[
    (200, "external_steer", true, "true: the steer_cmd_rad input steers; false: the spec's driver or steer profile"),
    (201, "external_torque", false, "true: the torque inputs drive and brake; false: the spec's speed controller"),
];

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The text of `modelDescription.xml`.
pub fn model_description() -> String {
    let mut x = String::new();
    let _ = write!(
        x,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="vehsim" guid="{GUID}"
  description="vehsim vehicle dynamics on ice (bicycle or 4-DOF model, Pacejka / ATIIM-Pacejka / Dugoff tyres, contact-temperature estimate) as a co-simulation unit"
  generationTool="vehsim-fmu {version}" variableNamingConvention="flat" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true"
    canInterpolateInputs="false" maxOutputDerivativeOrder="0" canRunAsynchronuously="false"
    canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true"
    canGetAndSetFMUstate="false" canSerializeFMUstate="false" providesDirectionalDerivative="false"/>
  <LogCategories>
    <Category name="logStatusError" description="errors: bad parameters, inputs, files"/>
    <Category name="logStatusWarning" description="warnings"/>
  </LogCategories>
  <DefaultExperiment startTime="0" stopTime="10" stepSize="0.01"/>
  <ModelVariables>
"#,
        version = env!("CARGO_PKG_VERSION"),
    );
    // (index in the list, 1-based) of each output, for ModelStructure
    let mut index = 0usize;
    let mut output_index = Vec::new();
    for (vr, name, causality, start, desc) in REAL_IN {
        index += 1;
        let (variability, initial) =
            if *causality == "parameter" { ("fixed", r#" initial="exact""#) } else { ("continuous", "") };
        let _ = writeln!(
            x,
            r#"    <ScalarVariable name="{name}" valueReference="{vr}" causality="{causality}" variability="{variability}"{initial} description="{}"><Real start="{start}"/></ScalarVariable>"#,
            esc(desc)
        );
    }
    for (k, name) in outputs().iter().enumerate() {
        index += 1;
        output_index.push(index);
        let _ = writeln!(
            x,
            r#"    <ScalarVariable name="{name}" valueReference="{}" causality="output" variability="continuous" initial="calculated" description="as the column {name} of vehsim run's timeseries.csv"><Real/></ScalarVariable>"#,
            OUTPUT_VR0 + k as u32
        );
    }
    for (vr, name, start, desc) in STRING_IN {
        let _ = writeln!(
            x,
            r#"    <ScalarVariable name="{name}" valueReference="{vr}" causality="parameter" variability="fixed" initial="exact" description="{}"><String start="{}"/></ScalarVariable>"#,
            esc(desc),
            esc(start)
        );
    }
    for (vr, name, start, desc) in BOOL_IN {
        let _ = writeln!(
            x,
            r#"    <ScalarVariable name="{name}" valueReference="{vr}" causality="parameter" variability="fixed" initial="exact" description="{}"><Boolean start="{start}"/></ScalarVariable>"#,
            esc(desc)
        );
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n");
    for i in &output_index {
        let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
    }
    x.push_str("    </Outputs>\n    <InitialUnknowns>\n");
    for i in &output_index {
        let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
    }
    x.push_str("    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n");
    x
}
