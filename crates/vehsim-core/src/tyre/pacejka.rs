//! Magic Formula tyre (MF 5.2 / PAC2002 equations): pure and combined slip Fx, Fy and Mz.
//!
//! Equations: H. B. Pacejka, *Tyre and Vehicle Dynamics*, 2nd ed., section 4.3.2 (eq. 4.E1–4.E67),
//! the PAC2002 set that `.tir` files with `PROPERTY_FILE_FORMAT = 'PAC2002'` or `'MF_05'` carry.
//! With dfz = (Fz - Fz0') / Fz0', Fz0' = FNOMIN * LFZO:
//!
//! ```text
//! pure Fx:  kx = kappa + SHx,  SHx = (PHX1 + PHX2 dfz) LHX
//!           Dx = (PDX1 + PDX2 dfz)(1 - PDX3 gx^2) LMUX' Fz,   Cx = PCX1 LCX
//!           Ex = (PEX1 + PEX2 dfz + PEX3 dfz^2)(1 - PEX4 sgn kx) LEX  (<= 1)
//!           Kx = Fz (PKX1 + PKX2 dfz) exp(PKX3 dfz) LKX',  Bx = Kx / (Cx Dx)
//!           SVx = Fz (PVX1 + PVX2 dfz) LVX LMUX'
//!           Fx0 = Dx sin(Cx atan(Bx kx - Ex (Bx kx - atan(Bx kx)))) + SVx
//! pure Fy:  ay = alpha + SHy,  SHy = (PHY1 + PHY2 dfz) LHY + PHY3 gy
//!           Dy = (PDY1 + PDY2 dfz)(1 - PDY3 gy^2) LMUY' Fz,  Cy = PCY1 LCY
//!           Ey = (PEY1 + PEY2 dfz)(1 - (PEY3 + PEY4 gy) sgn ay) LEY  (<= 1)
//!           Ky = PKY1 Fz0' sin(2 atan(Fz / (PKY2 Fz0'))) (1 - PKY3 |gy|) LKY',  By = Ky / (Cy Dy)
//!           SVy = Fz ((PVY1 + PVY2 dfz) LVY + (PVY3 + PVY4 dfz) gy) LMUY'
//! combined: Fx = Gxa Fx0,  Gxa = cos(Cxa atan(Bxa as - Exa(...))) / Gxa0,  as = alpha + RHX1,
//!           Bxa = RBX1 cos(atan(RBX2 kappa)) LXAL, Cxa = RCX1, Exa = REX1 + REX2 dfz
//!           Fy = Gyk Fy0 + SVyk,  Gyk likewise with ks = kappa + RHY1 + RHY2 dfz,
//!           Byk = RBY1 cos(atan(RBY2 (alpha - RBY3))) LYKA, Cyk = RCY1, Eyk = REY1 + REY2 dfz,
//!           SVyk = mu_y Fz (RVY1 + RVY2 dfz + RVY3 gy) cos(atan(RVY4 alpha)) sin(RVY5 atan(RVY6 kappa)) LVYKA
//! ```
//!
//! gx = camber LGAX, gy = camber LGAY. Mz: see below.
//!
//! Surface friction: `LMUX' = LMUX mu_surface / mu_reference` (likewise LMUY'), so a coefficient set
//! fitted on a road of friction `mu_reference` (1.0 for dry-road files) is scaled to the surface.
//! Optionally the slip stiffnesses follow the friction too, `LKX' = LKX (mu_surface /
//! mu_reference)^stiffness_mu_exponent` (a vehsim extension, default exponent 0 = plain MF).
//!
//! Sign conventions. PAC2002 files are written in the ISO / TYDEX W-axis system (x forward, y
//! left, z up) with the slip angle tan(alpha_file) = V_y / |V_x|, so the cornering stiffness PKY1 is
//! negative. vehsim uses alpha = -atan(V_y / |V_x|) (positive alpha gives positive Fy), so a file
//! with PKY1 < 0 is evaluated at alpha_file = -alpha and its Fy, Fx and Mz are used as they are
//! (same axes). ISO camber is a right-hand rotation about x (top of the wheel to the right); vehsim's
//! camber is positive with the top to the left, so camber_file = -camber for such files. A file with
//! PKY1 > 0 is taken to use vehsim's signs already and is evaluated unchanged. Kappa is positive when
//! driving in both systems.
//!
//! Tyre side. A `.tir` file describes a tyre measured for one side of the vehicle (`[MODEL]
//! TYRESIDE = 'LEFT'` or `'RIGHT'`, LEFT when absent); the same tyre mounted on the other side is
//! its mirror image (y -> -y): Fx(-alpha, -camber), -Fy(-alpha, -camber), -Mz(-alpha, -camber)
//! ([`PacejkaTyre::mounted_on`]), so conicity and ply-steer do not act the same way on both sides.
//! The vehicle models mount it per wheel (docs/tyres.md, "Tyre side"); a tyre without
//! side-dependent coefficients ([`MfCoefficients::side_dependent`]) is its own mirror image.
//!
//! Combined slip without R-coefficients. PAC2002 implementations read an absent coefficient as 0,
//! so a file without RBX1/RCX1 (RBY1/RCY1) has Gxa = cos(0) = 1 (Gyk = 1): no interaction, each
//! force keeps its pure-slip value (a friction square). vehsim does the same (the `auto` and
//! `magic_formula` methods) and warns that the combined forces may exceed a friction ellipse. The
//! normalised-slip friction ellipse of [`super::combine`] is only used when asked for
//! (`combined = "ellipse"`): with reference slips kappa_r = Dx/Kx, alpha_r = Dy/|Ky|, weights w_x,
//! w_y and equivalent slips kappa_eq, alpha_eq, Fx = Fx0(0) + w_x (Fx0(kappa_eq) - Fx0(0)) and
//! likewise Fy, so pure slip is exact (including the shifts) and the zero-slip offsets Fx0(0),
//! Fy0(0) keep the result continuous at the origin.
//!
//! Aligning moment (MF 5.2 / PAC2002 combined slip, eq. 4.E71–4.E78): Mz = -t Fy' + Mzr + s Fx with
//! the trail and residual moment at the equivalent slip angles
//! alpha_eq = atan(sqrt(tan^2 alpha + (Kx/Ky)^2 kappa^2)) sgn(alpha), Fy' = Fy - SVyk and
//! s = R0 (SSZ1 + SSZ2 Fy/Fz0' + (SSZ3 + SSZ4 dfz) camber) LS.

use std::f64::consts::FRAC_2_PI;

