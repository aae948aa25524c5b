//! Reader for Magic Formula tyre property files (`.tir`, the MSC ADAMS / TNO "TeimOrbit" layout).
//!
//! A `.tir` file is a list of `[SECTION]` headers, each followed by `KEY = value` lines. Comments
//! start with `$` (anywhere on a line) or `!` (at the start of a line). Values are numbers
//! (`1.2`, `-3.76e-005`) or quoted strings (`'PAC2002'`).
//!
//! What this reader does:
//! - Parses the sections it knows (`KNOWN_SECTIONS`); sections holding tables rather than
//!   `KEY = value` lines (`[SHAPE]`) are skipped. An unknown section is skipped and reported as a
//!   warning in [`TirFile::warnings`] (library code never prints).
//! - A line it cannot read (no `=`, a bad key, an unquoted non-number, a duplicate key) is a
//!   bad-input error naming the file and the 1-based line number.
//! - Converts the dimensional parameters to SI according to `[UNITS]` (`dimension_of`): lengths,
//!   forces, angles, speeds, stiffness and damping. The Magic Formula coefficients (P*, Q*, R*, L*)
//!   are dimensionless by definition of the formula (angles inside them are radians) and are not
//!   converted. A file without `[UNITS]` is read as SI, with a warning.
//! - Checks `PROPERTY_FILE_FORMAT` in `[MODEL]` against `SUPPORTED_FORMATS`.

use std::collections::BTreeMap;
use std::path::Path;

use vehsim_core::error::{Error, Result};

/// Property-file formats whose equations [`vehsim_core::tyre::pacejka`] implements (MF 5.2 family).
pub(crate) const SUPPORTED_FORMATS: &[&str] = &["PAC2002", "MF_05"];

/// Sections read as `KEY = value` lines.
pub(crate) const KNOWN_SECTIONS: &[&str] = &[
    "MDI_HEADER",
    "UNITS",
    "MODEL",
    "DIMENSION",
    "VERTICAL",
    "LONG_SLIP_RANGE",
    "SLIP_ANGLE_RANGE",
    "INCLINATION_ANGLE_RANGE",
    "VERTICAL_FORCE_RANGE",
    "SCALING_COEFFICIENTS",
    "LONGITUDINAL_COEFFICIENTS",
    "OVERTURNING_COEFFICIENTS",
    "LATERAL_COEFFICIENTS",
    "ROLLING_COEFFICIENTS",
    "ALIGNING_COEFFICIENTS",
    "TURNSLIP_COEFFICIENTS",
    "CONTACT",
    "STRUCTURAL",
    "INFLATION_PRESSURE_RANGE",
    "OPERATING_CONDITIONS",
];

/// Sections that hold tables (not `KEY = value`); their content is skipped without a warning.
pub(crate) const TABLE_SECTIONS: &[&str] = &["SHAPE"];

/// A value on the right of `=`.
#[derive(Debug, Clone, PartialEq)]
pub enum TirValue {
    /// A number (converted to SI if it is a dimensional parameter).
    Num(f64),
    /// A quoted string, quotes removed.
    Str(String),
}

/// A parsed property file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TirFile {
    /// Every `KEY = value` of the known sections, keys upper-cased, numbers in SI.
    pub values: BTreeMap<String, TirValue>,
    /// `PROPERTY_FILE_FORMAT` as written (upper-cased), one of `SUPPORTED_FORMATS`.
    pub format: String,
    /// Things the caller may want to show the user (unknown sections, missing `[UNITS]`).
    pub warnings: Vec<String>,
}

impl TirFile {
    /// Numeric value of `key` (upper-case name), if present.
    pub fn num(&self, key: &str) -> Option<f64> {
        match self.values.get(key) {
            Some(TirValue::Num(v)) => Some(*v),
            _ => None,
        }
    }

    /// String value of `key`, if present.
    pub fn string(&self, key: &str) -> Option<&str> {
        match self.values.get(key) {
            Some(TirValue::Str(s)) => Some(s.as_str()),
            _ => None,
        }
    }
}

/// Physical dimension of a dimensional `.tir` parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Dimension {
    Length,
    Force,
    Angle,
    /// Length / time.
    Speed,
    /// Force / length.
    Stiffness,
    /// Force * time / length.
    Damping,
    Mass,
}

/// The dimension of a known dimensional parameter; `None` for dimensionless ones.
pub(crate) fn dimension_of(key: &str) -> Option<Dimension> {
    use Dimension::*;
    Some(match key {
        "UNLOADED_RADIUS" | "WIDTH" | "RIM_RADIUS" | "RIM_WIDTH" => Length,
        "FNOMIN" | "FZMIN" | "FZMAX" => Force,
        "ALPMIN" | "ALPMAX" | "CAMMIN" | "CAMMAX" => Angle,
        "LONGVL" | "VXLOW" => Speed,
        "VERTICAL_STIFFNESS" => Stiffness,
        "VERTICAL_DAMPING" => Damping,
        "MBELT" => Mass,
        _ => return None,
    })
}

