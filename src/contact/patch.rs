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

/// Parse a CSV pressure grid: one line per row along travel (leading edge first), one value per
/// column across, in kPa; lines starting with '#' are comments; no header. Every row must have the
/// same number of columns.
pub fn parse_csv(file: &Path, text: &str, dx_m: f64, dy_m: f64) -> Result<PressureGrid> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut p = Vec::new();
    let mut cols = 0usize;
    let mut rows = 0usize;
    for (i, rec) in rdr.records().enumerate() {
        let rec = rec.map_err(|e| Error::input(file, format!("CSV row {}: {e}", i + 1)))?;
        if rec.iter().all(|f| f.is_empty()) {
            continue;
        }
        rows += 1;
        if rows == 1 {
            cols = rec.len();
        } else if rec.len() != cols {
            return Err(Error::input(
                file,
                format!("CSV row {rows}: {} columns, but row 1 has {cols}; every row needs the same number", rec.len()),
            ));
        }
        for (j, f) in rec.iter().enumerate() {
            let v: f64 = f.parse().map_err(|_| {
                Error::input(
                    file,
                    format!(
                        "CSV row {rows}, column {}: {} is not a number (pressure in kPa)",
                        j + 1,
                        crate::error::shown(f)
                    ),
                )
            })?;
            if !v.is_finite() || v < 0.0 {
                return Err(Error::input(
                    file,
                    format!("CSV row {rows}, column {}: negative or non-finite pressure {v} kPa; expected >= 0", j + 1),
                ));
            }
            p.push(v * 1e3);
        }
    }
    if rows == 0 {
        return Err(Error::input(file, "CSV pressure grid is empty; expected rows of pressures in kPa"));
    }
    let g = PressureGrid { rows, cols, dx_m, dy_m, p_pa: p };
    g.validate(file)?;
    Ok(g)
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
    let ribs = s.pattern.ribs.max(1);
    let (void_long, void_trans) = match (ribs > 1, s.pattern.block_pitch_m > 0.0) {
        (true, true) => (0.5 * s.pattern.void_ratio, 0.5 * s.pattern.void_ratio),
        (true, false) => (s.pattern.void_ratio, 0.0),
        (false, true) => (0.0, s.pattern.void_ratio),
        (false, false) => (0.0, 0.0),
    };
    let groove_w = if ribs > 1 { void_long * 2.0 * b / (ribs - 1) as f64 } else { 0.0 };
    let pitch = 2.0 * b / ribs as f64;
    let rubber = |x: f64, y: f64| -> bool {
        // y measured from the right edge of the tread (0..2b).
        let yy = y + b;
        if ribs > 1 {
            for k in 1..ribs {
                if (yy - k as f64 * pitch).abs() < 0.5 * groove_w {
                    return false;
                }
            }
        }
        if s.pattern.block_pitch_m > 0.0 && void_trans > 0.0 {
            let rib = ((yy / pitch).floor().max(0.0)) as usize;
            let shift = if rib % 2 == 1 { 0.5 * s.pattern.block_pitch_m } else { 0.0 };
            let ph = (x + shift).rem_euclid(s.pattern.block_pitch_m) / s.pattern.block_pitch_m;
            if ph < void_trans {
                return false;
            }
        }
        true
    };
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
                    if rubber(x, y) {
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

/// Lateral pressure tilt per unit sin(slip angle): the pressure across the patch is multiplied by
/// 1 + t eta (eta = -1 at column 0, +1 at the last column) with t = this x sin(alpha), clamped to
/// +-0.9, then rescaled to the same load. Assumption (no measured map under slip angle is
/// available): under a slip angle the carcass is pushed sideways and loads the shoulder toward
/// which the wheel slides; 2.0 gives +-7 % across the patch at 2 degrees.
pub const SLIP_ANGLE_TILT: f64 = 2.0;

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

/// How to read a PNG pressure map.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageLayout {
    /// Footprint box in image pixels [x0, y0, x1, y1) (x right, y down); its top row is the
    /// leading edge. Each image pixel becomes one grid pixel.
    pub footprint: [u32; 4],
    /// Colour-bar box [x0, y0, x1, y1); the bar runs vertically, `bar_min` at the bottom.
    pub colour_bar: [u32; 4],
    /// Pressures at the bottom and top of the bar, Pa.
    pub bar_min_pa: f64,
    pub bar_max_pa: f64,
    /// Largest RGB distance (Euclidean, 0–441) at which a footprint pixel still matches the bar;
    /// farther pixels are background (no contact). Typical 40–80.
    pub tolerance: f64,
    /// Physical pixel size along travel and across, m.
    pub dx_m: f64,
    pub dy_m: f64,
}

/// Largest decoded PNG pressure map, bytes (64 MiB: 4096 x 4096 RGBA). Scanned maps are a few
/// hundred pixels a side; the header's size is checked before the frame buffer is allocated, so
/// a short file claiming a huge image is an input error instead of an allocation failure.
pub const MAX_PNG_DECODED_BYTES: usize = 64 << 20;

