//! Known-answer fixtures of the vehicle models' derivatives: `Bicycle::derivatives` and
//! `Roll4Dof::derivatives` of the shipped sedan, for every tyre provider, at fixed states away
//! from equilibrium (cornering with slip, driven, contact warmer than the surface) under fixed
//! inputs, compared with tests/data/derivatives/<model>__<tyre>.csv to 1e-12 (relative to
//! max(1, |value|)). These pin the equations themselves: any change of a model's physics moves
//! them, and the fixtures are then re-blessed deliberately, like the golden trajectories:
//!
//!     VEHSIM_BLESS=1 cargo test --release --test derivatives

mod common;

use std::path::PathBuf;

use nalgebra::SVector;
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::vehicle::{Bicycle, Environment, Inputs, Roll4Dof, VehicleModel};
use vehsim_spec::vehicle::VehicleFile;

const TOL: f64 = 1e-12;

fn fixture(model: &str, tyre: &str) -> PathBuf {
    common::root().join(format!("tests/data/derivatives/{model}__{tyre}.csv"))
}

/// The state: leading rigid-body states in a left-hand turn with sideslip, the rest (wheel spin,
/// relaxed slips, forces, roll, lag) set from `extra` in order.
fn state<const N: usize>(extra: &[f64]) -> SVector<f64, N> {
    let mut x = SVector::<f64, N>::zeros();
    let body = [12.0, -3.0, 0.3, 14.0, 0.45, 0.25];
    for (i, v) in body.iter().chain(extra).take(N).enumerate() {
        x[i] = *v;
    }
    x
}

fn inputs() -> Inputs {
    Inputs {
        steer_rad: 0.04,
        drive_torque_nm: 350.0,
        brake_torque_nm: 20.0,
        contact_temp_c: [-1.0, -1.5, -0.5, -2.0],
        ..Inputs::default()
    }
}

const ENV: Environment = Environment {
    mu: 0.3,
    surface_temp_c: -3.0,
    regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
    road: vehsim_core::vehicle::road::Road::FLAT,
};

fn check(model: &str, tyre: &str, names: &[&str], d: &[f64]) {
    let path = fixture(model, tyre);
    if std::env::var_os("VEHSIM_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        let text: String = names.iter().zip(d).map(|(n, v)| format!("{n},{v:e}\n")).collect();
        std::fs::write(&path, format!("state,derivative\n{text}")).unwrap();
        return;
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let rows: Vec<(String, f64)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let (n, v) = l.split_once(',').unwrap();
            (n.to_string(), v.parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), d.len(), "{model} + {tyre}");
    for ((n, want), (name, got)) in rows.iter().zip(names.iter().zip(d)) {
        assert_eq!(n, name, "{model} + {tyre}");
        assert!(got.is_finite(), "{model} + {tyre}: d{name}/dt = {got}");
        assert!(
            (got - want).abs() <= TOL * want.abs().max(1.0),
            "{model} + {tyre}: d{name}/dt = {got:e}, fixture {want:e}"
        );
    }
}

#[test]
fn derivatives_match_the_fixtures_for_every_model_and_provider() {
    let path = common::root().join("vehicles/sedan.toml");
    let file = VehicleFile::load(&path).unwrap();
    for &kind in TyreModelKind::ALL {
        let vehicle = file.build(&path, kind).unwrap();
        let r = vehicle.tyre.rolling_radius_m;
        // Wheels: front spinning up (driven), rear slightly braked.
        let bicycle = Bicycle::new(vehicle.clone());
        let x = state::<13>(&[14.6 / r, 13.9 / r, 0.03, -0.01, 900.0, 700.0, 0.035]);
        let d = bicycle.derivatives(&x, &inputs(), &ENV);
        check("bicycle", kind.as_str(), &bicycle.state_names(), d.as_slice());
        let roll = Roll4Dof::new(vehicle.clone(), vehicle.roll.clone().unwrap());
        let x = state::<18>(&[14.5 / r, 14.7 / r, 13.8 / r, 14.0 / r, 0.03, 0.025, -0.01, -0.012, 0.02, 0.05]);
        let d = roll.derivatives(&x, &inputs(), &ENV);
        check("roll4dof", kind.as_str(), &roll.state_names(), d.as_slice());
    }
}
