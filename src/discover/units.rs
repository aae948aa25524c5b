//! Units of a measured run's columns: the run format is SI (s, rad, m/s, rad/s, m/s^2, m), and a
//! column may say it is logged in another common unit, in its header cell (`yaw_rate [deg/s]`) or
//! in the sidecar's `[units]` table (`yaw_rate = "deg/s"`). The reader converts it to SI before
//! any check. A unit that is not listed for its column is bad input (exit 2), as is a sidecar
//! unit for a column the CSV does not have, or a header and a sidecar that disagree.

use std::f64::consts::PI;

/// Standard gravity, m/s^2 (the `g` unit of an accelerometer channel).
const G0: f64 = 9.80665;

/// The units a column may be logged in, each with its factor to SI (the first is the SI unit).
pub fn units_of(column: &str) -> &'static [(&'static str, f64)] {
    const DEG: f64 = PI / 180.0;
    match column {
        "t" => &[("s", 1.0), ("ms", 1e-3)],
        "steer" | "psi" | "roll" => &[("rad", 1.0), ("deg", DEG)],
        "vx" | "vy" => &[("m/s", 1.0), ("km/h", 1.0 / 3.6)],
        "yaw_rate" => &[("rad/s", 1.0), ("deg/s", DEG)],
        "ay" | "ax" => &[("m/s^2", 1.0), ("g", G0)],
        "x" | "y" => &[("m", 1.0)],
        _ => &[],
    }
}

/// The factor to SI of `unit` for `column`, or the allowed units as text.
pub fn si_factor(column: &str, unit: &str) -> Result<f64, String> {
    let units = units_of(column);
    units.iter().find(|(u, _)| *u == unit).map(|(_, f)| *f).ok_or_else(|| {
        let names: Vec<&str> = units.iter().map(|(u, _)| *u).collect();
        format!("unit '{unit}' of column '{column}' is not accepted; allowed: {}", names.join(", "))
    })
}

/// A header cell split into the column's name and the unit in square brackets after it, if any
/// (`"yaw_rate [deg/s]"` is `("yaw_rate", Some("deg/s"))`).
pub fn split_header(cell: &str) -> (&str, Option<&str>) {
    match (cell.find('['), cell.strip_suffix(']')) {
        (Some(i), Some(inner)) if i < inner.len() => (cell[..i].trim(), Some(inner[i + 1..].trim())),
        _ => (cell, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_split_into_name_and_unit() {
        assert_eq!(split_header("yaw_rate [deg/s]"), ("yaw_rate", Some("deg/s")));
        assert_eq!(split_header("ay[g]"), ("ay", Some("g")));
        assert_eq!(split_header("ay"), ("ay", None));
        assert_eq!(split_header("ay]"), ("ay]", None));
        assert_eq!(split_header("[s]"), ("", Some("s")));
    }

    #[test]
    fn factors_convert_to_si() {
        assert_eq!(si_factor("yaw_rate", "rad/s"), Ok(1.0));
        assert!((si_factor("steer", "deg").unwrap() * 180.0 - PI).abs() < 1e-15);
        assert!((si_factor("vx", "km/h").unwrap() * 36.0 - 10.0).abs() < 1e-15);
        assert_eq!(si_factor("ay", "g"), Ok(9.80665));
        let e = si_factor("ay", "ft/s^2").unwrap_err();
        assert!(e.contains("'ft/s^2'") && e.contains("m/s^2, g"), "{e}");
        assert!(si_factor("brake", "bar").is_err());
    }
}
