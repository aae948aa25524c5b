//! Pressure-grid files: a CSV grid in kPa, or a PNG pressure map read through its colour bar
//! (dissertation Appendix C.2). Both give the [`PressureGrid`] of the contact-patch model; the
//! grid's layout and units are those of [`vehsim_core::contact::patch`].

use std::path::Path;

use vehsim_core::contact::patch::PressureGrid;
use vehsim_core::error::{Error, Result};

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
                        vehsim_core::error::shown(f)
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
    /// Pressure at the top of the bar, Pa.
    pub bar_max_pa: f64,
    /// Largest RGB distance (Euclidean, 0–441) at which a footprint pixel still matches the bar;
    /// farther pixels are background (no contact). Typical 40–80.
    pub tolerance: f64,
    /// Physical pixel size along travel and across, m.
    pub dx_m: f64,
    /// Physical pixel width across the tread, m.
    pub dy_m: f64,
}

/// Largest decoded PNG pressure map, bytes (64 MiB: 4096 x 4096 RGBA). Scanned maps are a few
/// hundred pixels a side; the header's size is checked before the frame buffer is allocated, so
/// a short file claiming a huge image is an input error instead of an allocation failure.
pub(crate) const MAX_PNG_DECODED_BYTES: usize = 64 << 20;

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