use super::combine::{equivalent, mf_cos, mf_sin, mf_sin_slope, normalised, positive, sgn};
use super::{TyreForces, TyreInput, TyreModel};

macro_rules! mf_coefficients {
    ($( $field:ident = $name:literal, $default:expr, $doc:literal; )*) => {
        /// Magic Formula coefficients in SI, named as in `.tir` files (upper case there).
        ///
        /// Dimensional ones: `fnomin` (N), `unloaded_radius` (m). All others are dimensionless
        /// (angles inside them in rad). Absent optional coefficients are 0, absent scaling factors 1.
        #[derive(Debug, Clone, PartialEq)]
        pub struct MfCoefficients {
            $( #[doc = $doc] pub $field: f64, )*
        }

        impl MfCoefficients {
            /// Every coefficient name read from a `.tir` file or an inline table.
            pub const NAMES: &'static [&'static str] = &[$($name),*];

            /// Build from a lookup by name; the names of absent required coefficients are pushed to
            /// `missing`.
            pub fn from_lookup(get: impl Fn(&str) -> Option<f64>, missing: &mut Vec<&'static str>) -> Self {
                Self {
                    $( $field: match get($name) {
                        Some(v) => v,
                        None => {
                            let d: Option<f64> = $default;
                            match d {
                                Some(d) => d,
                                None => { missing.push($name); 0.0 }
                            }
                        }
                    }, )*
                }
            }
        }
    };
}

mf_coefficients! {
    fnomin = "FNOMIN", None, "Nominal load, N (passenger tyres 3000–6000).";
    unloaded_radius = "UNLOADED_RADIUS", None, "Free tyre radius, m (0.28–0.40).";
    lfzo = "LFZO", Some(1.0), "Scale of the nominal load.";
    lcx = "LCX", Some(1.0), "Scale of Cx.";
    lmux = "LMUX", Some(1.0), "Scale of the longitudinal peak friction.";
    lex = "LEX", Some(1.0), "Scale of Ex.";
    lkx = "LKX", Some(1.0), "Scale of Kx.";
    lhx = "LHX", Some(1.0), "Scale of SHx.";
    lvx = "LVX", Some(1.0), "Scale of SVx.";
    lgax = "LGAX", Some(1.0), "Scale of camber for Fx.";
    lcy = "LCY", Some(1.0), "Scale of Cy.";
    lmuy = "LMUY", Some(1.0), "Scale of the lateral peak friction.";
    ley = "LEY", Some(1.0), "Scale of Ey.";
    lky = "LKY", Some(1.0), "Scale of Ky.";
    lhy = "LHY", Some(1.0), "Scale of SHy.";
    lvy = "LVY", Some(1.0), "Scale of SVy.";
    lgay = "LGAY", Some(1.0), "Scale of camber for Fy.";
    ltr = "LTR", Some(1.0), "Scale of the peak pneumatic trail.";
    lres = "LRES", Some(1.0), "Scale of the residual-torque offset.";
    lgaz = "LGAZ", Some(1.0), "Scale of camber for Mz.";
    lxal = "LXAL", Some(1.0), "Scale of the alpha influence on Fx.";
    lyka = "LYKA", Some(1.0), "Scale of the kappa influence on Fy.";
    lvyka = "LVYKA", Some(1.0), "Scale of the kappa-induced Fy.";
    ls = "LS", Some(1.0), "Scale of the moment arm s of Fx in Mz.";
    pcx1 = "PCX1", None, "Shape factor Cx (1.4–1.8).";
    pdx1 = "PDX1", None, "Longitudinal friction at Fz0' (dry road 1.0–1.3).";
    pdx2 = "PDX2", Some(0.0), "Variation of mu_x with load (-0.2–0).";
    pdx3 = "PDX3", Some(0.0), "Variation of mu_x with camber squared.";
    pex1 = "PEX1", Some(0.0), "Curvature Ex at Fz0' (-1–1).";
    pex2 = "PEX2", Some(0.0), "Variation of Ex with load.";
    pex3 = "PEX3", Some(0.0), "Variation of Ex with load squared.";
    pex4 = "PEX4", Some(0.0), "Ex asymmetry driving/braking.";
    pkx1 = "PKX1", None, "Slip stiffness Kx/Fz at Fz0' (dry road 15–30).";
    pkx2 = "PKX2", Some(0.0), "Variation of Kx/Fz with load.";
    pkx3 = "PKX3", Some(0.0), "Exponent of Kx/Fz with load.";
    phx1 = "PHX1", Some(0.0), "Horizontal shift SHx at Fz0'.";
    phx2 = "PHX2", Some(0.0), "Variation of SHx with load.";
    pvx1 = "PVX1", Some(0.0), "Vertical shift SVx/Fz at Fz0'.";
    pvx2 = "PVX2", Some(0.0), "Variation of SVx/Fz with load.";
    pcy1 = "PCY1", None, "Shape factor Cy (1.2–1.5).";
    pdy1 = "PDY1", None, "Lateral friction at Fz0' (dry road 0.9–1.2).";
    pdy2 = "PDY2", Some(0.0), "Variation of mu_y with load.";
    pdy3 = "PDY3", Some(0.0), "Variation of mu_y with camber squared.";
    pey1 = "PEY1", Some(0.0), "Curvature Ey at Fz0'.";
    pey2 = "PEY2", Some(0.0), "Variation of Ey with load.";
    pey3 = "PEY3", Some(0.0), "Ey asymmetry (sign of alpha).";
    pey4 = "PEY4", Some(0.0), "Ey asymmetry with camber.";
    pky1 = "PKY1", None, "Maximum Ky/Fz0' (ISO files: negative, -10 to -25).";
    pky2 = "PKY2", None, "Load (in Fz0') at which Ky peaks (1.5–3); must not be 0.";
    pky3 = "PKY3", Some(0.0), "Variation of Ky with camber.";
    phy1 = "PHY1", Some(0.0), "Horizontal shift SHy at Fz0', rad.";
    phy2 = "PHY2", Some(0.0), "Variation of SHy with load.";
    phy3 = "PHY3", Some(0.0), "Variation of SHy with camber.";
    pvy1 = "PVY1", Some(0.0), "Vertical shift SVy/Fz at Fz0'.";
    pvy2 = "PVY2", Some(0.0), "Variation of SVy/Fz with load.";
    pvy3 = "PVY3", Some(0.0), "Variation of SVy/Fz with camber.";
    pvy4 = "PVY4", Some(0.0), "Variation of SVy/Fz with camber and load.";
    ssz1 = "SSZ1", Some(0.0), "Moment arm of Fx in Mz, s/R0, at Fz0'.";
    ssz2 = "SSZ2", Some(0.0), "Variation of s/R0 with Fy/Fz0'.";
    ssz3 = "SSZ3", Some(0.0), "Variation of s/R0 with camber.";
    ssz4 = "SSZ4", Some(0.0), "Variation of s/R0 with camber and load.";
    qbz1 = "QBZ1", Some(0.0), "Trail slope Bt at Fz0'.";
    qbz2 = "QBZ2", Some(0.0), "Variation of Bt with load.";
    qbz3 = "QBZ3", Some(0.0), "Variation of Bt with load squared.";
    qbz4 = "QBZ4", Some(0.0), "Variation of Bt with camber.";
    qbz5 = "QBZ5", Some(0.0), "Variation of Bt with |camber|.";
    qbz9 = "QBZ9", Some(0.0), "Slope Br of the residual torque.";
    qbz10 = "QBZ10", Some(0.0), "Slope Br of the residual torque per By Cy.";
    qcz1 = "QCZ1", Some(0.0), "Shape Ct of the pneumatic trail.";
    qdz1 = "QDZ1", Some(0.0), "Peak trail Dt/(R0 Fz/Fz0').";
    qdz2 = "QDZ2", Some(0.0), "Variation of peak trail with load.";
    qdz3 = "QDZ3", Some(0.0), "Variation of peak trail with camber.";
    qdz4 = "QDZ4", Some(0.0), "Variation of peak trail with camber squared.";
    qdz6 = "QDZ6", Some(0.0), "Peak residual torque Dr/(Fz R0).";
    qdz7 = "QDZ7", Some(0.0), "Variation of Dr with load.";
    qdz8 = "QDZ8", Some(0.0), "Variation of Dr with camber.";
    qdz9 = "QDZ9", Some(0.0), "Variation of Dr with camber and load.";
    qez1 = "QEZ1", Some(0.0), "Trail curvature Et at Fz0'.";
    qez2 = "QEZ2", Some(0.0), "Variation of Et with load.";
    qez3 = "QEZ3", Some(0.0), "Variation of Et with load squared.";
    qez4 = "QEZ4", Some(0.0), "Variation of Et with the sign of alpha_t.";
    qez5 = "QEZ5", Some(0.0), "Variation of Et with camber and the sign of alpha_t.";
    qhz1 = "QHZ1", Some(0.0), "Trail horizontal shift at Fz0'.";
    qhz2 = "QHZ2", Some(0.0), "Variation of the trail shift with load.";
    qhz3 = "QHZ3", Some(0.0), "Variation of the trail shift with camber.";
    qhz4 = "QHZ4", Some(0.0), "Variation of the trail shift with camber and load.";
    rbx1 = "RBX1", Some(0.0), "Slope of Gxa (5–20); absent = 0: Gxa = 1.";
    rbx2 = "RBX2", Some(0.0), "Variation of the Gxa slope with kappa.";
    rcx1 = "RCX1", Some(0.0), "Shape of Gxa (about 1).";
    rex1 = "REX1", Some(0.0), "Curvature of Gxa.";
    rex2 = "REX2", Some(0.0), "Variation of the Gxa curvature with load.";
    rhx1 = "RHX1", Some(0.0), "Shift of Gxa.";
    rby1 = "RBY1", Some(0.0), "Slope of Gyk (5–15).";
    rby2 = "RBY2", Some(0.0), "Variation of the Gyk slope with alpha.";
    rby3 = "RBY3", Some(0.0), "Alpha shift of the Gyk slope.";
    rcy1 = "RCY1", Some(0.0), "Shape of Gyk (about 1).";
    rey1 = "REY1", Some(0.0), "Curvature of Gyk.";
    rey2 = "REY2", Some(0.0), "Variation of the Gyk curvature with load.";
    rhy1 = "RHY1", Some(0.0), "Shift of Gyk.";
    rhy2 = "RHY2", Some(0.0), "Variation of the Gyk shift with load.";
    rvy1 = "RVY1", Some(0.0), "Kappa-induced side force SVyk/(mu_y Fz).";
    rvy2 = "RVY2", Some(0.0), "Variation of SVyk with load.";
    rvy3 = "RVY3", Some(0.0), "Variation of SVyk with camber.";
    rvy4 = "RVY4", Some(0.0), "Variation of SVyk with alpha.";
    rvy5 = "RVY5", Some(0.0), "Variation of SVyk with kappa.";
    rvy6 = "RVY6", Some(0.0), "Variation of SVyk with atan(kappa).";
}

