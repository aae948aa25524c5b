//! Which command a spec file belongs to, told from its top-level keys, so that a spec given to
//! the wrong command gets a one-line hint naming the right one instead of an "unknown field" error.
//!
//! - run spec (`vehsim run`, `validate`, `bench`): a `[maneuver]` table;
//! - tyre-curve spec (`vehsim tyre`): top-level `providers` with `slip_ratio` or `slip_angle_deg`;
//! - ATIIM scenario (`vehsim atiim`): `[pressure]` and `[operating]` tables;
//! - envelope spec (`vehsim envelope`): a run spec with an `[envelope]` table (the search settings).
//!
//! Anything else (or text that is not TOML) is left to the command's own parser and its messages.

use std::path::Path;

use vehsim_core::error::{Error, Result};

/// The kinds of spec the commands read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpecKind {
    /// A manoeuvre spec, with or without a sweep.
    Run,
    /// A tyre force-curve sweep.
    TyreCurves,
    /// An ATIIM contact-patch scenario.
    AtiimScenario,
    /// A run spec with `[envelope]` search settings.
    Envelope,
}

impl SpecKind {
    /// What the kind is called in the hint, and the command that reads it.
    fn describe(self) -> (&'static str, &'static str) {
        match self {
            SpecKind::Run => ("a run (manoeuvre) spec", "vehsim run"),
            SpecKind::TyreCurves => ("a tyre-curve spec", "vehsim tyre"),
            SpecKind::AtiimScenario => ("an ATIIM scenario spec", "vehsim atiim"),
            SpecKind::Envelope => ("an envelope spec", "vehsim envelope"),
        }
    }
}

/// The kind of a parsed spec, or `None` when its keys fit no kind.
pub fn detect(table: &toml::Table) -> Option<SpecKind> {
    let is_table = |k: &str| table.get(k).is_some_and(|v| v.is_table());
    if is_table("maneuver") && is_table("envelope") {
        Some(SpecKind::Envelope)
    } else if is_table("maneuver") {
        Some(SpecKind::Run)
    } else if table.contains_key("providers")
        && (table.contains_key("slip_ratio") || table.contains_key("slip_angle_deg"))
    {
        Some(SpecKind::TyreCurves)
    } else if is_table("pressure") && is_table("operating") {
        Some(SpecKind::AtiimScenario)
    } else {
        None
    }
}

/// Bad input (exit 2) when `table`, read from `path`, is a spec of another kind than `expected`:
/// one line naming the kind found and the command to use.
pub fn expect(path: &Path, table: &toml::Table, expected: SpecKind) -> Result<()> {
    match detect(table) {
        Some(found) if found != expected => {
            let (what, command) = found.describe();
            Err(Error::input(
                path,
                format!("this is {what}, not {}; use `{command} {}`", expected.describe().0, path.display()),
            ))
        }
        _ => Ok(()),
    }
}

/// As [`expect`], for spec text not yet parsed; text that is not TOML passes (its parser reports it).
pub fn expect_text(path: &Path, text: &str, expected: SpecKind) -> Result<()> {
    match toml::from_str::<toml::Table>(text) {
        Ok(t) => expect(path, &t, expected),
        Err(_) => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(s: &str) -> toml::Table {
        toml::from_str(s).unwrap()
    }

    #[test]
    fn kinds_are_told_apart_by_their_keys() {
        assert_eq!(detect(&table("name = 'a'\n[maneuver]\nkind = 'sine_steer'")), Some(SpecKind::Run));
        assert_eq!(
            detect(&table("name = 'a'\nproviders = ['pacejka']\nslip_ratio = { min = 0, max = 1, points = 3 }")),
            Some(SpecKind::TyreCurves)
        );
        assert_eq!(
            detect(&table("[pressure]\nsource = 'synth'\n[operating]\nspeed_mps = 1.0")),
            Some(SpecKind::AtiimScenario)
        );
        assert_eq!(
            detect(&table("name = 'a'\n[maneuver]\nkind = 'iso3888_2'\n[envelope]\ntolerance_mps = 0.1")),
            Some(SpecKind::Envelope)
        );
        // `maneuver` as a plain value, or `pressure` alone, is no known kind.
        assert_eq!(detect(&table("maneuver = 1\n[pressure]\nx = 1")), None);
    }

    #[test]
    fn a_spec_of_another_kind_gets_a_hint_naming_the_command() {
        let p = Path::new("scenarios/tyre/tyre_curves.toml");
        let t = table("providers = ['pacejka']\nslip_angle_deg = { min = 0, max = 1, points = 3 }");
        let e = expect(p, &t, SpecKind::Run).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let msg = e.to_string();
        assert!(msg.contains("vehsim tyre scenarios/tyre/tyre_curves.toml") && !msg.contains('\n'), "{msg}");
        assert!(expect(p, &t, SpecKind::TyreCurves).is_ok());
        assert!(expect_text(p, "not = = toml", SpecKind::Run).is_ok());
    }
}
