//! The vehicle's own physical parameters as discovery candidates, generated from one declared
//! table ([`TABLE`]): every body key of the vehicle spec that the replay reads, with its
//! validation bound (the spec's, [`vehsim_core::vehicle::body_bounds`]) and the range the fit
//! searches, relative to the spec's value, with the reason for that range. Each entry is one
//! candidate ([`super::effects::Effect::VehicleParam`]): adding an entry adds a candidate.
//!
//! A candidate's one parameter is a factor s on the spec's value (dimensionless, no-effect value
//! 1): the replay runs the vehicle with the key set to s times its value ([`scaled_vehicle`]), so
//! every quantity derived from it (static axle loads from the mass and the CG position, the
//! wheelbase) follows as it does when the spec itself says so, and the improved vehicle.toml
//! writes the key itself (`mass_kg = s m`), which replays to the same bits.
//!
//! Keys left out, and why: `track_m` is read only by load transfer, as the ratio h/track with the
//! load-transfer height h, which `load_transfer` fits already; `cg_height_m` is read only by the
//! 4-DOF baseline, as that same height. The road-wheel steer is measured, so no steering ratio is
//! read (the CSV's `steer` is the road-wheel angle).

use super::effects::ParamDef;
use vehsim_core::error::Bound;
use vehsim_core::vehicle::body_bounds as bb;
use vehsim_core::vehicle::Vehicle;

/// One physical parameter of the vehicle that the replay reads.
#[derive(Debug, Clone, Copy)]
pub struct VehicleParam {
    /// The candidate's name in reports (`vehsim synth --effect NAME`).
    pub effect: &'static str,
    /// Its parameter: the factor on the spec's value.
    pub param: &'static str,
    /// The spec key's validation bound (its key is the vehicle file's key).
    pub bound: Bound,
    /// The factor's range in the fit, [lo, hi] (relative to the spec's value).
    pub fit: [f64; 2],
    /// Where that range comes from.
    pub source: &'static str,
    /// The factor `vehsim synth` hides by default.
    pub synth: f64,
    /// What the candidate says, in one sentence.
    pub describe: &'static str,
    /// The vehicle's field holding the key's value (SI units as the key's).
    pub field: fn(&mut Vehicle) -> &mut f64,
}

/// Every vehicle parameter discovery fits; the first keeps the name `yaw_inertia` that earlier
/// reports used (it was a hand-listed candidate with the same range).
pub const TABLE: [VehicleParam; 4] = [
    VehicleParam {
        effect: "yaw_inertia",
        param: "yaw_inertia_scale",
        bound: bb::YAW_INERTIA,
        fit: [0.3, 3.0],
        source: "estimates of I_z from m (a b) or from the wheelbase vary by a factor of about 2 across \
                 body styles; a factor of 3 either way also covers a mistyped value",
        synth: 1.4,
        describe: "the yaw moment of inertia differs from the vehicle's by a factor",
        field: |v| &mut v.yaw_inertia_kgm2,
    },
    VehicleParam {
        effect: "mass",
        param: "mass_scale",
        bound: bb::MASS,
        fit: [0.7, 1.5],
        source: "kerb to gross mass: a passenger car's payload is up to about 45 % of its kerb mass; \
                 0.7 covers a spec written at gross mass for a car driven light",
        synth: 1.25,
        describe: "the vehicle's mass (and with it the static axle loads) differs from the spec's by a factor",
        field: |v| &mut v.mass_kg,
    },
    VehicleParam {
        effect: "cg_to_front_axle",
        param: "cg_to_front_axle_scale",
        bound: bb::CG_TO_FRONT,
        fit: [0.7, 1.3],
        source: "load and fuel move the CG by up to about 10 % of the wheelbase; 30 % of the distance \
                 also covers a mis-measured CG",
        synth: 1.2,
        describe: "the CG lies farther from (or nearer to) the front axle than the spec says",
        field: |v| &mut v.a_m,
    },
    VehicleParam {
        effect: "cg_to_rear_axle",
        param: "cg_to_rear_axle_scale",
        bound: bb::CG_TO_REAR,
        fit: [0.7, 1.3],
        source: "as cg_to_front_axle",
        synth: 1.2,
        describe: "the CG lies farther from (or nearer to) the rear axle than the spec says",
        field: |v| &mut v.b_m,
    },
];

/// Number of vehicle-parameter candidates.
pub const N: usize = TABLE.len();

/// The fit's parameter of each entry: its factor, start 1 (the spec's value), search scale 0.1,
/// the fitting range, no-effect value 1.
pub const DEFS: [ParamDef; N] = {
    let mut out = [ParamDef { name: "", unit: "1", start: 1.0, scale: 0.1, lo: 1.0, hi: 1.0, null: Some(1.0) }; N];
    let mut i = 0;
    while i < N {
        out[i].name = TABLE[i].param;
        out[i].lo = TABLE[i].fit[0];
        out[i].hi = TABLE[i].fit[1];
        i += 1;
    }
    out
};

/// The vehicle with every entry's value multiplied by its factor in `scale` (in [`TABLE`]
/// order); None when every factor is 1 (the vehicle as it is).
pub fn scaled_vehicle(v: &Vehicle, scale: &[f64; N]) -> Option<Vehicle> {
    if scale.iter().all(|&s| s == 1.0) {
        return None;
    }
    let mut out = v.clone();
    for (e, &s) in TABLE.iter().zip(scale) {
        if s != 1.0 {
            *(e.field)(&mut out) *= s;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sedan() -> Vehicle {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let kind = crate::discover::tyre_kind("pacejka").unwrap();
        crate::discover::load_vehicle(&root.join("vehicles/sedan.toml"), None, kind).unwrap()
    }

    /// Every fitting range lies within its key's validation bound for the shipped sedan's values
    /// (a fitted value is one `vehsim run` accepts), contains the no-effect factor 1 and the
    /// default synthesis factor; every entry names a distinct key, candidate and parameter.
    #[test]
    fn fitting_ranges_lie_within_the_declared_bounds() {
        let v = sedan();
        for (i, e) in TABLE.iter().enumerate() {
            let mut w = v.clone();
            let value = *(e.field)(&mut w);
            assert!(e.bound.contains(value * e.fit[0]) && e.bound.contains(value * e.fit[1]), "{}", e.bound.key);
            assert!(e.fit[0] < 1.0 && 1.0 < e.fit[1] && e.fit[0] <= e.synth && e.synth <= e.fit[1], "{}", e.effect);
            assert_eq!((DEFS[i].name, DEFS[i].lo, DEFS[i].hi), (e.param, e.fit[0], e.fit[1]));
            for f in &TABLE[i + 1..] {
                assert!(f.bound.key != e.bound.key && f.effect != e.effect && f.param != e.param);
            }
        }
    }

    /// A factor multiplies exactly its own key (the others keep their bits); all ones is no change.
    #[test]
    fn a_factor_scales_its_own_key_only() {
        let v = sedan();
        assert!(scaled_vehicle(&v, &[1.0; N]).is_none());
        for i in 0..N {
            let mut s = [1.0; N];
            s[i] = 1.25;
            let w = scaled_vehicle(&v, &s).unwrap();
            for (j, e) in TABLE.iter().enumerate() {
                let (mut a, mut b) = (v.clone(), w.clone());
                let (x, y) = (*(e.field)(&mut a), *(e.field)(&mut b));
                assert_eq!(y, if j == i { x * 1.25 } else { x }, "{}", e.bound.key);
            }
        }
    }
}