impl MfCoefficients {
    /// (name, value) of the coefficients that make a tyre differ from its mirror image (y -> -y:
    /// alpha, camber, Fy and Mz change sign, kappa and Fx do not). Each adds a term that is even in
    /// (alpha, camber) to Fy or Mz, or odd to Fx, or makes a shape factor depend on the sign of
    /// alpha or camber:
    /// the zero-slip shifts of Fy (PHY1, PHY2, PVY1, PVY2: conicity and ply steer), the Ey
    /// asymmetry PEY3, the Gxa shift RHX1, the Gyk slope shift RBY3, the kappa-induced side force
    /// at zero camber (RVY1, RVY2), the trail shift (QHZ1, QHZ2), the camber-linear trail terms
    /// QBZ4, QDZ3, the trail-curvature asymmetry QEZ4, the residual moment at zero camber (QDZ6,
    /// QDZ7) and the Fx moment arm at zero camber SSZ1. With all of them 0 the formulas are odd in
    /// (alpha, camber) for Fy and Mz and even for Fx (tests/tyre_side.rs checks both the list and
    /// that no other coefficient breaks the symmetry).
    pub fn side_dependent(&self) -> [(&'static str, f64); 17] {
        [
            ("PHY1", self.phy1),
            ("PHY2", self.phy2),
            ("PVY1", self.pvy1),
            ("PVY2", self.pvy2),
            ("PEY3", self.pey3),
            ("RHX1", self.rhx1),
            ("RBY3", self.rby3),
            ("RVY1", self.rvy1),
            ("RVY2", self.rvy2),
            ("QHZ1", self.qhz1),
            ("QHZ2", self.qhz2),
            ("QBZ4", self.qbz4),
            ("QDZ3", self.qdz3),
            ("QEZ4", self.qez4),
            ("QDZ6", self.qdz6),
            ("QDZ7", self.qdz7),
            ("SSZ1", self.ssz1),
        ]
    }
}

/// How combined slip is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Combination {
    /// The MF weighting functions Gxa, Gyk (needs RBX1, RCX1, RBY1, RCY1).
    MagicFormula,
    /// The normalised-slip friction ellipse of [`super::combine`].
    Ellipse,
}

