//! The names of the tyre providers a manoeuvre can select (`tyre_model = "pacejka"`).

use std::str::FromStr;

/// Names of the tyre providers a spec can select.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum TyreModelKind {
    /// Linear in slip, stiffness proportional to load ([`LinearTyre`](super::LinearTyre)).
    Linear,
    /// Third-order brush polynomial with theoretical-slip combination ([`PolynomialTyre`](super::PolynomialTyre)).
    Polynomial,
    /// Magic Formula MF 5.2 / PAC2002 ([`PacejkaTyre`](super::PacejkaTyre)).
    Pacejka,
    /// Dugoff, eq. 5.2–5.4 with the lateral term C_alpha tan(alpha) ([`DugoffTyre`](super::DugoffTyre)).
    Dugoff,
    /// Dugoff with the temperature factor H, eq. 5.5–5.6 ([`DugoffThermalTyre`](super::DugoffThermalTyre)).
    DugoffThermal,
    /// ATIIM-modified Magic Formula, eq. 5.8–5.17 ([`AtiimPacejkaTyre`](super::AtiimPacejkaTyre)).
    AtiimPacejka,
}

choice_names!(TyreModelKind {
    Linear => "linear",
    Polynomial => "polynomial",
    Pacejka => "pacejka",
    Dugoff => "dugoff",
    DugoffThermal => "dugoff_thermal",
    AtiimPacejka => "atiim_pacejka",
});

impl FromStr for TyreModelKind {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Self::parse(s).ok_or_else(|| format!("unknown tyre model '{s}'; allowed: {}", Self::allowed()))
    }
}
