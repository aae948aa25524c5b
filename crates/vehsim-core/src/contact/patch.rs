//! Contact-patch pressure grids: read from CSV, synthesized from load and tyre data, or decoded
//! from a PNG pressure map through its colour bar (dissertation §4.1 module 1, Appendix C.2).
//!
//! Layout: `rows` pixels along the direction of travel, row 0 at the leading edge (the tread
//! enters there); `cols` pixels across the width, column 0 at the right-hand edge seen from above
//! (-y in ISO 8855), increasing toward +y (left). Pixel length `dx_m` (along travel) and width
//! `dy_m` (across). A *track* is one column: the line of pixels a tread element passes through.
//! Pressures are contact pressures on the gross pixel area, Pa (>= 0; 0 = no contact / groove).

use std::path::Path;

use crate::error::{Error, Result};

/// A contact-pressure grid.
#[derive(Debug, Clone, PartialEq)]
pub struct PressureGrid {
    /// Pixels along travel (row 0 = leading edge), >= 1.
    pub rows: usize,
    /// Pixels across the width, >= 1.
    pub cols: usize,
    /// Pixel length along travel, m (typically 1–5 mm).
    pub dx_m: f64,
    /// Pixel width across, m (typically 1–5 mm).
    pub dy_m: f64,
    /// Row-major pressures, Pa, `p_pa[r * cols + c]`.
    pub p_pa: Vec<f64>,
}

impl PressureGrid {
    /// Pressure at (row, col), Pa.
    pub fn p(&self, r: usize, c: usize) -> f64 {
        self.p_pa[r * self.cols + c]
    }

    /// Pixel area, m^2.
    pub fn pixel_area_m2(&self) -> f64 {
        self.dx_m * self.dy_m
    }

    /// Total normal load sum(p) * pixel area, N.
    pub fn load_n(&self) -> f64 {
        self.p_pa.iter().sum::<f64>() * self.pixel_area_m2()
    }

    /// Area of pixels with p > 0, m^2.
    pub fn contact_area_m2(&self) -> f64 {
        self.p_pa.iter().filter(|p| **p > 0.0).count() as f64 * self.pixel_area_m2()
    }

    /// Mean pressure over loaded pixels, Pa (0 for an empty grid).
    pub fn mean_contact_pressure_pa(&self) -> f64 {
        let a = self.contact_area_m2();
        if a > 0.0 {
            self.load_n() / a
        } else {
            0.0
        }
    }

    /// Nested rows for plotting / CSV, in `scale` units (e.g. 1e-3 for kPa).
    pub fn to_rows(&self, scale: f64) -> Vec<Vec<f64>> {
        self.p_pa.chunks(self.cols).map(|r| r.iter().map(|v| v * scale).collect()).collect()
    }

    /// Check shape and values; `file` names the source in the error.
    pub fn validate(&self, file: &Path) -> Result<()> {
        if self.rows == 0 || self.cols == 0 || self.p_pa.len() != self.rows * self.cols {
            return Err(Error::input(
                file,
                format!(
                    "pressure grid has shape {}x{} but {} values; expected rows x cols values, both >= 1",
                    self.rows,
                    self.cols,
                    self.p_pa.len()
                ),
            ));
        }
        if !(self.dx_m.is_finite() && self.dx_m > 0.0 && self.dy_m.is_finite() && self.dy_m > 0.0) {
            return Err(Error::input(file, "pixel length and width must be finite and > 0 m"));
        }
        for (i, p) in self.p_pa.iter().enumerate() {
            if !p.is_finite() || *p < 0.0 {
                return Err(Error::input(
                    file,
                    format!(
                        "row {}, column {}: pressure {p} Pa is not allowed; expected >= 0",
                        i / self.cols + 1,
                        i % self.cols + 1
                    ),
                ));
            }
        }
        if self.load_n() <= 0.0 {
            return Err(Error::input(file, "pressure grid carries no load (all pressures are 0)"));
        }
        Ok(())
    }
}

/// Tread pattern for synthesized patches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreadPattern {
    /// Number of circumferential ribs, 1–8 (1 = slick). Ribs are separated by grooves.
    pub ribs: usize,
    /// Void ratio: groove area / gross area, 0–0.6 (passenger tyres 0.25–0.35).
    pub void_ratio: f64,
    /// Pitch of transverse grooves cutting ribs into blocks, m (0 = ribs only; 0.02–0.04 typical).
    pub block_pitch_m: f64,
}

/// Inputs of a synthesized pressure grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SynthInputs {
    /// Normal load, N (1000–12000).
    pub load_n: f64,
    /// Inflation pressure, Pa (150e3–300e3; 35 psi = 241 kPa).
    pub inflation_pa: f64,
    /// Tread (contact) width at full load, m (about 0.8 x section width; SRTT ~0.18).
    pub tread_width_m: f64,
    /// Rated load (100 % load index), N: sets the shape (SRTT 7000).
    pub rated_load_n: f64,
    /// Camber angle, deg (-6..6); positive shortens and unloads the +y (left) side.
    pub camber_deg: f64,
    /// Tread pattern.
    pub pattern: TreadPattern,
    /// Grid size (rows along travel, cols across), each 4–512.
    pub rows: usize,
    /// Grid pixels across the width, 4–512.
    pub cols: usize,
}