/// The range of magnitudes (SI) a road-vehicle tyre's dimensional parameter has, with its unit and
/// what it is: a value outside it almost certainly means `[UNITS]` that do not match the numbers
/// (a radius of 0.338 read as millimetres). Parameters not listed are not checked.
pub(crate) fn plausible_si(key: &str) -> Option<(f64, f64, &'static str, &'static str)> {
    Some(match key {
        "UNLOADED_RADIUS" => (0.1, 2.0, "m", "a tyre's unloaded radius"),
        "RIM_RADIUS" => (0.05, 1.5, "m", "a rim radius"),
        "WIDTH" => (0.03, 1.5, "m", "a tyre's width"),
        "RIM_WIDTH" => (0.03, 1.5, "m", "a rim width"),
        "FNOMIN" => (100.0, 100_000.0, "N", "a tyre's nominal load"),
        "VERTICAL_STIFFNESS" => (1e4, 1e8, "N/m", "a tyre's vertical stiffness"),
        "LONGVL" => (0.1, 100.0, "m/s", "a measurement speed"),
        _ => return None,
    })
}

/// SI factors of the five base units of `[UNITS]`, and the length and force names as written.
#[derive(Debug, Clone, PartialEq)]
struct Units {
    length: f64,
    force: f64,
    angle: f64,
    mass: f64,
    time: f64,
    length_name: String,
    force_name: String,
}

impl Units {
    fn factor(&self, d: Dimension) -> f64 {
        match d {
            Dimension::Length => self.length,
            Dimension::Force => self.force,
            Dimension::Angle => self.angle,
            Dimension::Speed => self.length / self.time,
            Dimension::Stiffness => self.force / self.length,
            Dimension::Damping => self.force * self.time / self.length,
            Dimension::Mass => self.mass,
        }
    }
}

/// SI factor of a unit name in `[UNITS]` for base quantity `key`, or the list of accepted names.
fn unit_factor(key: &str, name: &str) -> std::result::Result<f64, &'static str> {
    let n = name.trim().to_ascii_lowercase();
    let n = n.as_str();
    match key {
        "LENGTH" => match n {
            "meter" | "metre" | "m" => Ok(1.0),
            "millimeter" | "millimetre" | "mm" => Ok(1e-3),
            "centimeter" | "centimetre" | "cm" => Ok(1e-2),
            "kilometer" | "kilometre" | "km" => Ok(1e3),
            "inch" | "in" => Ok(0.0254),
            "foot" | "ft" => Ok(0.3048),
            _ => Err("meter, millimeter, centimeter, kilometer, inch, foot"),
        },
        "FORCE" => match n {
            "newton" | "n" => Ok(1.0),
            "kilonewton" | "kn" => Ok(1e3),
            "pound_force" | "lbf" => Ok(4.448_221_615_260_5),
            "kilogram_force" | "kgf" => Ok(9.806_65),
            _ => Err("newton, kilonewton, pound_force, kilogram_force"),
        },
        "ANGLE" => match n {
            "radian" | "radians" | "rad" => Ok(1.0),
            "degree" | "degrees" | "deg" => Ok(std::f64::consts::PI / 180.0),
            _ => Err("radian, degree"),
        },
        "MASS" => match n {
            "kg" | "kilogram" => Ok(1.0),
            "gram" | "g" => Ok(1e-3),
            "tonne" | "megagram" => Ok(1e3),
            "pound_mass" | "lbm" => Ok(0.453_592_37),
            _ => Err("kg, gram, tonne, pound_mass"),
        },
        "TIME" => match n {
            "second" | "sec" | "s" => Ok(1.0),
            "millisecond" | "ms" => Ok(1e-3),
            "minute" | "min" => Ok(60.0),
            "hour" | "h" => Ok(3600.0),
            _ => Err("second, millisecond, minute, hour"),
        },
        _ => Ok(1.0),
    }
}

/// Read and parse a `.tir` file.
pub(crate) fn read_tir(path: &Path) -> Result<TirFile> {
    let text = crate::files::read_input(path)?;
    parse_tir(path, &text)
}

fn line_err(path: &Path, line_no: usize, msg: impl std::fmt::Display) -> Error {
    Error::input(path, format!("line {line_no}: {msg}"))
}

/// Parse the text of a `.tir` file; `path` is used in messages only.
pub fn parse_tir(path: &Path, text: &str) -> Result<TirFile> {
    let (raw, mut warnings) = read_entries(path, text)?;
    let units = read_units(path, &raw, &mut warnings)?;
    let values = to_si(path, raw, &units)?;
    let format = file_format(path, &values)?;
    Ok(TirFile { values, format, warnings })
}