/// Multipliers a modifier applies on top of the coefficients (the ATIIM temperature law of
/// [`super::atiim`]): peak friction (multiplies LMUX', LMUY') and slip stiffness (multiplies LKX',
/// LKY'), dimensionless. [`Scale::ONE`] is the plain Magic Formula, bit for bit (x * 1.0 == x).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// Factor on the longitudinal peak friction (LMUX').
    pub mu_x: f64,
    /// Factor on the longitudinal slip stiffness (LKX').
    pub k_x: f64,
    /// Factor on the lateral peak friction (LMUY').
    pub mu_y: f64,
    /// Factor on the cornering stiffness (LKY').
    pub k_y: f64,
}

impl Scale {
    /// No modification.
    pub const ONE: Scale = Scale { mu_x: 1.0, k_x: 1.0, mu_y: 1.0, k_y: 1.0 };
}

/// Side of the vehicle: the side a tyre property file was measured for (`.tir` `[MODEL]
/// TYRESIDE`) or the side a wheel is on (left: +y).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TyreSide {
    /// `TYRESIDE = 'LEFT'` (the PAC2002 default when the key is absent).
    Left = 0,
    /// `TYRESIDE = 'RIGHT'`.
    Right = 1,
}

impl TyreSide {
    /// Left, then right.
    pub const BOTH: [TyreSide; 2] = [TyreSide::Left, TyreSide::Right];
}

/// A built Magic Formula tyre with per-file constants precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct PacejkaTyre {
    /// The coefficients as read (SI).
    pub coeffs: MfCoefficients,
    /// Friction of the surface the coefficients were fitted on (1.0 for dry-road files); the
    /// surface friction of each input scales LMUX/LMUY by mu_surface / mu_reference.
    pub mu_reference: f64,
    /// Exponent p of LKX' = LKX (mu_surface/mu_reference)^p (0 = stiffness independent of surface).
    pub stiffness_mu_exponent: f64,
    /// Combined-slip method.
    pub combination: Combination,
    /// Whether Mz is computed: the spec asked for it (`aligning_moment = true`) and the file has
    /// aligning-moment coefficients (QCZ1, QDZ1 != 0); Mz = 0 otherwise. It costs about as much as
    /// Fx and Fy together (three more transcendental functions), so it is off by default.
    pub has_mz: bool,
    /// The side the coefficients were measured for (TYRESIDE); see [`PacejkaTyre::mounted_on`].
    pub measured_side: TyreSide,
    // Precomputed.
    fz0p: f64,
    /// -1 when the tyre is mounted on the side opposite `measured_side` (mirrored), else 1.
    mirror: f64,
    /// -1 for ISO files (PKY1 < 0): alpha_file = -alpha, camber_file = -camber.
    sign_iso: f64,
}

/// The load-independent part of the pure-slip formulas: what depends on the surface friction and
/// the camber but neither on the load nor on the ATIIM modifier ([`Scale`]). [`super::Prepared`]
/// keeps it, so a model whose loads change (load transfer) prepares it once per surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Surface {
    /// LMUX (mu_surface / mu_reference), LMUY likewise (before the modifier).
    lmux0: f64,
    lmuy0: f64,
    /// (mu_surface / mu_reference)^stiffness_mu_exponent.
    rk: f64,
    gy: f64,
    cx: f64,
    cy: f64,
    /// 1 - PDX3 gx^2, 1 - PDY3 gy^2, 1 - PKY3 |gy|.
    cam_dx: f64,
    cam_dy: f64,
    cam_ky: f64,
    /// PHY3 gy.
    shy_cam: f64,
    ey_asym: f64,
}

/// Per-input quantities of the pure-slip formulas (they depend on the load, friction and camber,
/// not on the slips: [`super::Prepared`] keeps them). The `*0` fields are the products before
/// the modifier's factors enter ([`Pure::scaled`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pure {
    dfz: f64,
    lmuy: f64,
    gy: f64,
    // Fx0
    shx: f64,
    cx: f64,
    dx: f64,
    ex0: f64,
    bx: f64,
    kx: f64,
    svx: f64,
    // Fy0
    shy: f64,
    cy: f64,
    dy: f64,
    ey0: f64,
    ey_asym: f64,
    by: f64,
    ky: f64,
    svy: f64,
    muy: f64,
    // Before the modifier: LMUX', LMUY' without it, and Dx / (LMUX' Fz), Kx, SVx / LMUX',
    // mu_y / LMUY', Ky, SVy / LMUY' without its factors.
    fz: f64,
    lmux0: f64,
    lmuy0: f64,
    dx0: f64,
    kx0: f64,
    svx0: f64,
    muy0: f64,
    ky0: f64,
    svy0: f64,
}

impl Pure {
    /// The same quantities with the modifier `m` applied: bit for bit what
    /// [`PacejkaTyre::pure`] gives with `m` at this load and surface (the factors enter last in
    /// every product, in the same order).
    #[inline(always)]
    pub(crate) fn scaled(&self, m: &Scale) -> Pure {
        let lmux = self.lmux0 * m.mu_x;
        let lmuy = self.lmuy0 * m.mu_y;
        let dx = self.dx0 * lmux * self.fz;
        let kx = self.kx0 * m.k_x;
        let muy = self.muy0 * lmuy;
        let dy = muy * self.fz;
        let ky = self.ky0 * m.k_y;
        Pure {
            lmuy,
            dx,
            kx,
            bx: safe_div(kx, self.cx * dx),
            svx: self.svx0 * lmux,
            muy,
            dy,
            ky,
            by: safe_div(ky, self.cy * dy),
            svy: self.svy0 * lmuy,
            ..*self
        }
    }

    /// max(|Dx|, |Dy|) (N) of [`Self::scaled`] by `m` (inlined, the unused quantities drop out).
    #[inline]
    pub(crate) fn peak_scaled(&self, m: &Scale) -> f64 {
        let p = self.scaled(m);
        p.dx.abs().max(p.dy.abs())
    }
}

impl PacejkaTyre {
    /// Build from validated coefficients. `combination` None picks the MF functions (absent R
    /// coefficients are 0, as PAC2002 implementations read them).
    pub fn new(
        coeffs: MfCoefficients,
        mu_reference: f64,
        stiffness_mu_exponent: f64,
        combination: Option<Combination>,
        aligning_moment: bool,
    ) -> Self {
        let combination = combination.unwrap_or(Combination::MagicFormula);
        let fz0p = coeffs.fnomin * coeffs.lfzo;
        let sign_iso = if coeffs.pky1 < 0.0 { -1.0 } else { 1.0 };
        let has_mz = aligning_moment && coeffs.qcz1 != 0.0 && coeffs.qdz1 != 0.0;
        Self {
            coeffs,
            mu_reference,
            stiffness_mu_exponent,
            combination,
            has_mz,
            measured_side: TyreSide::Left,
            fz0p,
            mirror: 1.0,
            sign_iso,
        }
    }

