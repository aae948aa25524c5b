//! Material properties of ice, water and tread rubber (dissertation Table 4.1, §4.1.6, Table 3.4).
//!
//! All values SI. Temperatures in degC where the name ends `_c`; differences in K.
//!
//! Errata applied: the ice density of Table 4.1 is 917 kg/m^3 (the table prints
//! g/m^3); its 2.25 W/(m K) "heat transfer coefficient" is the thermal conductivity of ice; the
//! specific heat of ice (2050 J/(kg K)) is not in the table and is added here. Gent's relation
//! (eq. 4.24) gives Young's modulus in MPa.
//!
//! Of eq. 4.25–4.28 we keep only eq. 4.26, the definition of diffusivity a = k / (rho c). The chain
//! Shore A -> E -> expansion coefficient (eq. 4.25, Grüneisen) -> diffusivity is not physical: the
//! thermal expansion coefficient does not enter heat conduction, so the diffusivity cannot follow
//! from it. Eq. 4.27 is Fourier's law (used throughout) and eq. 4.28 (expansion from the loaded
//! radius) has no thermal role here. The Shore A hardness is still used: through Gent's E it sets
//! the shear stiffness of the tread brush (see [`Compound::brush_stiffness_pa_per_m`]), which decides
//! how much of the patch slides at a given slip.

/// Melting point of ice at atmospheric pressure, degC.
pub const MELT_C: f64 = 0.0;

/// Thermal properties of one solid (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solid {
    /// Thermal conductivity k, W/(m K). Ice 2.25; tread rubber 0.2–0.35.
    pub conductivity_w_mk: f64,
    /// Density rho, kg/m^3. Ice 917; tread rubber 1100–1200.
    pub density_kg_m3: f64,
    /// Specific heat c, J/(kg K). Ice 2050; tread rubber 1500–2000.
    pub specific_heat_j_kgk: f64,
}

impl Solid {
    /// Thermal diffusivity a = k / (rho c), m^2/s (eq. 4.26). Ice ~1.2e-6; rubber ~1.2e-7.
    pub fn diffusivity_m2_s(&self) -> f64 {
        self.conductivity_w_mk / (self.density_kg_m3 * self.specific_heat_j_kgk)
    }

    /// Thermal effusivity e = sqrt(k rho c), W s^0.5/(m^2 K). Ice ~2060; rubber ~700.
    /// Two semi-infinite bodies in perfect contact share a surface heat flux in the ratio of
    /// their effusivities (same contact time) — this is how heat is partitioned.
    pub fn effusivity(&self) -> f64 {
        (self.conductivity_w_mk * self.density_kg_m3 * self.specific_heat_j_kgk).sqrt()
    }
}

/// Ice (Table 4.1 with errata 2).
pub const ICE: Solid = Solid { conductivity_w_mk: 2.25, density_kg_m3: 917.0, specific_heat_j_kgk: 2050.0 };

/// Latent heat of fusion of ice, J/kg (Table 4.1: 330 000; the handbook value is 333 500).
pub const LATENT_HEAT_J_KG: f64 = 330_000.0;

/// Dynamic viscosity of water near 0 degC, Pa s (Table 4.1: 0.00182; handbook 0.00179).
pub const WATER_VISCOSITY_PA_S: f64 = 0.00182;

/// Young's modulus from Shore A hardness by Gent's relation (eq. 4.24), MPa.
/// `shore_a`: 0 < S < 100 (the relation diverges at 100); tyre treads 50–75 give 2.5–6 MPa.
/// Returns `None` outside (0, 99].
pub fn gent_modulus_mpa(shore_a: f64) -> Option<f64> {
    if !(shore_a.is_finite() && shore_a > 0.0 && shore_a <= 99.0) {
        return None;
    }
    Some(0.0981 * (56.0 + 7.62336 * shore_a) / (0.137505 * (254.0 - 2.54 * shore_a)))
}

/// A tread compound: thermal properties plus hardness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compound {
    /// Thermal properties of the tread rubber.
    pub solid: Solid,
    /// Shore A hardness at the test temperature, 0–99 (tyres 50–75).
    pub shore_a: f64,
}

