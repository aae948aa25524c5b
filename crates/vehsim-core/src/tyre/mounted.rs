//! A tyre mounted on a vehicle: its geometry and one built provider per side of the car.

use std::sync::Arc;

use super::pacejka::TyreSide;
use super::TyreModel;

/// A validated tyre: geometry plus one built provider.
#[derive(Debug, Clone)]
pub struct Tyre {
    /// Name from the spec file.
    pub name: String,
    /// Effective rolling radius, m.
    pub rolling_radius_m: f64,
    /// Unloaded radius, m.
    pub unloaded_radius_m: f64,
    /// Nominal load, N.
    pub nominal_load_n: f64,
    /// Longitudinal relaxation length, m.
    pub relaxation_length_x_m: f64,
    /// The force provider, as measured (a `.tir` tyre on the side its TYRESIDE names).
    pub model: Arc<dyn TyreModel>,
    /// The provider mounted on the vehicle's left and right wheels ([`Tyre::on`]): for a Magic
    /// Formula tyre with side-dependent coefficients the measured tyre on its own side and its
    /// mirror image on the other; for every other tyre `model` itself on both sides.
    pub mounted: [Arc<dyn TyreModel>; 2],
}

impl Tyre {
    /// The provider of a wheel on `side` of the vehicle.
    #[inline]
    pub fn on(&self, side: TyreSide) -> &Arc<dyn TyreModel> {
        &self.mounted[side as usize]
    }

    /// The same tyre on an ice surface whose friction follows `law` ([`super::ice`]): the Magic
    /// Formula providers (pacejka, atiim_pacejka) are wrapped; every other provider is unchanged
    /// (its `mu` stays fixed).
    pub fn on_ice(&self, law: &super::ice::SurfaceFriction) -> Tyre {
        let wrap = |m: &Arc<dyn TyreModel>| m.on_ice(law).unwrap_or_else(|| m.clone());
        let model = wrap(&self.model);
        let mounted = if self.same_on_both_sides() {
            let m = wrap(&self.mounted[0]);
            [m.clone(), m]
        } else {
            [wrap(&self.mounted[0]), wrap(&self.mounted[1])]
        };
        Tyre { model, mounted, ..self.clone() }
    }

    /// Whether the left and right wheels carry the same provider (no side-dependent coefficients).
    pub fn same_on_both_sides(&self) -> bool {
        Arc::ptr_eq(&self.mounted[0], &self.mounted[1])
    }
}
