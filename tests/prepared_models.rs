//! The core's models built from the shipped spec files: prepared (cached) evaluations change no
//! bit against the plain ones. These
//! tests need the spec layer to read the shipped vehicle files, so they live here rather than
//! beside the code in `vehsim-core`, which reads no files.

mod bicycle {
    use vehsim_core::tyre::TyreModelKind;
    use vehsim_core::vehicle::bicycle::*;
    use vehsim_core::vehicle::{Environment, Inputs, VehicleModel};
    use vehsim_spec::VehicleFile;

    /// The prepared model (Magic Formula coefficients of the static loads) gives the same
    /// derivative and observation bit for bit as the unprepared one, on the prepared path
    /// (isothermal) and on the fallback (a heated contact, a thermal friction law); and
    /// one evaluation asking for more gives the same values bit for bit.
    #[test]
    fn prepared_tyres_change_no_bit() {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("vehicles/sedan.toml");
        let mut v = VehicleFile::load(&p).unwrap().build(&p, TyreModelKind::Pacejka).unwrap();
        for thermal in [0.0, -0.05] {
            v.lateral.thermal_mu_per_k = thermal;
            let env = Environment {
                mu: 0.15,
                surface_temp_c: -3.0,
                regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
                road: vehsim_core::vehicle::road::Road::FLAT,
            };
            let (plain, prepared) = (Bicycle::new(v.clone()), Bicycle::new(v.clone()).prepared_for(&env));
            assert!(prepared.has_prepared_curves());
            let mut x = plain.initial_state(0.0, 0.0, 0.2, 10.0);
            (x[ix::VY], x[ix::R], x[ix::KAPPA_F], x[ix::KAPPA_R]) = (0.3, 0.2, 0.02, -0.01);
            for temp in [-3.0, 1.5] {
                let u = Inputs {
                    steer_rad: 0.05,
                    drive_torque_nm: 300.0,
                    contact_temp_c: [temp, -3.0, temp, temp],
                    ..Inputs::default()
                };
                assert_eq!(crate::everything(&plain, &x, &u, &env), crate::everything(&prepared, &x, &u, &env));
                assert_eq!(plain.derivatives(&x, &u, &env), prepared.derivatives(&x, &u, &env));
                assert_eq!(plain.observe(&x, &u, &env), prepared.observe(&x, &u, &env));
                // the engine's shared evaluation: the separate calls' values, bit for bit
                for m in [&plain, &prepared] {
                    crate::assert_shared_evaluation(m, &x, &u, &env);
                }
            }
        }
    }
}

mod roll4dof {
    use vehsim_core::tyre::TyreModelKind;
    use vehsim_core::vehicle::roll4dof::*;
    use vehsim_core::vehicle::{Environment, Inputs, VehicleModel, GRAVITY};
    use vehsim_spec::VehicleFile;

    fn sedan() -> Roll4Dof {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("vehicles/sedan.toml");
        let v = VehicleFile::load(&p).unwrap().build(&p, TyreModelKind::Linear).unwrap();
        let roll = v.roll.clone().unwrap();
        Roll4Dof::new(v, roll)
    }

    /// Mirroring the state and the steer about the x axis mirrors the derivative exactly.
    #[test]
    fn mirrored_state_gives_mirrored_derivative() {
        let m = sedan();
        let env = Environment {
            mu: 0.15,
            surface_temp_c: -3.0,
            regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
            road: vehsim_core::vehicle::road::Road::FLAT,
        };
        let mut x = m.initial_state(1.0, 2.0, 0.3, 12.0);
        let vals = [(ix::VY, 0.4), (ix::R, 0.2), (ix::PHI, 0.01), (ix::P, -0.05), (ix::AX_LAG, 0.3), (ix::AY_LAG, 1.1)];
        for (i, v) in vals {
            x[i] = v;
        }
        for (i, w) in [37.0, 36.0, 36.5, 36.8].iter().enumerate() {
            x[ix::OMEGA + i] = *w;
            x[ix::KAPPA + i] = 0.01 * (i as f64 + 1.0);
        }
        let u = Inputs { steer_rad: 0.05, drive_torque_nm: 800.0, contact_temp_c: [-3.0; 4], ..Inputs::default() };
        let mut xm = x;
        xm[ix::Y] = -x[ix::Y];
        xm[ix::YAW] = -x[ix::YAW];
        for i in [ix::VY, ix::R, ix::PHI, ix::P, ix::AY_LAG] {
            xm[i] = -x[i];
        }
        // Left and right wheels swap.
        for base in [ix::OMEGA, ix::KAPPA] {
            xm[base] = x[base + 1];
            xm[base + 1] = x[base];
            xm[base + 2] = x[base + 3];
            xm[base + 3] = x[base + 2];
        }
        let um = Inputs { steer_rad: -0.05, ..u };
        let (d, dm) = (m.derivatives(&x, &u, &env), m.derivatives(&xm, &um, &env));
        let odd = [ix::Y, ix::YAW, ix::VY, ix::R, ix::PHI, ix::P, ix::AY_LAG];
        for i in 0..N {
            let j = match i {
                k if (ix::OMEGA..ix::OMEGA + 4).contains(&k) || (ix::KAPPA..ix::KAPPA + 4).contains(&k) => k ^ 1,
                k => k,
            };
            let sign = if odd.contains(&i) { -1.0 } else { 1.0 };
            let scale = d[i].abs().max(1.0);
            assert!((d[i] - sign * dm[j]).abs() <= 1e-12 * scale, "component {i}: {} vs {}", d[i], dm[j]);
        }
        let fz = m.normal_loads(&x);
        let w = m.vehicle.mass_kg * GRAVITY;
        assert!((fz.iter().sum::<f64>() - w).abs() < 1e-9 * w);
    }