impl Compound {
    /// Generic passenger-tyre tread (k 0.25 W/(m K), rho 1150 kg/m^3, c 1800 J/(kg K); typical
    /// filled-SBR handbook values — the dissertation gives none) with the given hardness.
    pub fn generic(shore_a: f64) -> Self {
        Compound {
            solid: Solid { conductivity_w_mk: 0.25, density_kg_m3: 1150.0, specific_heat_j_kgk: 1800.0 },
            shore_a,
        }
    }

    /// Young's modulus, Pa (Gent, eq. 4.24); 4 MPa if the hardness is out of range (checked by the spec).
    pub fn youngs_modulus_pa(&self) -> f64 {
        gent_modulus_mpa(self.shore_a).unwrap_or(4.0) * 1e6
    }

    /// Brush (tread-element) shear stiffness per unit contact area, Pa/m: G (1 - void) / depth with
    /// G = E / 3 (incompressible rubber). `tread_depth_m` 0.002–0.010; `void_ratio` 0–0.6.
    /// A tread element deflected by d carries a shear stress of this times d.
    pub fn brush_stiffness_pa_per_m(&self, tread_depth_m: f64, void_ratio: f64) -> f64 {
        self.youngs_modulus_pa() / 3.0 * (1.0 - void_ratio).max(0.05) / tread_depth_m.max(1e-4)
    }
}

/// Shore A hardness of the dissertation's tyres (Table 3.4, average of tread block, sidewall and
/// shoulder) at 19.9, -3 and -10 degC. Tire A is the SRTT P225/60R16; B the Pirelli P235/55R19
/// all-season; D a 215/60R16 winter tyre; E a 215/60R16 directional all-season.
pub(crate) const TABLE_3_4: [(&str, [f64; 3]); 4] =
    [("A", [64.7, 67.3, 69.3]), ("B", [66.3, 66.2, 68.2]), ("D", [56.5, 52.0, 52.3]), ("E", [68.2, 68.5, 68.3])];

/// Preset names accepted by [`preset_shore_a`].
pub const PRESETS: [&str; 5] = ["srtt", "tire_a", "tire_b", "tire_d", "tire_e"];

/// Shore A of a Table 3.4 tyre at `temp_c`, interpolated linearly between the three measurement
/// temperatures (clamped outside -10..19.9 degC). `name`: one of [`PRESETS`] ("srtt" = Tire A).
pub fn preset_shore_a(name: &str, temp_c: f64) -> Option<f64> {
    let key = match name {
        "srtt" | "tire_a" => "A",
        "tire_b" => "B",
        "tire_d" => "D",
        "tire_e" => "E",
        _ => return None,
    };
    let (_, v) = TABLE_3_4.iter().find(|(k, _)| *k == key)?;
    let temps = [19.9, -3.0, -10.0];
    let t = if temp_c.is_finite() { temp_c.clamp(-10.0, 19.9) } else { -3.0 };
    Some(if t >= -3.0 {
        let u = (t - -3.0) / (19.9 - -3.0);
        v[1] + u * (v[0] - v[1])
    } else {
        let u = (t - temps[2]) / (temps[1] - temps[2]);
        v[2] + u * (v[1] - v[2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gent_matches_hand_computation_and_rejects_out_of_range() {
        // S = 65: 0.0981*(56+495.5184)/(0.137505*(254-165.1)) = 54.1040/12.2242 = 4.426 MPa.
        let e = gent_modulus_mpa(65.0).unwrap();
        assert!((e - 4.426).abs() < 0.01, "{e}");
        assert!(gent_modulus_mpa(100.0).is_none());
        assert!(gent_modulus_mpa(f64::NAN).is_none());
    }

    #[test]
    fn ice_properties_follow_from_definitions() {
        assert!((ICE.diffusivity_m2_s() - 2.25 / (917.0 * 2050.0)).abs() < 1e-15);
        assert!((ICE.effusivity() - (2.25f64 * 917.0 * 2050.0).sqrt()).abs() < 1e-9);
    }

    #[test]
    fn presets_hit_table_values_at_measurement_temperatures() {
        assert!((preset_shore_a("srtt", -3.0).unwrap() - 67.3).abs() < 1e-12);
        assert!((preset_shore_a("tire_d", -10.0).unwrap() - 52.3).abs() < 1e-12);
        assert!((preset_shore_a("tire_e", 19.9).unwrap() - 68.2).abs() < 1e-12);
        assert!(preset_shore_a("nope", 0.0).is_none());
    }
}