    /// The same tyre mounted on `side`: as measured on its own side, mirrored (y -> -y) on the
    /// other, i.e. F'(alpha, camber) = (Fx, -Fy, -Mz)(-alpha, -camber). Conicity and ply-steer
    /// (PHY*, PVY*, the Mz shifts) then act mirror-symmetrically on the two sides of the car.
    pub fn mounted_on(&self, side: TyreSide) -> Self {
        let mut t = self.clone();
        t.mirror = if side == self.measured_side { 1.0 } else { -1.0 };
        t
    }

    /// Whether this instance evaluates the mirrored tyre.
    pub fn is_mirrored(&self) -> bool {
        self.mirror < 0.0
    }

    /// Whether the coefficients are mirror-symmetric: every coefficient of
    /// [`MfCoefficients::side_dependent`] is 0, so the tyre equals its mirror image (the same
    /// forces on either side of the car) and [`Self::mounted_on`] need not mirror it.
    pub fn is_mirror_symmetric(&self) -> bool {
        self.coeffs.side_dependent().iter().all(|&(_, v)| v == 0.0)
    }

    /// Scaled nominal load Fz0' = FNOMIN LFZO, N.
    pub fn scaled_nominal_load(&self) -> f64 {
        self.fz0p
    }

    #[inline(always)]
    fn pure(&self, fz: f64, mu_surface: f64, camber_file: f64, m: &Scale) -> Pure {
        self.at_load(&self.surface(mu_surface, camber_file), fz, m)
    }

    /// The load-independent part of [`Self::pure`] for a surface of friction `mu_surface` and
    /// file camber `camber_file`.
    pub(crate) fn surface(&self, mu_surface: f64, camber_file: f64) -> Surface {
        let c = &self.coeffs;
        let r = mu_surface / self.mu_reference;
        let rk = if self.stiffness_mu_exponent == 0.0 {
            1.0
        } else if self.stiffness_mu_exponent == 0.5 {
            r.sqrt()
        } else {
            r.powf(self.stiffness_mu_exponent)
        };
        let gx = camber_file * c.lgax;
        let gy = camber_file * c.lgay;
        Surface {
            lmux0: c.lmux * r,
            lmuy0: c.lmuy * r,
            rk,
            gy,
            cx: c.pcx1 * c.lcx,
            cy: c.pcy1 * c.lcy,
            cam_dx: 1.0 - c.pdx3 * gx * gx,
            cam_dy: 1.0 - c.pdy3 * gy * gy,
            cam_ky: 1.0 - c.pky3 * gy.abs(),
            shy_cam: c.phy3 * gy,
            ey_asym: c.pey3 + c.pey4 * gy,
        }
    }

    /// [`Self::pure`] at load `fz` on the prepared surface `s`, with the modifier `m`.
    #[inline(always)]
    pub(crate) fn at_load(&self, s: &Surface, fz: f64, m: &Scale) -> Pure {
        let c = &self.coeffs;
        let dfz = (fz - self.fz0p) / self.fz0p;
        let gy = s.gy;

        let shx = (c.phx1 + c.phx2 * dfz) * c.lhx;
        let cx = s.cx;
        let dx0 = (c.pdx1 + c.pdx2 * dfz) * s.cam_dx;
        let ex0 = (c.pex1 + c.pex2 * dfz + c.pex3 * dfz * dfz) * c.lex;
        let kexp = if c.pkx3 == 0.0 { 1.0 } else { (c.pkx3 * dfz).exp() };
        let kx0 = fz * (c.pkx1 + c.pkx2 * dfz) * kexp * c.lkx * s.rk;
        let svx0 = fz * (c.pvx1 + c.pvx2 * dfz) * c.lvx;

        let shy = (c.phy1 + c.phy2 * dfz) * c.lhy + s.shy_cam;
        let cy = s.cy;
        let muy0 = (c.pdy1 + c.pdy2 * dfz) * s.cam_dy;
        let ey0 = (c.pey1 + c.pey2 * dfz) * c.ley;
        // sin(2 atan(x)) = 2x / (1 + x^2).
        let xk = safe_div(fz, c.pky2 * self.fz0p);
        let ky0 = c.pky1 * self.fz0p * (2.0 * xk / (1.0 + xk * xk)) * s.cam_ky * c.lky * s.rk;
        let svy0 = fz * ((c.pvy1 + c.pvy2 * dfz) * c.lvy + (c.pvy3 + c.pvy4 * dfz) * gy);
        Pure {
            dfz,
            lmuy: 0.0,
            gy,
            shx,
            cx,
            dx: 0.0,
            ex0,
            bx: 0.0,
            kx: 0.0,
            svx: 0.0,
            shy,
            cy,
            dy: 0.0,
            ey0,
            ey_asym: s.ey_asym,
            by: 0.0,
            ky: 0.0,
            svy: 0.0,
            muy: 0.0,
            fz,
            lmux0: s.lmux0,
            lmuy0: s.lmuy0,
            dx0,
            kx0,
            svx0,
            muy0,
            ky0,
            svy0,
        }
        .scaled(m)
    }

    #[inline]
    fn ex(&self, p: &Pure, kx: f64) -> f64 {
        (p.ex0 * (1.0 - self.coeffs.pex4 * sgn(kx))).min(1.0)
    }

    #[inline]
    fn ey(p: &Pure, ay: f64) -> f64 {
        (p.ey0 * (1.0 - p.ey_asym * sgn(ay))).min(1.0)
    }

    /// Fx0 without SVx at shifted slip kx.
    #[inline]
    fn fx0_core(&self, p: &Pure, kx: f64) -> f64 {
        mf_sin(p.bx, p.cx, p.dx, self.ex(p, kx), kx)
    }

    /// Fy0 without SVy at shifted slip ay.
    #[inline]
    fn fy0_core(p: &Pure, ay: f64) -> f64 {
        mf_sin(p.by, p.cy, p.dy, Self::ey(p, ay), ay)
    }

    /// Denominator guard of the G functions: |G0| is kept >= 0.1 (G0 is 1 without shifts).
    fn g0_guard(g0: f64) -> f64 {
        if g0.abs() < 0.1 {
            0.1_f64.copysign(g0)
        } else {
            g0
        }
    }

