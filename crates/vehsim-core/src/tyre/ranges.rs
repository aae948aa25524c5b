//! The operating ranges a tyre's data declares as measured (a `.tir` file's slip, slip-angle and
//! load ranges); the plausibility checks flag a run that leaves them.

/// The ranges a tyre file declares (each `None` when not declared). Slip ratio dimensionless
/// (kappa, positive driving), slip angle rad (positive giving positive F_y), load N.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TyreRanges {
    /// Slip-ratio range (min, max), dimensionless (positive driving).
    pub kappa: Option<(f64, f64)>,
    /// Slip-angle range (min, max), rad (positive giving positive F_y).
    pub alpha_rad: Option<(f64, f64)>,
    /// Normal-load range (min, max), N.
    pub fz_n: Option<(f64, f64)>,
}

impl TyreRanges {
    /// Whether any range is declared.
    pub fn any(&self) -> bool {
        self.kappa.is_some() || self.alpha_rad.is_some() || self.fz_n.is_some()
    }
}
