//! Shared pieces of the providers: the Magic Formula sine curve and its slope, the
//! normalised-slip friction-ellipse combination of two pure-slip curves, and the memoised load
//! factor power `powf_memo`.
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

use super::fastmath;

/// `x.powf(p)`, bit for bit, remembering the last four distinct (x, p) pairs of the calling thread.
///
/// The providers' load factors (Fz / Fz_nominal)^p cost a libm `pow` (about 120 instructions) per
/// evaluation, but a vehicle model with static loads (the bicycle) asks for the same two loads
/// again and again: a hit costs a handful of compares instead. The memo stores `powf`'s own result,
/// so the value returned is exactly `x.powf(p)` whether it hits or not (keys compare bit patterns;
/// the initial entries hold the true value 1^1 = 1). Per thread, so batch workers share nothing.
#[inline]
pub(crate) fn powf_memo(x: f64, p: f64) -> f64 {
    use std::cell::Cell;
    const ONE: u64 = 0x3ff0_0000_0000_0000; // 1.0f64.to_bits()
    thread_local! {
        static MEMO: [Cell<(u64, u64, f64)>; 4] = const { [const { Cell::new((ONE, ONE, 1.0)) }; 4] };
        static NEXT: Cell<usize> = const { Cell::new(0) };
    }
    let key = (x.to_bits(), p.to_bits());
    MEMO.with(|m| {
        for e in m {
            let (kx, kp, v) = e.get();
            if (kx, kp) == key {
                return v;
            }
        }
        let v = x.powf(p);
        NEXT.with(|n| {
            let k = n.get();
            m[k & 3].set((key.0, key.1, v));
            n.set(k.wrapping_add(1));
        });
        v
    })
}

/// Magic Formula sine curve y = D sin(C atan(B x - E (B x - atan(B x)))) (the arctangents and
/// the sine by [`fastmath`], a polynomial kernel within an ulp or two of the library's).
#[inline(always)]
pub(crate) fn mf_sin(b: f64, c: f64, d: f64, e: f64, x: f64) -> f64 {
    let bx = b * x;
    // E = 0 is common; skipping the inner atan then is exact.
    let phi = if e == 0.0 { bx } else { bx - e * (bx - fastmath::atan(bx)) };
    if c == 1.5 && phi.abs() <= 1e150 {
        return d * sin_three_halves_atan(phi);
    }
    d * fastmath::sin(c * fastmath::atan(phi))
}

/// sin(1.5 atan(phi)) by square roots (C = 1.5 is a common longitudinal shape factor): with
/// theta = atan(phi) and r = sqrt(1 + phi^2), cos(theta) = 1 / r, sin(theta) = phi / r, and the
/// half angle (|theta / 2| < pi / 4) has cos = sqrt((r + 1) / (2 r)) and
/// sin = phi / sqrt(2 r (r + 1)) (1 - 1 / r written as phi^2 / (r (r + 1)), without the
/// cancellation at small phi), so
/// sin(theta + theta / 2) = phi (r + 2) / (r sqrt(2 r (r + 1))).
/// Smooth and odd in phi, 1.5 phi at small phi, 1 / sqrt(2) as phi -> infinity; within a few
/// 1e-16 of the arctangent-and-sine form (test below). |phi| <= 1e150 (phi^2 finite).
#[inline]
pub(crate) fn sin_three_halves_atan(phi: f64) -> f64 {
    let r = (1.0 + phi * phi).sqrt();
    phi * (r + 2.0) / (r * (2.0 * r * (r + 1.0)).sqrt())
}

/// cos(C atan(B x - E (B x - atan(B x)))), the Magic Formula weighting shape. With C = 1 it is
/// evaluated exactly as 1 / sqrt(1 + phi^2).
#[inline]
pub(crate) fn mf_cos(b: f64, c: f64, e: f64, x: f64) -> f64 {
    let bx = b * x;
    let phi = if e == 0.0 { bx } else { bx - e * (bx - fastmath::atan(bx)) };
    if c == 1.0 {
        1.0 / (1.0 + phi * phi).sqrt()
    } else {
        (c * fastmath::atan(phi)).cos()
    }
}

/// dy/dx of [`mf_sin`] at `x` (E held fixed).
pub(crate) fn mf_sin_slope(b: f64, c: f64, d: f64, e: f64, x: f64) -> f64 {
    let bx = b * x;
    let phi = bx - e * (bx - fastmath::atan(bx));
    let dphi = b - e * (b - b / (1.0 + bx * bx));
    d * (c * fastmath::atan(phi)).cos() * c / (1.0 + phi * phi) * dphi
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
pub(crate) fn sgn(x: f64) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The C = 1.5 closed form against the arctangent and sine of the library, over 60 decades
    /// of phi of both signs: within 6e-16 absolute (the curve is at most 1 in magnitude; measured 4.4e-16).
    #[test]
    fn three_halves_closed_form_matches_atan_and_sin() {
        let mut worst = 0.0_f64;
        let mut phi = 1e-30_f64;
        while phi < 1e30 {
            for p in [phi, -phi] {
                let want = (1.5 * p.atan()).sin();
                worst = worst.max((sin_three_halves_atan(p) - want).abs());
            }
            phi *= 1.0137;
        }
        assert!(worst <= 6e-16, "largest difference {worst:e}");
        assert_eq!(sin_three_halves_atan(0.0), 0.0);
        assert!((sin_three_halves_atan(1e150) - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-16);
        // mf_sin takes it for C = 1.5 and the general form otherwise, the same curve
        for x in [-3.0_f64, -0.2, 0.0, 0.01, 0.07, 0.4, 2.0, 40.0] {
            let a = mf_sin(9.0, 1.5, 600.0, 0.5, x);
            let bx: f64 = 9.0 * x;
            let b = 600.0 * (1.5 * (bx - 0.5 * (bx - bx.atan())).atan()).sin();
            assert!((a - b).abs() <= 1e-12, "{x}: {a} {b}");
        }
    }

    /// The memo returns `powf`'s result bit for bit: on hits, on misses, after evictions, for
    /// special values, and for keys that differ only in the exponent.
    #[test]
    fn powf_memo_is_powf() {
        let xs = [0.5, 1.0, 1.3, 0.5, 1.3, 0.0, -0.0, -2.0, f64::INFINITY, f64::NAN, 1e-300, 2.7, 0.9, 1.1, 0.5];
        for round in 0..3 {
            for (i, &x) in xs.iter().enumerate() {
                for p in [0.8, 1.0, 0.5, 0.8 + 1e-16] {
                    let (a, b) = (powf_memo(x, p), x.powf(p));
                    assert!(a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()), "{round} {i}: {x}^{p}");
                }
            }
        }
        let mut x = 0.01;
        while x < 3.0 {
            assert_eq!(powf_memo(x, 0.8).to_bits(), x.powf(0.8).to_bits());
            assert_eq!(powf_memo(x, 0.8).to_bits(), x.powf(0.8).to_bits());
            x *= 1.0001;
        }
    }
}