    /// (Fx, Fy, Mz) in file axes at file slip angle `a` and camber `g`, with `p` the pure-slip
    /// quantities of the load and conditions.
    #[inline(always)]
    fn eval(&self, p: &Pure, fz: f64, kappa: f64, a: f64, g: f64) -> (f64, f64, f64) {
        let c = &self.coeffs;
        let (fx, fy, fy_prime);
        match self.combination {
            Combination::MagicFormula => {
                let kx = kappa + p.shx;
                let ay = a + p.shy;
                let fx0 = self.fx0_core(p, kx) + p.svx;
                let fy0 = Self::fy0_core(p, ay) + p.svy;
                // Gxa. cos(atan(x)) = 1 / sqrt(1 + x^2).
                let r2 = c.rbx2 * kappa;
                let bxa = c.rbx1 / (1.0 + r2 * r2).sqrt() * c.lxal;
                let exa = (c.rex1 + c.rex2 * p.dfz).min(1.0);
                let gxa0 = if c.rhx1 == 0.0 { 1.0 } else { Self::g0_guard(mf_cos(bxa, c.rcx1, exa, c.rhx1)) };
                // (G0 = 1 exactly without a shift: the division is skipped, same value)
                let gxa = if c.rhx1 == 0.0 {
                    mf_cos(bxa, c.rcx1, exa, a + c.rhx1)
                } else {
                    mf_cos(bxa, c.rcx1, exa, a + c.rhx1) / gxa0
                };
                // Gyk.
                let shyk = c.rhy1 + c.rhy2 * p.dfz;
                let r2 = c.rby2 * (a - c.rby3);
                let byk = c.rby1 / (1.0 + r2 * r2).sqrt() * c.lyka;
                let eyk = (c.rey1 + c.rey2 * p.dfz).min(1.0);
                let gyk0 = if shyk == 0.0 { 1.0 } else { Self::g0_guard(mf_cos(byk, c.rcy1, eyk, shyk)) };
                let gyk = if shyk == 0.0 {
                    mf_cos(byk, c.rcy1, eyk, kappa + shyk)
                } else {
                    mf_cos(byk, c.rcy1, eyk, kappa + shyk) / gyk0
                };
                let rv = c.rvy1 + c.rvy2 * p.dfz + c.rvy3 * p.gy;
                let svyk = if rv == 0.0 {
                    0.0
                } else {
                    self.dvyk(p, fz, rv, a) * (c.rvy5 * (c.rvy6 * kappa).atan()).sin() * c.lvyka
                };
                fx = gxa * fx0;
                fy = gyk * fy0 + svyk;
                fy_prime = fy - svyk;
            }
            Combination::Ellipse => {
                // Pure values at zero slip (ply-steer / conicity offsets); 0 without shifts.
                let (fx00, fy00) = self.offsets(p);
                let kref = safe_div(p.dx, p.kx).abs();
                let aref = safe_div(p.dy, p.ky).abs();
                let (s, wx, wy) = normalised(safe_div(kappa, kref), safe_div(a, aref));
                let fxe = self.fx0_core(p, equivalent(sgn(kappa), s, kref) + p.shx) + p.svx;
                let fye = Self::fy0_core(p, equivalent(sgn(a), s, aref) + p.shy) + p.svy;
                fx = fx00 + wx * (fxe - fx00);
                fy = fy00 + wy * (fye - fy00);
                fy_prime = fy;
            }
        }
        let mz = if self.has_mz { self.mz(p, fz, kappa, a, g, (fy, fy_prime), fx) } else { 0.0 };
        (fx, fy, mz)
    }

    /// The zero-slip offsets Fx0(0), Fy0(0) of the ellipse combination (0 without shifts).
    fn offsets(&self, p: &Pure) -> (f64, f64) {
        let fx00 = if p.shx == 0.0 { p.svx } else { self.fx0_core(p, p.shx) + p.svx };
        let fy00 = if p.shy == 0.0 { p.svy } else { Self::fy0_core(p, p.shy) + p.svy };
        (fx00, fy00)
    }

    /// Peak of the kappa-induced side force, mu_y Fz (RVY1 + RVY2 dfz + RVY3 gy) cos(atan(RVY4 a)),
    /// for `rv` = RVY1 + RVY2 dfz + RVY3 gy.
    #[inline]
    fn dvyk(&self, p: &Pure, fz: f64, rv: f64, a: f64) -> f64 {
        let r4 = self.coeffs.rvy4 * a;
        p.muy * fz * rv / (1.0 + r4 * r4).sqrt()
    }

    /// The bound on |F| (N) in file axes at file slip angle `a` (see
    /// [`TyreModel::peak_friction`]): from the pure-slip peaks and the G functions' values at zero
    /// slip, without evaluating the forces (their sines are not needed).
    fn bound(&self, p: &Pure, fz: f64, kappa: f64, a: f64) -> f64 {
        let c = &self.coeffs;
        match self.combination {
            Combination::MagicFormula => {
                let r2 = c.rbx2 * kappa;
                let bxa = c.rbx1 / (1.0 + r2 * r2).sqrt() * c.lxal;
                let exa = (c.rex1 + c.rex2 * p.dfz).min(1.0);
                let gxa0 = if c.rhx1 == 0.0 { 1.0 } else { Self::g0_guard(mf_cos(bxa, c.rcx1, exa, c.rhx1)) };
                let shyk = c.rhy1 + c.rhy2 * p.dfz;
                let r2 = c.rby2 * (a - c.rby3);
                let byk = c.rby1 / (1.0 + r2 * r2).sqrt() * c.lyka;
                let eyk = (c.rey1 + c.rey2 * p.dfz).min(1.0);
                let gyk0 = if shyk == 0.0 { 1.0 } else { Self::g0_guard(mf_cos(byk, c.rcy1, eyk, shyk)) };
                let rv = c.rvy1 + c.rvy2 * p.dfz + c.rvy3 * p.gy;
                let dvyk = if rv == 0.0 { 0.0 } else { self.dvyk(p, fz, rv, a) };
                let xmax = (p.dx.abs() + p.svx.abs()) / gxa0.abs();
                let ymax = (p.dy.abs() + p.svy.abs()) / gyk0.abs() + dvyk.abs() * c.lvyka.abs();
                // the plain root: forces are far from overflow (`hypot` costs several times more)
                (xmax * xmax + ymax * ymax).sqrt()
            }
            Combination::Ellipse => {
                let (fx00, fy00) = self.offsets(p);
                p.dx.abs().max(p.dy.abs()) + (fx00.abs() + p.svx.abs()).hypot(fy00.abs() + p.svy.abs())
            }
        }
    }

