//! The envelope chart: the limit (highest passing entry speed, m/s, or highest steady lateral
//! acceleration, m/s^2) against the first swept factor, one line per value of the remaining factors
//! (the second first), and each reference as a horizontal line across the chart, or in the note
//! under it when drawing it would squash the combinations' lines (more than 50 % beyond their range).

use std::path::Path;

use super::{Envelope, Kind, Row};
use crate::output::num::sig;
use crate::plot::{line_chart, LineChart, Series};
use vehsim_core::error::Result;

/// Write `<stem>.png` and `<stem>.svg`. The first factor's values are the x axis when they are
/// numbers, else their position (1, 2, ...).
pub fn plot(stem: &Path, env: &Envelope, rows: &[Row]) -> Result<()> {
    let combos: Vec<&Row> = rows.iter().filter(|r| r.label.is_empty()).collect();
    let x_of = |i: usize, r: &Row| r.params.first().and_then(|p| p.parse::<f64>().ok()).unwrap_or((i + 1) as f64);
    let mut series: Vec<Series> = Vec::new();
    for (i, r) in combos.iter().enumerate() {
        let rest = env.keys.iter().zip(&r.params).skip(1).map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>();
        let label = if rest.is_empty() { "limit".to_string() } else { rest.join(", ") };
        let point = (x_of(i, r), r.limit.value.unwrap_or(f64::NAN));
        match series.iter_mut().find(|s| s.label == label) {
            Some(s) => s.points.push(point),
            None => series.push(Series { label, points: vec![point] }),
        }
    }
    let xs: Vec<f64> = series.iter().flat_map(|s| s.points.iter().map(|p| p.0)).collect();
    let (x0, x1) = xs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    let (x0, x1) = if x0.is_finite() { (x0, x1) } else { (0.0, 1.0) };
    let ys = series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).filter(|y| y.is_finite());
    let (y0, y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    let (what, y_label, unit) = match env.kind {
        Kind::Speed => ("Highest passing ISO 3888-2 entry speed", "entry speed (m/s)", "m/s"),
        Kind::LateralAcceleration => ("Highest steady lateral acceleration", "a_y (m/s^2)", "m/s^2"),
    };
    let mut off_scale = Vec::new();
    for r in rows.iter().filter(|r| !r.label.is_empty()) {
        let v = r.limit.value.unwrap_or(f64::NAN);
        if y0.is_finite() && v.is_finite() && (v > y1 + 0.5 * y1.abs() || v < y0 - 0.5 * y0.abs()) {
            off_scale.push(format!("{}: {} {unit}", r.label, sig(v, 3)));
        } else {
            series.push(Series { label: format!("{} (reference)", r.label), points: vec![(x0, v), (x1, v)] });
        }
    }
    let note = if off_scale.is_empty() {
        String::new()
    } else {
        format!("Reference, off this scale: {}.", off_scale.join("; "))
    };
    let chart = LineChart {
        title: what.into(),
        x_label: env.keys.first().map_or_else(|| "run".into(), |k| key_label(k)),
        y_label: y_label.into(),
        series,
        note,
    };
    line_chart(stem, &chart)
}

/// An axis label for a swept spec key: the dotted path in words with the unit its suffix names,
/// e.g. `surface.temperature_c` -> `surface temperature (°C) [surface.temperature_c]`; a key
/// without a unit suffix is kept as it is.
fn key_label(key: &str) -> String {
    const UNITS: [(&str, &str); 6] =
        [("_c", "°C"), ("_mps", "m/s"), ("_kmh", "km/h"), ("_deg", "deg"), ("_m", "m"), ("_s", "s")];
    match UNITS.iter().find(|(suffix, _)| key.ends_with(suffix)) {
        Some((suffix, unit)) => {
            let words = key[..key.len() - suffix.len()].replace(['.', '_'], " ");
            format!("{words} ({unit}) [{key}]")
        }
        None => key.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::key_label;

    #[test]
    fn swept_keys_read_as_words_with_their_unit() {
        assert_eq!(key_label("surface.temperature_c"), "surface temperature (°C) [surface.temperature_c]");
        assert_eq!(key_label("speed_mps"), "speed (m/s) [speed_mps]");
        assert_eq!(key_label("mu"), "mu");
    }
}