/// One `KEY = value` entry of a read section: (line number, upper-case key, raw value).
type Entry = (usize, String, TirValue);

/// The entries of the sections vehsim reads, with their line numbers, in file order; units are
/// applied after the whole file is read, because [UNITS] need not come first. Warnings for
/// unknown sections.
fn read_entries(path: &Path, text: &str) -> Result<(Vec<Entry>, Vec<String>)> {
    let mut raw: Vec<(usize, String, TirValue)> = Vec::new();
    let mut warnings = Vec::new();
    let mut section: Option<String> = None;
    // What to do with the lines of the current section.
    #[derive(PartialEq)]
    enum Mode {
        Read,
        Skip,
    }
    let mut mode = Mode::Skip;
    // A UTF-8 byte-order mark (written by some Windows editors) is not text of the file.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (idx, line) in text.lines().enumerate() {
        let no = idx + 1;
        let body = line.split('$').next().unwrap_or("").trim();
        if body.is_empty() || body.starts_with('!') {
            continue;
        }
        if body.starts_with('[') {
            let Some(end) = body.find(']') else {
                return Err(line_err(
                    path,
                    no,
                    format!("malformed section header {} (expected [NAME])", vehsim_core::error::shown(body)),
                ));
            };
            let name = body[1..end].trim().to_ascii_uppercase();
            if name.is_empty() {
                return Err(line_err(path, no, "empty section name '[]'"));
            }
            if KNOWN_SECTIONS.contains(&name.as_str()) {
                mode = Mode::Read;
            } else {
                if !TABLE_SECTIONS.contains(&name.as_str()) {
                    warnings.push(format!("{}: line {no}: unknown section [{name}] ignored", path.display()));
                }
                mode = Mode::Skip;
            }
            section = Some(name);
            continue;
        }
        if mode == Mode::Skip {
            if section.is_none() {
                return Err(line_err(
                    path,
                    no,
                    format!("{} appears before the first [SECTION] header", vehsim_core::error::shown(body)),
                ));
            }
            continue;
        }
        let Some((k, v)) = body.split_once('=') else {
            return Err(line_err(
                path,
                no,
                format!("malformed line {} (expected KEY = value)", vehsim_core::error::shown(body)),
            ));
        };
        let key = k.trim().to_ascii_uppercase();
        let key_ok = key.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !key_ok {
            return Err(line_err(path, no, format!("malformed key '{}' (expected a name like PCX1)", k.trim())));
        }
        let value = parse_value(path, no, &key, v.trim())?;
        if let Some((first, _, _)) = raw.iter().find(|(_, k2, _)| *k2 == key) {
            return Err(line_err(path, no, format!("{key} is given twice (first on line {first})")));
        }
        raw.push((no, key, value));
    }
    Ok((raw, warnings))
}

/// A value: a quoted string ('...' or "...") or a finite number.
fn parse_value(path: &Path, no: usize, key: &str, v: &str) -> Result<TirValue> {
    for q in ['\'', '"'] {
        if let Some(s) = v.strip_prefix(q) {
            return match s.strip_suffix(q) {
                Some(inner) => Ok(TirValue::Str(inner.to_string())),
                None => Err(line_err(path, no, format!("unterminated string for {key}: {v}"))),
            };
        }
    }
    match v.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(TirValue::Num(x)),
        _ => Err(line_err(path, no, format!("value of {key} is not a finite number or a quoted string: '{v}'"))),
    }
}

/// The file's [UNITS] (SI, with a warning, when it has none).
fn read_units(path: &Path, raw: &[Entry], warnings: &mut Vec<String>) -> Result<Units> {
    let mut units = Units {
        length: 1.0,
        force: 1.0,
        angle: 1.0,
        mass: 1.0,
        time: 1.0,
        length_name: "meter (none given)".into(),
        force_name: "newton (none given)".into(),
    };
    let mut saw_units = false;
    for (no, key, value) in raw {
        if !matches!(key.as_str(), "LENGTH" | "FORCE" | "ANGLE" | "MASS" | "TIME") {
            continue;
        }
        saw_units = true;
        let TirValue::Str(name) = value else {
            return Err(line_err(path, *no, format!("{key} in [UNITS] must be a quoted unit name")));
        };
        let f = unit_factor(key, name)
            .map_err(|allowed| line_err(path, *no, format!("unsupported {key} unit '{name}'; supported: {allowed}")))?;
        match key.as_str() {
            "LENGTH" => {
                (units.length, units.length_name) = (f, vehsim_core::error::shown(name).trim_matches('\'').into())
            }
            "FORCE" => (units.force, units.force_name) = (f, vehsim_core::error::shown(name).trim_matches('\'').into()),
            "ANGLE" => units.angle = f,
            "MASS" => units.mass = f,
            _ => units.time = f,
        }
    }
    if !saw_units {
        warnings.push(format!("{}: no [UNITS] section; values are read as SI", path.display()));
    }
    Ok(units)
}