    /// Aligning moment in file axes (MF 5.2 / PAC2002 combined slip):
    /// Mz = -t(alpha_t,eq) Fy' + Mzr(alpha_r,eq) + s Fx, with Fy' the combined Fy without the
    /// kappa-induced SVyk, s = R0 (SSZ1 + SSZ2 Fy/Fz0' + (SSZ3 + SSZ4 dfz) camber) LS and the
    /// equivalent slip angles of eq. 4.E77–4.E78. At kappa = 0 the
    /// equivalent angles are the plain ones (taken as they are, so pure slip is bit-exact).
    #[allow(clippy::too_many_arguments)]
    fn mz(&self, p: &Pure, fz: f64, kappa: f64, a: f64, g: f64, (fy, fy_prime): (f64, f64), fx: f64) -> f64 {
        let c = &self.coeffs;
        let dfz = p.dfz;
        let gz = g * c.lgaz;
        let lky_lmuy = safe_div(c.lky, p.lmuy);
        let sht = c.qhz1 + c.qhz2 * dfz + (c.qhz3 + c.qhz4 * dfz) * gz;
        let at = a + sht;
        let shf = p.shy + safe_div(p.svy, p.ky);
        let ar = a + shf;
        // Equivalent slip angles: atan(sqrt(tan^2 a + (Kx/Ky)^2 kappa^2)) sgn(a).
        let (at_eq, ar_eq) = if kappa == 0.0 {
            (at, ar)
        } else {
            let r = safe_div(p.kx, p.ky) * kappa;
            let r2 = r * r;
            let eq = |x: f64| {
                let t = x.tan();
                (t * t + r2).sqrt().atan() * sgn(x)
            };
            (eq(at), eq(ar))
        };
        let bt = (c.qbz1 + c.qbz2 * dfz + c.qbz3 * dfz * dfz) * (1.0 + c.qbz4 * gz + c.qbz5 * gz.abs()) * lky_lmuy;
        let ct = c.qcz1;
        let dt = fz
            * (c.qdz1 + c.qdz2 * dfz)
            * (1.0 + c.qdz3 * gz + c.qdz4 * gz * gz)
            * (c.unloaded_radius / self.fz0p)
            * c.ltr;
        let et_asym = c.qez4 + c.qez5 * gz;
        let et_sign = if et_asym == 0.0 { 1.0 } else { 1.0 + et_asym * FRAC_2_PI * (bt * ct * at).atan() };
        let et = ((c.qez1 + c.qez2 * dfz + c.qez3 * dfz * dfz) * et_sign).min(1.0);
        let cos_a = a.cos();
        let t = mf_cos(bt, ct, et, at_eq) * dt * cos_a;
        let br = c.qbz9 * lky_lmuy + c.qbz10 * p.by * p.cy;
        let dr = fz * ((c.qdz6 + c.qdz7 * dfz) * c.lres + (c.qdz8 + c.qdz9 * dfz) * gz) * c.unloaded_radius * p.lmuy;
        let x = br * ar_eq;
        let mzr = dr / (1.0 + x * x).sqrt() * cos_a;
        let s_arm = c.unloaded_radius * (c.ssz1 + c.ssz2 * (fy / self.fz0p) + (c.ssz3 + c.ssz4 * dfz) * g) * c.ls;
        -t * fy_prime + mzr + s_arm * fx
    }

    fn file_angles(&self, i: &TyreInput) -> (f64, f64) {
        let s = self.sign_iso * self.mirror;
        (s * i.alpha_rad, s * i.camber_rad)
    }
}

/// a / b, or 0 when b is 0 (a degenerate coefficient set must not produce NaN).
#[inline]
fn safe_div(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        0.0
    } else {
        a / b
    }
}

#[inline]
fn inactive(i: &TyreInput) -> bool {
    !positive(i.fz_n) || !positive(i.mu_surface) || !i.fz_n.is_finite()
}

impl PacejkaTyre {
    /// Forces with the modifier `m` applied (see [`Scale`]).
    pub fn forces_scaled(&self, i: &TyreInput, m: &Scale) -> TyreForces {
        if inactive(i) {
            return TyreForces::default();
        }
        let (a, g) = self.file_angles(i);
        self.forces_from(&self.pure(i.fz_n, i.mu_surface, g, m), i, a, g)
    }

    /// Forces at file angles (`a`, `g`) with the pure-slip quantities `p` of the input's load.
    #[inline]
    fn forces_from(&self, p: &Pure, i: &TyreInput, a: f64, g: f64) -> TyreForces {
        let (fx, fy, mz) = self.eval(p, i.fz_n, i.kappa, a, g);
        TyreForces { fx_n: fx, fy_n: self.mirror * fy, mz_nm: self.mirror * mz }
    }

    /// [`TyreModel::prepare`] of this curve, for any modifier (the prepared coefficients are
    /// those without it; [`Self::forces_prepared_scaled`] applies it).
    pub fn prepare_scaled(&self, i: &TyreInput) -> super::Prepared {
        let g = self.file_angles(i).1;
        super::Prepared {
            input: *i,
            pacejka: (!inactive(i)).then(|| self.pure(i.fz_n, i.mu_surface, g, &Scale::ONE)),
            surface: Some(self.surface(i.mu_surface, g)),
        }
    }

    /// `f` of the pure-slip coefficients of `i` (file camber `g`) with the modifier `m`, from
    /// what `prepared` (made by [`Self::prepare_scaled`] of this instance) holds for it: its load
    /// part at the same load and surface, its surface part at another load, else computed in
    /// full; `None` when `i` is inactive. The coefficients are the same bit for bit as
    /// [`Self::pure`]'s; those built here live on the stack for the call (no copy into a slot).
    #[inline(always)]
    fn with_prepared_pure<R>(
        &self,
        prepared: &super::Prepared,
        i: &TyreInput,
        g: f64,
        m: &Scale,
        f: impl FnOnce(&Pure) -> R,
    ) -> Option<R> {
        match (&prepared.pacejka, &prepared.surface) {
            // (an active prepared input with the same load and friction: `i` is active too)
            (Some(p), _) if prepared.matches_load(i) => Some(if *m == Scale::ONE { f(p) } else { f(&p.scaled(m)) }),
            _ if inactive(i) => None,
            (_, Some(s)) if prepared.matches_surface(i) => Some(f(&self.at_load(s, i.fz_n, m))),
            _ => Some(f(&self.pure(i.fz_n, i.mu_surface, g, m))),
        }
    }