/// Area of the unit superellipse |u|^n + |v|^n <= 1 (Simpson's rule, 1e-6 relative).
fn superellipse_area(n: f64) -> f64 {
    let m = 4000;
    let f = |u: f64| (1.0 - u.powf(n)).max(0.0).powf(1.0 / n);
    let h = 1.0 / m as f64;
    let mut s = f(0.0) + f(1.0);
    for i in 1..m {
        s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    4.0 * s * h / 3.0
}

/// Synthesize a pressure grid (an empirical shape, not a structural model of the tyre):
/// - gross area = load / inflation pressure (carcass stiffness neglected);
/// - outline a superellipse with exponent 2 (oval) at <= 40 % of rated load growing to 6 (nearly
///   rectangular) at 120 %; width grows from 85 % to 100 % of the tread width with load;
/// - pressure across: crowned at low load, raised at the edges (|y/b|^4 term) above 60 % load;
///   along travel (1 - |x/a|^4)^0.5;
/// - camber: the local half-length and pressure fall linearly toward the +y side (trapezoid);
/// - grooves: ribs separated by circumferential grooves and (optionally) transverse grooves, each
///   pixel weighted by its rubber fraction (4 x 4 supersampling);
/// - finally scaled so that sum(p) * pixel area = load exactly.
pub fn synthesize(file: &Path, s: &SynthInputs) -> Result<PressureGrid> {
    let ck = crate::error::Checker::new(file);
    check_synth_inputs(&ck, s)?;
    let rho = s.load_n / s.rated_load_n;
    let b = 0.5 * s.tread_width_m * (0.85 + 0.15 * rho).clamp(0.6, 1.0);
    let n = 2.0 + 4.0 * ((rho - 0.4) / 0.8).clamp(0.0, 1.0);
    let area = s.load_n / s.inflation_pa;
    let a = area / (superellipse_area(n) * b);
    let tc = (2.0 * s.camber_deg.to_radians().sin()).clamp(-0.5, 0.5);
    let a_max = a * (1.0 + tc.abs());
    let len = 2.0 * a_max * 1.06;
    let wid = 2.0 * b * 1.06;
    let dx = len / s.rows as f64;
    let dy = wid / s.cols as f64;
    let edge = 1.5 * ((rho - 0.6) / 0.6).clamp(0.0, 1.0);
    let crown = 0.35 * (1.0 - rho).clamp(0.0, 1.0);
    let tread = Tread::of(s, b);
    let shape = |x: f64, y: f64| -> f64 {
        let eta = y / b;
        if eta.abs() >= 1.0 {
            return 0.0;
        }
        let a_loc = a * (1.0 - tc * eta);
        // superellipse outline: |x/a|^n + |y/b|^n <= 1
        let lim = a_loc * (1.0 - eta.abs().powf(n)).max(0.0).powf(1.0 / n);
        if x.abs() >= lim || lim <= 0.0 {
            return 0.0;
        }
        let xi = x / lim;
        let along = (1.0 - xi.powi(4)).max(0.0).sqrt();
        let across = (1.0 - crown * eta * eta + edge * eta.powi(4)) * (1.0 - tc * eta);
        along * across.max(0.0)
    };
    let mut p = vec![0.0; s.rows * s.cols];
    let sub = 4;
    for r in 0..s.rows {
        for c in 0..s.cols {
            let mut acc = 0.0;
            for i in 0..sub {
                for j in 0..sub {
                    // x positive toward the leading edge (row 0).
                    let x = len / 2.0 - (r as f64 + (i as f64 + 0.5) / sub as f64) * dx;
                    let y = -wid / 2.0 + (c as f64 + (j as f64 + 0.5) / sub as f64) * dy;
                    if tread.rubber(x, y) {
                        acc += shape(x, y);
                    }
                }
            }
            p[r * s.cols + c] = acc / (sub * sub) as f64;
        }
    }
    let total: f64 = p.iter().sum::<f64>() * dx * dy;
    if total.is_nan() || total <= 0.0 {
        return Err(Error::input(file, "synthesized patch is empty; check load, width and void ratio"));
    }
    let k = s.load_n / total;
    p.iter_mut().for_each(|v| *v *= k);
    Ok(PressureGrid { rows: s.rows, cols: s.cols, dx_m: dx, dy_m: dy, p_pa: p })
}

/// Where a synthesized tread has rubber: longitudinal grooves between `ribs` ribs and, with a
/// block pitch, transverse grooves (staggered rib to rib) taking the void ratio's share.
struct Tread {
    /// Half the contact width, m.
    b: f64,
    ribs: usize,
    /// Rib pitch across the width, m.
    pitch: f64,
    /// Longitudinal groove width, m.
    groove_w: f64,
    /// Fraction of each block pitch that is transverse groove.
    void_trans: f64,
    /// Block pitch along travel, m (0: no transverse grooves).
    block_pitch_m: f64,
}

impl Tread {
    /// The tread of `s` over a contact half-width `b` (m).
    fn of(s: &SynthInputs, b: f64) -> Self {
        let ribs = s.pattern.ribs.max(1);
        let (void_long, void_trans) = match (ribs > 1, s.pattern.block_pitch_m > 0.0) {
            (true, true) => (0.5 * s.pattern.void_ratio, 0.5 * s.pattern.void_ratio),
            (true, false) => (s.pattern.void_ratio, 0.0),
            (false, true) => (0.0, s.pattern.void_ratio),
            (false, false) => (0.0, 0.0),
        };
        let groove_w = if ribs > 1 { void_long * 2.0 * b / (ribs - 1) as f64 } else { 0.0 };
        let pitch = 2.0 * b / ribs as f64;
        Tread { b, ribs, pitch, groove_w, void_trans, block_pitch_m: s.pattern.block_pitch_m }
    }

    /// Whether (x, y) is rubber (not a groove); x along travel, y across from the centre, m.
    fn rubber(&self, x: f64, y: f64) -> bool {
        // y measured from the right edge of the tread (0..2b).
        let yy = y + self.b;
        if self.ribs > 1 {
            for k in 1..self.ribs {
                if (yy - k as f64 * self.pitch).abs() < 0.5 * self.groove_w {
                    return false;
                }
            }
        }
        if self.block_pitch_m > 0.0 && self.void_trans > 0.0 {
            let rib = ((yy / self.pitch).floor().max(0.0)) as usize;
            let shift = if rib % 2 == 1 { 0.5 * self.block_pitch_m } else { 0.0 };
            let ph = (x + shift).rem_euclid(self.block_pitch_m) / self.block_pitch_m;
            if ph < self.void_trans {
                return false;
            }
        }
        true
    }
}

/// The synthesis inputs within their ranges (messages name the inputs' own fields).
fn check_synth_inputs(ck: &crate::error::Checker, s: &SynthInputs) -> Result<()> {
    ck.range("load_n", s.load_n, 100.0, 50_000.0)?;
    ck.range("inflation_kpa", s.inflation_pa * 1e-3, 50.0, 1000.0)?;
    ck.range("tread_width_m", s.tread_width_m, 0.03, 0.6)?;
    ck.range("rated_load_n", s.rated_load_n, 100.0, 100_000.0)?;
    ck.range("camber_deg", s.camber_deg, -15.0, 15.0)?;
    ck.range("void_ratio", s.pattern.void_ratio, 0.0, 0.7)?;
    ck.non_negative("block_pitch_m", s.pattern.block_pitch_m)?;
    ck.range("ribs", s.pattern.ribs as f64, 1.0, 12.0)?;
    ck.range("rows", s.rows as f64, 4.0, 512.0)?;
    ck.range("cols", s.cols as f64, 4.0, 512.0)?;
    Ok(())
}

/// Lateral pressure tilt per unit sin(slip angle): the pressure across the patch is multiplied by
/// 1 + t eta (eta = -1 at column 0, +1 at the last column) with t = this x sin(alpha), clamped to
/// +-0.9, then rescaled to the same load. Assumption (no measured map under slip angle is
/// available): under a slip angle the carcass is pushed sideways and loads the shoulder toward
/// which the wheel slides; 2.0 gives +-7 % across the patch at 2 degrees.
pub(crate) const SLIP_ANGLE_TILT: f64 = 2.0;

/// Tilt `grid` for slip angle `alpha_rad` (positive: the wheel slides toward +y, the pressure
/// rises there); the load is unchanged. No-op for alpha = 0 or a single column.
pub fn tilt_for_slip_angle(grid: &mut PressureGrid, alpha_rad: f64) {
    let t = (SLIP_ANGLE_TILT * alpha_rad.sin()).clamp(-0.9, 0.9);
    if t == 0.0 || !t.is_finite() || grid.cols < 2 || grid.p_pa.len() != grid.rows * grid.cols {
        return;
    }
    let before: f64 = grid.p_pa.iter().sum();
    let cols = grid.cols;
    for (k, p) in grid.p_pa.iter_mut().enumerate() {
        let eta = 2.0 * ((k % cols) as f64 + 0.5) / cols as f64 - 1.0;
        *p *= 1.0 + t * eta;
    }
    let after: f64 = grid.p_pa.iter().sum();
    if after > 0.0 {
        grid.p_pa.iter_mut().for_each(|p| *p *= before / after);
    }
}