/// Decode an 8-bit RGB(A)/grey PNG into (width, height, RGB bytes).
fn decode_png(file: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<[u8; 3]>)> {
    let mut dec = png::Decoder::new(bytes);
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = dec.read_info().map_err(|e| Error::input(file, format!("not a readable PNG: {e}")))?;
    let size = reader.output_buffer_size();
    if size > MAX_PNG_DECODED_BYTES {
        let (w, h) = (reader.info().width, reader.info().height);
        return Err(Error::input(
            file,
            format!(
                "PNG of {w}x{h} pixels is too large: {size} bytes decoded; at most {} MiB allowed (e.g. 4096 x 4096 RGBA)",
                MAX_PNG_DECODED_BYTES >> 20
            ),
        ));
    }
    let mut buf = vec![0; size];
    let info = reader.next_frame(&mut buf).map_err(|e| Error::input(file, format!("not a readable PNG: {e}")))?;
    let ch = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => 3,
    };
    let (w, h) = (info.width, info.height);
    let mut px = Vec::with_capacity(w as usize * h as usize);
    for row in buf[..info.buffer_size()].chunks(info.line_size) {
        for p in row.chunks(ch).take(w as usize) {
            px.push(if ch < 3 { [p[0], p[0], p[0]] } else { [p[0], p[1], p[2]] });
        }
    }
    Ok((w, h, px))
}

/// Read a PNG pressure map: each footprint pixel is matched to the nearest colour on the colour
/// bar (RGB distance) and given that bar position's pressure, linear from `bar_min_pa` (bottom) to
/// `bar_max_pa` (top); pixels farther than `tolerance` from every bar colour are background.
/// The bar is "readable" if its box lies in the image, is at least 8 pixels tall, and its
/// row-averaged colours take at least 8 distinct values.
pub fn read_png_map(file: &Path, bytes: &[u8], lay: &ImageLayout) -> Result<PressureGrid> {
    let (w, h, px) = decode_png(file, bytes)?;
    let inside = |b: &[u32; 4]| b[0] < b[2] && b[1] < b[3] && b[2] <= w && b[3] <= h;
    let [bx0, by0, bx1, by1] = lay.colour_bar;
    if !inside(&lay.colour_bar) || by1 - by0 < 8 {
        return Err(Error::input(
            file,
            format!(
                "no readable colour bar: box {:?} must lie inside the {w}x{h} image and be at least 8 pixels tall",
                lay.colour_bar
            ),
        ));
    }
    if !inside(&lay.footprint) {
        return Err(Error::input(file, format!("footprint box {:?} must lie inside the {w}x{h} image", lay.footprint)));
    }
    if !(lay.bar_max_pa > lay.bar_min_pa && lay.bar_min_pa >= 0.0 && lay.bar_max_pa.is_finite()) {
        return Err(Error::input(file, "colour bar range: expected 0 <= bar_min_kpa < bar_max_kpa"));
    }
    // Bar colours, bottom (min) to top (max), averaged across the bar's width.
    let nbar = (by1 - by0) as usize;
    let mut bar: Vec<[f64; 3]> = Vec::with_capacity(nbar);
    for y in (by0..by1).rev() {
        let mut acc = [0.0; 3];
        for x in bx0..bx1 {
            let c = px[(y * w + x) as usize];
            for k in 0..3 {
                acc[k] += c[k] as f64;
            }
        }
        let n = (bx1 - bx0) as f64;
        bar.push([acc[0] / n, acc[1] / n, acc[2] / n]);
    }
    let mut distinct: Vec<[i64; 3]> =
        bar.iter().map(|c| [c[0].round() as i64, c[1].round() as i64, c[2].round() as i64]).collect();
    distinct.sort();
    distinct.dedup();
    if distinct.len() < 8 {
        return Err(Error::input(
            file,
            format!(
                "no readable colour bar in box {:?}: it has {} distinct colours; expected a gradient of at least 8",
                lay.colour_bar,
                distinct.len()
            ),
        ));
    }
    let [fx0, fy0, fx1, fy1] = lay.footprint;
    let (rows, cols) = ((fy1 - fy0) as usize, (fx1 - fx0) as usize);
    let tol2 = lay.tolerance * lay.tolerance;
    let mut p = Vec::with_capacity(rows * cols);
    for y in fy0..fy1 {
        for x in fx0..fx1 {
            let c = px[(y * w + x) as usize];
            let (mut best, mut bi) = (f64::INFINITY, 0usize);
            for (i, b) in bar.iter().enumerate() {
                let d = (c[0] as f64 - b[0]).powi(2) + (c[1] as f64 - b[1]).powi(2) + (c[2] as f64 - b[2]).powi(2);
                if d < best {
                    best = d;
                    bi = i;
                }
            }
            p.push(if best <= tol2 {
                lay.bar_min_pa + (lay.bar_max_pa - lay.bar_min_pa) * bi as f64 / (nbar - 1) as f64
            } else {
                0.0
            });
        }
    }
    let g = PressureGrid { rows, cols, dx_m: lay.dx_m, dy_m: lay.dy_m, p_pa: p };
    g.validate(file)?;
    Ok(g)
}