    /// [`Self::forces_scaled`] using the coefficients `prepared` holds for `i` (made by
    /// [`Self::prepare_scaled`] of this instance), the same values bit for bit.
    #[inline]
    pub fn forces_prepared_scaled(&self, prepared: &super::Prepared, i: &TyreInput, m: &Scale) -> TyreForces {
        let (a, g) = self.file_angles(i);
        // The prepared load (the usual case) inlined on its own, so the scaled coefficients need
        // not be built on the stack for an outlined call.
        if let Some(p) = &prepared.pacejka {
            if prepared.matches_load(i) {
                return self.forces_from(&p.scaled(m), i, a, g);
            }
        }
        self.with_prepared_pure(prepared, i, g, m, |p| self.forces_from(p, i, a, g)).unwrap_or_default()
    }

    /// [`Self::peak_friction_scaled`] using the coefficients `prepared` holds for `i` (made by
    /// [`Self::prepare_scaled`] of this instance), the same value bit for bit.
    pub fn peak_friction_prepared_scaled(&self, prepared: &super::Prepared, i: &TyreInput, m: &Scale) -> f64 {
        let (a, g) = self.file_angles(i);
        self.with_prepared_pure(prepared, i, g, m, |p| self.bound(p, i.fz_n, i.kappa, a) / i.fz_n).unwrap_or(0.0)
    }

    /// [`TyreModel::peak_force_floor_prepared`] with the modifier `m` applied: max(|Dx|, |Dy|)
    /// at the prepared load, scaled (N). `Self::bound` is at least that in both combinations
    /// (Magic Formula: the hypot of (|Dx| + |SVx|) / |Gxa0| and of (|Dy| + |SVy|) / |Gyk0| plus
    /// |DVyk|, with |G0| <= 1; ellipse: max(|Dx|, |Dy|) plus a non-negative term), for finite
    /// slips (with which the bound is finite); the modifier scales Dx and Dy inside it alike.
    pub fn peak_force_floor_prepared_scaled(
        &self,
        prepared: &super::Prepared,
        i: &TyreInput,
        m: &Scale,
    ) -> Option<f64> {
        match &prepared.pacejka {
            Some(p) if prepared.matches_load(i) && i.kappa.is_finite() && i.alpha_rad.is_finite() => {
                Some(p.peak_scaled(m))
            }
            _ => None,
        }
    }

    /// [`TyreModel::peak_friction`] with the modifier `m` applied.
    pub fn peak_friction_scaled(&self, i: &TyreInput, m: &Scale) -> f64 {
        if inactive(i) {
            return 0.0;
        }
        let (a, g) = self.file_angles(i);
        let p = self.pure(i.fz_n, i.mu_surface, g, m);
        self.bound(&p, i.fz_n, i.kappa, a) / i.fz_n
    }

    /// [`TyreModel::longitudinal_stiffness`] with the modifier `m` applied.
    pub fn longitudinal_stiffness_scaled(&self, i: &TyreInput, m: &Scale) -> f64 {
        if inactive(i) {
            return 0.0;
        }
        let (_, g) = self.file_angles(i);
        let p = self.pure(i.fz_n, i.mu_surface, g, m);
        mf_sin_slope(p.bx, p.cx, p.dx, self.ex(&p, p.shx), p.shx)
    }

    /// [`TyreModel::cornering_stiffness`] with the modifier `m` applied.
    pub fn cornering_stiffness_scaled(&self, i: &TyreInput, m: &Scale) -> f64 {
        if inactive(i) {
            return 0.0;
        }
        let (_, g) = self.file_angles(i);
        let p = self.pure(i.fz_n, i.mu_surface, g, m);
        self.sign_iso * mf_sin_slope(p.by, p.cy, p.dy, Self::ey(&p, p.shy), p.shy)
    }
}

impl TyreModel for PacejkaTyre {
    fn name(&self) -> &'static str {
        "pacejka"
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        self.forces_scaled(i, &Scale::ONE)
    }

    fn on_ice(&self, law: &super::ice::SurfaceFriction) -> Option<std::sync::Arc<dyn TyreModel>> {
        Some(std::sync::Arc::new(super::ice::IceSurfaceTyre::pacejka(self.clone(), law.clone())))
    }

    fn prepare(&self, i: &TyreInput) -> super::Prepared {
        self.prepare_scaled(i)
    }

    fn forces_prepared(&self, prepared: &super::Prepared, i: &TyreInput) -> TyreForces {
        match &prepared.pacejka {
            // (an active prepared input with the same load and friction: `i` is active too)
            Some(p) if prepared.matches_load(i) => {
                let (a, g) = self.file_angles(i);
                self.forces_from(p, i, a, g)
            }
            _ => self.forces_prepared_scaled(prepared, i, &Scale::ONE),
        }
    }

    /// A guaranteed bound on |F|/Fz at this input. With the MF combined-slip functions it is
    /// hypot(X, Y)/Fz with X = (|Dx| + |SVx|)/|Gxa0| and Y = (|Dy| + |SVy|)/|Gyk0| + |SVyk| peak: the
    /// published functions weight Fx and Fy separately and do not enforce an ellipse, so the
    /// combined force can exceed max(Dx, Dy) (by up to ~40 % in the worst direction). With the
    /// ellipse fallback the bound is max(|Dx|, |Dy|)/Fz plus the vertical shifts.
    fn peak_friction(&self, i: &TyreInput) -> f64 {
        self.peak_friction_scaled(i, &Scale::ONE)
    }

    fn peak_friction_prepared(&self, prepared: &super::Prepared, i: &TyreInput) -> f64 {
        match &prepared.pacejka {
            // (an active prepared input with the same load and friction: `i` is active too)
            Some(p) if prepared.matches_load(i) => {
                let (a, _) = self.file_angles(i);
                self.bound(p, i.fz_n, i.kappa, a) / i.fz_n
            }
            _ => self.peak_friction_prepared_scaled(prepared, i, &Scale::ONE),
        }
    }

    /// max(|Dx|, |Dy|) at the prepared load ([`Self::peak_force_floor_prepared_scaled`] without
    /// a modifier).
    fn peak_force_floor_prepared(&self, prepared: &super::Prepared, i: &TyreInput) -> Option<f64> {
        self.peak_force_floor_prepared_scaled(prepared, i, &Scale::ONE)
    }

    /// dFx/dkappa at kappa = 0, alpha = 0 (the MF Gxa is 1 at alpha = 0), including the shifts.
    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        self.longitudinal_stiffness_scaled(i, &Scale::ONE)
    }

    /// dFy/dalpha (vehsim alpha) at kappa = 0, alpha = 0.
    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        self.cornering_stiffness_scaled(i, &Scale::ONE)
    }
}