    /// The prepared model gives the same derivative and observation bit for bit as the
    /// unprepared one, with load transfer (every wheel off its static load, one lifted), a heated
    /// contact, for the Magic Formula and its ATIIM modification; and one evaluation asking
    /// for more gives the same values bit for bit.
    #[test]
    fn prepared_tyres_change_no_bit() {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("vehicles/sedan.toml");
        for kind in [TyreModelKind::Pacejka, TyreModelKind::AtiimPacejka] {
            let v = VehicleFile::load(&p).unwrap().build(&p, kind).unwrap();
            let roll = v.roll.clone().unwrap();
            let env = Environment {
                mu: 0.15,
                surface_temp_c: -3.0,
                regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
                road: vehsim_core::vehicle::road::Road::FLAT,
            };
            let (plain, prepared) = (Roll4Dof::new(v.clone(), roll.clone()), Roll4Dof::new(v, roll).prepared_for(&env));
            let mut x = plain.initial_state(0.0, 0.0, 0.2, 10.0);
            for ay in [0.0, 1.5, 80.0] {
                (x[ix::VY], x[ix::R], x[ix::PHI], x[ix::AX_LAG], x[ix::AY_LAG]) = (0.3, 0.2, 0.01, 0.4, ay);
                for (i, k) in [0.02, -0.01, 0.05, 0.0].iter().enumerate() {
                    x[ix::KAPPA + i] = *k;
                }
                for temp in [-3.0, -1.0] {
                    let u = Inputs {
                        steer_rad: 0.05,
                        drive_torque_nm: 300.0,
                        contact_temp_c: [temp, -3.0, temp, -2.0],
                        ..Inputs::default()
                    };
                    let (a, b) = (crate::everything(&plain, &x, &u, &env), crate::everything(&prepared, &x, &u, &env));
                    assert_eq!(a, b, "{kind:?} ay {ay} temp {temp}");
                    assert!(a.0.iter().all(|v| v.is_finite()));
                    // the engine's shared evaluation: the separate calls' values, bit for bit
                    for m in [&plain, &prepared] {
                        crate::assert_shared_evaluation(m, &x, &u, &env);
                    }
                }
            }
            assert!(plain.normal_loads(&x).contains(&0.0), "the last state lifts a wheel");
        }
    }

    /// At rest with no input nothing moves and nothing is non-finite.
    #[test]
    fn standstill_is_an_equilibrium() {
        let m = sedan();
        let env = Environment {
            mu: 0.15,
            surface_temp_c: -3.0,
            regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
            road: vehsim_core::vehicle::road::Road::FLAT,
        };
        let x = m.initial_state(0.0, 0.0, 0.0, 0.0);
        let d = m.derivatives(&x, &Inputs::default(), &env);
        assert!(d.iter().all(|v| *v == 0.0), "{d:?}");
    }

    #[test]
    fn ackermann_inner_wheel_steers_more_and_mirrors() {
        let (l, t) = (2.8, 1.6);
        let (fl, fr) = front_steer_angles(0.1, 1.0, l, t);
        assert!(fl > 0.1 && fr < 0.1);
        // Ideal Ackermann: cot(outer) - cot(inner) = t / L.
        assert!(((1.0 / fr.tan() - 1.0 / fl.tan()) - t / l).abs() < 1e-12);
        let (ml, mr) = front_steer_angles(-0.1, 1.0, l, t);
        assert!((ml + fr).abs() < 1e-15 && (mr + fl).abs() < 1e-15);
        assert_eq!(front_steer_angles(0.1, 0.0, l, t), (0.1, 0.1));
    }
}

use nalgebra::SVector;
use vehsim_core::contact::TyreContact;
use vehsim_core::vehicle::{Environment, Extras, Inputs, Observation, VehicleModel};

/// Test helper: one evaluation asking for everything: the derivative, the observation and the
/// contact conditions.
fn everything<const N: usize, M: VehicleModel<N>>(
    m: &M,
    x: &SVector<f64, N>,
    u: &Inputs,
    env: &Environment,
) -> (SVector<f64, N>, Observation, [TyreContact; 4]) {
    let (mut o, mut c) = (Observation::default(), [TyreContact::default(); 4]);
    let d = m.evaluate(x, u, env, Extras { observation: Some(&mut o), contacts: Some(&mut c[..M::TYRES]) });
    (d, o, c)
}

/// Test helper: `VehicleModel::evaluate` gives the same derivative, observation and contact
/// conditions bit for bit whatever it is asked for (the engine's contact estimate and output
/// rows rely on it).
fn assert_shared_evaluation<const N: usize, M: VehicleModel<N>>(
    m: &M,
    x: &SVector<f64, N>,
    u: &Inputs,
    env: &Environment,
) {
    let (k, o, c) = everything(m, x, u, env);
    assert_eq!(m.derivatives(x, u, env), k);
    assert_eq!(m.observe(x, u, env), o);
    let mut d = [TyreContact::default(); 4];
    assert_eq!(m.evaluate(x, u, env, Extras { observation: None, contacts: Some(&mut d[..M::TYRES]) }), k);
    assert_eq!(c, d);
    // not trivially empty (a lifted wheel transmits nothing, so not every tyre)
    assert!(c[..M::TYRES].iter().any(|t| t.friction_force_n > 0.0 && t.slide_speed_mps > 0.0), "{c:?}");
}
