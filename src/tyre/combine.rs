//! Shared pieces of the providers: the Magic Formula sine curve and its slope, and the
//! normalised-slip friction-ellipse combination of two pure-slip curves.
//!
//! Normalised-slip combination (the "similarity" idea of Pacejka, Tyre and Vehicle Dynamics,
//! section 4.3): with reference slips kappa_r and alpha_r, define s_x = kappa / kappa_r,
//! s_y = alpha / alpha_r and s = sqrt(s_x^2 + s_y^2). The combined forces are
//!
//! ```text
//! Fx = (|s_x| / s) * Fx0(sign(kappa) * s * kappa_r)
//! Fy = (|s_y| / s) * Fy0(sign(alpha) * s * alpha_r)
//! ```
//!
//! so pure slip is reproduced exactly (s_y = 0 gives Fx = Fx0(kappa)), and because
//! (|s_x|/s)^2 + (|s_y|/s)^2 = 1 the pair satisfies (Fx/Dx)^2 + (Fy/Dy)^2 <= 1 whenever
//! |Fx0| <= Dx and |Fy0| <= Dy: a friction ellipse, never a friction square. Both weights stay
//! bounded as s -> 0 and the pure curves vanish at zero slip, so the result is continuous there.

/// Magic Formula sine curve y = D sin(C atan(B x - E (B x - atan(B x)))).
#[inline]
pub fn mf_sin(b: f64, c: f64, d: f64, e: f64, x: f64) -> f64 {
    let bx = b * x;
    // E = 0 is common; skipping the inner atan then is exact.
    let phi = if e == 0.0 { bx } else { bx - e * (bx - bx.atan()) };
    d * (c * phi.atan()).sin()
}

/// cos(C atan(B x - E (B x - atan(B x)))), the Magic Formula weighting shape. With C = 1 it is
/// evaluated exactly as 1 / sqrt(1 + phi^2).
#[inline]
pub fn mf_cos(b: f64, c: f64, e: f64, x: f64) -> f64 {
    let bx = b * x;
    let phi = if e == 0.0 { bx } else { bx - e * (bx - bx.atan()) };
    if c == 1.0 {
        1.0 / (1.0 + phi * phi).sqrt()
    } else {
        (c * phi.atan()).cos()
    }
}

/// dy/dx of [`mf_sin`] at `x` (E held fixed).
pub fn mf_sin_slope(b: f64, c: f64, d: f64, e: f64, x: f64) -> f64 {
    let bx = b * x;
    let phi = bx - e * (bx - bx.atan());
    let dphi = b - e * (b - b / (1.0 + bx * bx));
    d * (c * phi.atan()).cos() * c / (1.0 + phi * phi) * dphi
}

/// Weights and equivalent slip magnitude of the normalised-slip combination:
/// returns (s, |s_x|/s, |s_y|/s), and (0, 0, 0) at zero slip.
#[inline]
pub fn normalised(sx: f64, sy: f64) -> (f64, f64, f64) {
    // sqrt of the sum of squares rather than hypot (several times faster); the slips here are at
    // most ~1e17 in magnitude, far from overflow, and an overflow is handled below.
    let s = (sx * sx + sy * sy).sqrt();
    if s > 0.0 && s.is_finite() {
        (s, sx.abs() / s, sy.abs() / s)
    } else if s.is_infinite() {
        // One component overflowed: the direction is that component's.
        let wx = if sx.is_infinite() { 1.0 } else { 0.0 };
        (s, wx, 1.0 - wx)
    } else {
        (0.0, 0.0, 0.0)
    }
}

/// +1 for x >= 0, -1 otherwise (a sign that is never 0, used to carry the slip direction).
#[inline]
pub fn sgn(x: f64) -> f64 {
    if x < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Equivalent slip `sign * s * reference`, with an infinite s kept finite (clamped to 1e12 times
/// the reference: every saturating curve is flat there).
#[inline]
pub fn equivalent(sign: f64, s: f64, reference: f64) -> f64 {
    sign * s.min(1e12) * reference
}

/// `x > 0` (false for NaN): the guard of every provider against zero or invalid load and friction.
#[inline]
pub fn positive(x: f64) -> bool {
    x > 0.0
}