/// Every value in SI units, each dimensional one checked against its plausible range.
fn to_si(path: &Path, raw: Vec<Entry>, units: &Units) -> Result<BTreeMap<String, TirValue>> {
    let mut values = BTreeMap::new();
    for (no, key, value) in raw {
        let value = match (value, dimension_of(&key)) {
            (TirValue::Num(x), Some(d)) => {
                let si = x * units.factor(d);
                if let Some((lo, hi, unit, what)) = plausible_si(&key) {
                    if !(lo..=hi).contains(&si.abs()) {
                        return Err(line_err(
                            path,
                            no,
                            format!(
                                "{key} = {} reads as {} {unit} with the file's [UNITS] (LENGTH '{}', FORCE '{}'), \
                                 but {what} is {}-{} {unit}: do [UNITS] match the values?",
                                vehsim_core::error::short_num(x),
                                vehsim_core::error::short_num(si),
                                units.length_name,
                                units.force_name,
                                vehsim_core::error::short_num(lo),
                                vehsim_core::error::short_num(hi)
                            ),
                        ));
                    }
                }
                TirValue::Num(si)
            }
            (v, _) => v,
        };
        values.insert(key, value);
    }
    Ok(values)
}

/// The PROPERTY_FILE_FORMAT, one of the supported ones.
fn file_format(path: &Path, values: &BTreeMap<String, TirValue>) -> Result<String> {
    let format = match values.get("PROPERTY_FILE_FORMAT") {
        Some(TirValue::Str(s)) => s.trim().to_ascii_uppercase(),
        Some(TirValue::Num(x)) => format!("{x}"),
        None => {
            return Err(Error::input(
                path,
                format!("[MODEL] has no PROPERTY_FILE_FORMAT; supported formats: {}", SUPPORTED_FORMATS.join(", ")),
            ))
        }
    };
    if !SUPPORTED_FORMATS.contains(&format.as_str()) {
        return Err(Error::input(
            path,
            format!(
                "unsupported PROPERTY_FILE_FORMAT '{format}'; supported formats: {} (Magic Formula 5.2 equations)",
                SUPPORTED_FORMATS.join(", ")
            ),
        ));
    }
    Ok(format)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.tir")
    }

    #[test]
    fn reads_values_comments_and_converts_units() {
        let t = "$ header\n[UNITS]\nLENGTH = 'mm' $ c\nFORCE='kilonewton'\n[MODEL]\nPROPERTY_FILE_FORMAT='PAC2002'\n\
                 [DIMENSION]\nUNLOADED_RADIUS = 344\n[VERTICAL]\nFNOMIN = 4.85\n[SHAPE]\n{radial width}\n 1.0 0.0\n\
                 [LONGITUDINAL_COEFFICIENTS]\nPCX1 = 1.6 $ shape\nPVX1 = -8.8e-006\n[FOO]\nX = 1\n";
        let f = parse_tir(p(), t).unwrap();
        assert_eq!(f.format, "PAC2002");
        assert!((f.num("UNLOADED_RADIUS").unwrap() - 0.344).abs() < 1e-15);
        assert!((f.num("FNOMIN").unwrap() - 4850.0).abs() < 1e-9);
        assert_eq!(f.num("PCX1"), Some(1.6));
        assert_eq!(f.num("PVX1"), Some(-8.8e-6));
        assert_eq!(f.num("X"), None);
        assert_eq!(f.warnings.len(), 1);
        assert!(f.warnings[0].contains("[FOO]") && f.warnings[0].contains("line 17"), "{:?}", f.warnings);
    }

    #[test]
    fn malformed_and_duplicate_lines_name_the_line() {
        let t = "[MODEL]\nPROPERTY_FILE_FORMAT='PAC2002'\n[LATERAL_COEFFICIENTS]\nPCY1 1.3\n";
        let e = parse_tir(p(), t).unwrap_err().to_string();
        assert!(e.contains("line 4") && e.contains("KEY = value"), "{e}");
        let t = "[MODEL]\nPROPERTY_FILE_FORMAT='PAC2002'\n[LATERAL_COEFFICIENTS]\nPCY1 = 1.3\nPCY1 = 1.4\n";
        let e = parse_tir(p(), t).unwrap_err().to_string();
        assert!(e.contains("line 5") && e.contains("twice"), "{e}");
        let t = "[MODEL]\nPROPERTY_FILE_FORMAT='PAC2002'\n[UNITS]\nLENGTH='furlong'\n";
        let e = parse_tir(p(), t).unwrap_err().to_string();
        assert!(e.contains("line 4") && e.contains("furlong") && e.contains("millimeter"), "{e}");
    }
}
