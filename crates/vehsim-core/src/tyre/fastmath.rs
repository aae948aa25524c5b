//! Arctangent, sine, cosine, tangent and exponential for the simulation's hot path: polynomial
//! kernels accurate to about one unit in the last place over the ranges the tyre, wheel and
//! contact formulas use, at a fraction of the instructions of the C library's correctly rounded
//! versions (which handle every argument and rounding mode; these need only be smooth and accurate
//! on a bounded range, and fall back to the library outside it).
//!
//! - [`atan`]: every argument, with one division at most. |x| = a is moved to |u| <= tan(pi/12)
//!   by atan(a) = pi/6 + atan((sqrt(3) a - 1) / (a + sqrt(3))) for a in (tan(pi/12), 1],
//!   pi/3 + atan((a - sqrt(3)) / (1 + sqrt(3) a)) for a in (1, cot(pi/12)] and
//!   pi/2 - atan(1/a) beyond; then atan(u) = u + u s Q(s), s = u^2, Q of degree 8.
//! - [`sin`]: |x| <= pi (the Magic Formula's C atan(.) with C <= 2); |x| > pi/2 is folded by
//!   sin(x) = sin(pi - x); then sin(x) = x + x s R(s), R of degree 7. Beyond pi, NaN or infinite:
//!   the library's `sin`.
//! - [`sin_cos`]: |x| <= pi/2 as (sin(x), sin(pi/2 - |x|)) (steer and yaw angles); beyond, the
//!   library's `sin_cos`.
//! - [`tan`]: |x| <= 1 as sin(x) / sin(pi/2 - |x|) (signed); beyond, the library's `tan`.
//! - [`exp`]: |x| <= 700 as 2^k e^r, k the nearest integer to x / ln 2, r = x - k ln 2 (ln 2 in
//!   two parts, the first exact in k ln 2), e^r = 1 + r + r^2 G(r), G of degree 9; beyond, NaN or
//!   infinite: the library's `exp`.
//!
//! The kernels Q, R and G are Chebyshev interpolants of (atan(sqrt s)/sqrt s - 1)/s on
//! [0, tan^2(pi/12)], (sin(sqrt s)/sqrt s - 1)/s on [0, pi^2/4] and (e^r - 1 - r)/r^2 on
//! [-ln2/2, ln2/2], computed in 60-digit decimal arithmetic and written in monomial form
//! (`scripts/fastmath_kernels.py` prints them with their interpolation error), evaluated by
//! Estrin's scheme (a short dependency chain). Their own error is
//! below 2e-17 relative to the result; what remains is the rounding of the reduction and of
//! its evaluation, checked against the library functions in the tests below (a few 1e-16,
//! relative to |result| for atan, tan and exp and absolute for sin and cos). Each function is
//! smooth on every piece and continuous across the pieces to that rounding, so the integrators
//! keep their order (tests/convergence.rs). Unlike the library's, `sin`, `sin_cos` and `tan` give
//! +0, not -0, at x = -0 (the sign of a zero carries nothing here; `atan` keeps it).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, FRAC_PI_6, PI};

/// sqrt(3).
const SQRT_3: f64 = 1.732_050_807_568_877_2;
/// tan(pi/12) = 2 - sqrt(3).
const TAN_PI_12: f64 = 0.267_949_192_431_122_7;
/// cot(pi/12) = 2 + sqrt(3).
const COT_PI_12: f64 = 3.732_050_807_568_877;

/// Q(s), atan(u) = u + u s Q(s), s = u^2 <= tan^2(pi/12), lowest degree first.
const ATAN_Q: [f64; 9] = [
    -0.3333333333333333,
    0.19999999999996879,
    -0.14285714284553033,
    0.11111110944421528,
    -0.09090897075908187,
    0.07691819455539145,
    -0.06654941820381093,
    0.057163002389839374,
    -0.03957783567228748,
];

/// R(s), sin(x) = x + x s R(s), s = x^2 <= pi^2/4, lowest degree first.
const SIN_R: [f64; 8] = [
    -0.16666666666666666,
    0.008333333333333316,
    -0.00019841269841254966,
    2.7557319219160833e-06,
    -2.505210761669045e-08,
    1.6058977292642743e-10,
    -7.643969663988074e-13,
    2.7314368769379893e-15,
];

/// G(r), e^r = 1 + r + r^2 G(r), |r| <= ln2/2, lowest degree first.
const EXP_G: [f64; 10] = [
    0.5000000000000001,
    0.16666666666666669,
    0.04166666666662413,
    0.008333333333330062,
    0.0013888888917213717,
    0.00019841269863053618,
    2.4801521295954376e-05,
    2.7557268459997064e-06,
    2.7620088445409746e-07,
    2.510038549551032e-08,
];

/// ln 2 in two parts: the first with its low 20 bits of mantissa zero (k LN2_HI is exact for
/// |k| < 2^20), the second the rest.
const LN2_HI: f64 = 0.693_147_180_485_539_1;
const LN2_LO: f64 = 7.440617110012397e-11;
/// 1.5 2^52: adding and subtracting it rounds a double of magnitude below 2^51 to an integer
/// (to nearest, ties to even) without a library call.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

// The kernels' polynomials by Estrin's scheme, written out: pairs c[2i] + c[2i+1] x, then pairs
// of those with x^2, x^4, x^8 (three more multiplications than Horner's scheme, but a dependency
// chain of four levels instead of nine: the kernels sit on the critical path of the tyre
// formulas, where latency sets the wall time).

/// Q(s) of [`ATAN_Q`] (degree 8).
#[inline(always)]
fn atan_q(s: f64) -> f64 {
    let c = &ATAN_Q;
    let (s2, s4) = (s * s, (s * s) * (s * s));
    let p03 = (c[0] + c[1] * s) + (c[2] + c[3] * s) * s2;
    let p47 = (c[4] + c[5] * s) + (c[6] + c[7] * s) * s2;
    (p03 + p47 * s4) + c[8] * (s4 * s4)
}

/// R(s) of [`SIN_R`] (degree 7).
#[inline(always)]
fn sin_r(s: f64) -> f64 {
    let c = &SIN_R;
    let s2 = s * s;
    let p03 = (c[0] + c[1] * s) + (c[2] + c[3] * s) * s2;
    let p47 = (c[4] + c[5] * s) + (c[6] + c[7] * s) * s2;
    p03 + p47 * (s2 * s2)
}

/// G(r) of [`EXP_G`] (degree 9).
#[inline(always)]
fn exp_g(r: f64) -> f64 {
    let c = &EXP_G;
    let (r2, r4) = (r * r, (r * r) * (r * r));
    let p03 = (c[0] + c[1] * r) + (c[2] + c[3] * r) * r2;
    let p47 = (c[4] + c[5] * r) + (c[6] + c[7] * r) * r2;
    (p03 + p47 * r4) + (c[8] + c[9] * r) * (r4 * r4)
}

/// atan(u) for |u| <= tan(pi/12).
#[inline(always)]
fn atan_kernel(u: f64) -> f64 {
    let s = u * u;
    u + u * s * atan_q(s)
}

/// sin(x) for |x| <= pi/2.
#[inline(always)]
fn sin_kernel(x: f64) -> f64 {
    let s = x * x;
    x + x * s * sin_r(s)
}

/// Arctangent, radians in [-pi/2, pi/2]; NaN gives NaN, +-inf gives +-pi/2, the sign of 0 kept.
/// (Inlined at every use: `#[inline]` left it outlined, a call per arctangent, four per Magic
/// Formula evaluation.)
#[inline(always)]
pub fn atan(x: f64) -> f64 {
    let a = x.abs();
    // one division at most: a in (tan(pi/12), 1] about pi/6, (1, cot(pi/12)] about pi/3, beyond
    // by pi/2 - atan(1/a) (infinite a gives 1/a = 0; NaN falls through to NaN)
    let r = if a <= TAN_PI_12 {
        atan_kernel(a)
    } else if a <= 1.0 {
        FRAC_PI_6 + atan_kernel((SQRT_3 * a - 1.0) / (a + SQRT_3))
    } else if a <= COT_PI_12 {
        FRAC_PI_3 + atan_kernel((a - SQRT_3) / (1.0 + SQRT_3 * a))
    } else {
        FRAC_PI_2 - atan_kernel(1.0 / a)
    };
    r.copysign(x)
}

/// Sine of `x`, radians (see the module docs for the range of the polynomial).
#[inline]
pub fn sin(x: f64) -> f64 {
    let a = x.abs();
    if a <= FRAC_PI_2 {
        sin_kernel(x)
    } else if a <= PI {
        sin_kernel(PI - a).copysign(x)
    } else {
        x.sin()
    }
}

/// (sin x, cos x) of `x`, radians (see the module docs for the range of the polynomial).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let a = x.abs();
    if a <= FRAC_PI_2 {
        (sin_kernel(x), sin_kernel(FRAC_PI_2 - a))
    } else {
        x.sin_cos()
    }
}

/// Tangent of `x`, radians (see the module docs for the range of the polynomial).
#[inline]
pub fn tan(x: f64) -> f64 {
    let a = x.abs();
    if a <= 1.0 {
        sin_kernel(x) / sin_kernel(FRAC_PI_2 - a)
    } else {
        x.tan()
    }
}

/// tan(x)^2, radians: |x| <= 1 as s^2 / (1 - s^2) with s = sin(x) (one kernel where [`tan`]
/// takes two and a division of its own; 1 - s^2 >= cos(1)^2 = 0.29 there, so it loses nothing to
/// cancellation); beyond, the library's `tan` squared.
#[inline]
pub(crate) fn tan_sq(x: f64) -> f64 {
    if x.abs() <= 1.0 {
        let s = sin_kernel(x);
        let s2 = s * s;
        s2 / (1.0 - s2)
    } else {
        let t = x.tan();
        t * t
    }
}

/// e^x (see the module docs for the range of the polynomial).
#[inline]
pub fn exp(x: f64) -> f64 {
    if x.abs() > 700.0 || x.is_nan() {
        return x.exp();
    }
    let k = (x * std::f64::consts::LOG2_E + ROUND_MAGIC) - ROUND_MAGIC;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let er = 1.0 + (r + r * r * exp_g(r));
    // 2^k as a double: |k| <= 1010, so k + 1023 is a normal exponent
    er * f64::from_bits(((k as i64 + 1023) as u64) << 52)
}

/// Cells of [`fast_ln`]'s table over the mantissa [1, 2) (a power of two).
const LN_CELLS: usize = 256;

/// ln of x in [0.5, 1] by the series 2 atanh((x - 1) / (x + 1)) to round-off (|s| <= 1/3, 40
/// terms), for the compile-time table of [`fast_ln`].
const fn ln_series(x: f64) -> f64 {
    let s = (x - 1.0) / (x + 1.0);
    let s2 = s * s;
    let (mut term, mut sum, mut n) = (s, 0.0, 0);
    while n < 40 {
        sum += term / (2 * n + 1) as f64;
        term *= s2;
        n += 1;
    }
    2.0 * sum
}

/// Per cell k of the mantissa, the reciprocal 1 / c of its start c = 1 + k / 256 (as rounded to
/// f64) and -ln of that stored reciprocal, computed at compile time (cell 0: exactly 1 and 0).
const LN_TABLE: [(f64, f64); LN_CELLS] = {
    let mut t = [(0.0, 0.0); LN_CELLS];
    let mut k = 0;
    while k < LN_CELLS {
        let inv = 1.0 / (1.0 + k as f64 / LN_CELLS as f64);
        t[k] = (inv, -ln_series(inv));
        k += 1;
    }
    t
};

/// Natural logarithm for table coordinates, absolute error < 1e-14 for finite x > 0 and exactly
/// 0 at 1, with no division (the flash lookup's chain is latency-bound): x = m 2^e, m in [1, 2);
/// the table gives 1 / c for the start c of m's 1/256 cell and ln c, and ln m = ln c +
/// ln(1 + r) with r = m / c - 1 in [0, 2^-8), by its series to r^5 (truncation below 2^-48 / 6).
/// Non-positive, subnormal or non-finite x fall back to `f64::ln`.
#[inline]
pub(crate) fn fast_ln(x: f64) -> f64 {
    if !(x.is_normal() && x > 0.0) {
        return x.ln();
    }
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let (inv, ln_c) = LN_TABLE[((bits >> 44) & (LN_CELLS as u64 - 1)) as usize];
    let r = m * inv - 1.0;
    let r2 = r * r;
    let p = (r + r2 * (r * (1.0 / 3.0) - 0.5)) + (r2 * r2) * (r * 0.2 - 0.25);
    (e as f64 * std::f64::consts::LN_2 + ln_c) + p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Arguments spread over [lo, hi], both ends and the pieces' joins included.
    fn grid(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
        (0..=n).map(move |k| lo + (hi - lo) * k as f64 / n as f64)
    }

    #[test]
    fn atan_matches_the_library_to_a_few_ulp() {
        let mut worst = 0.0_f64;
        let mut check = |x: f64| {
            let (got, want) = (atan(x), x.atan());
            let rel = ((got - want) / want).abs();
            worst = worst.max(if want == 0.0 { got.abs() } else { rel });
        };
        grid(-1.2, 1.2, 240_001).for_each(&mut check);
        grid(-60.0, 60.0, 120_001).for_each(&mut check);
        for x in [TAN_PI_12, -TAN_PI_12, 1.0, -1.0, COT_PI_12, -COT_PI_12, 1e-300, 1e300, 5e-324, 1e8] {
            check(x);
            check(x.next_up());
            check(x.next_down());
        }
        assert!(worst < 4.5e-16, "largest relative error {worst:.2e}");
        assert_eq!(atan(f64::INFINITY), FRAC_PI_2);
        assert_eq!(atan(f64::NEG_INFINITY), -FRAC_PI_2);
        assert!(atan(f64::NAN).is_nan());
        assert!(atan(-0.0).is_sign_negative() && atan(0.0) == 0.0);
    }

    #[test]
    fn sin_matches_the_library_to_a_few_ulp() {
        let mut worst = 0.0_f64;
        for x in grid(-PI, PI, 400_001).chain([FRAC_PI_2, FRAC_PI_2.next_up(), PI, -PI, 1e-300]) {
            worst = worst.max((sin(x) - x.sin()).abs());
        }
        assert!(worst < 4.5e-16, "largest absolute error {worst:.2e}");
        // beyond pi and non-finite: the library's
        assert_eq!(sin(10.0), 10.0f64.sin());
        assert!(sin(f64::NAN).is_nan() && sin(f64::INFINITY).is_nan());
        assert_eq!(sin(-0.0), 0.0);
    }

    #[test]
    fn sin_cos_matches_the_library_to_a_few_ulp() {
        let mut worst = 0.0_f64;
        for x in grid(-FRAC_PI_2, FRAC_PI_2, 400_001).chain([1e-300, -0.0]) {
            let ((s, c), (ws, wc)) = (sin_cos(x), x.sin_cos());
            worst = worst.max((s - ws).abs()).max((c - wc).abs());
        }
        assert!(worst < 4.5e-16, "largest absolute error {worst:.2e}");
        assert_eq!(sin_cos(2.0), 2.0f64.sin_cos());
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::NAN).1.is_nan());
    }

    #[test]
    fn tan_matches_the_library_to_a_few_ulp() {
        let mut worst = 0.0_f64;
        for x in grid(-1.0, 1.0, 200_001).chain([1e-300, -1e-12]) {
            let want = x.tan();
            worst = worst.max(if want == 0.0 { tan(x).abs() } else { ((tan(x) - want) / want).abs() });
        }
        assert!(worst < 6e-16, "largest relative error {worst:.2e}");
        assert_eq!(tan(1.3), 1.3f64.tan());
        // the sign of a zero result is not kept (x + x s R(s) at x = -0 is +0)
        assert_eq!(tan(-0.0), 0.0);
        assert_eq!(sin_cos(-0.0).0, 0.0);
        assert!(tan(f64::NAN).is_nan());
    }

    #[test]
    fn exp_matches_the_library_to_a_few_ulp() {
        let mut worst = 0.0_f64;
        for x in grid(-40.0, 40.0, 400_001).chain(grid(-700.0, 700.0, 14_001)).chain([0.0, -0.0, 1e-300, 0.5 * LN2_HI])
        {
            let (got, want) = (exp(x), x.exp());
            worst = worst.max(((got - want) / want).abs());
        }
        assert!(worst < 4.5e-16, "largest relative error {worst:.2e}");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(800.0), f64::INFINITY);
        assert_eq!(exp(-800.0), 0.0);
        assert_eq!(exp(-710.0), (-710.0f64).exp());
        assert!(exp(f64::NAN).is_nan());
    }

    #[test]
    fn odd_and_monotone_where_it_matters() {
        let mut last = -FRAC_PI_2;
        for x in grid(-30.0, 30.0, 600_001) {
            assert_eq!(atan(-x), -atan(x));
            let y = atan(x);
            assert!(y >= last, "atan not monotone at {x}");
            last = y;
        }
        for x in grid(0.0, PI, 10_001) {
            assert_eq!(sin(-x), -sin(x));
        }
    }

    /// tan_sq against the library's tangent squared: within 2e-15 relative over |x| <= 1 and
    /// beyond it (where it is the library's), and exactly 0 at 0.
    #[test]
    fn tan_sq_matches_tan_squared() {
        let mut worst = 0.0_f64;
        let mut x = -1.6_f64;
        while x <= 1.6 {
            let want = x.tan() * x.tan();
            if want > 0.0 {
                worst = worst.max((tan_sq(x) / want - 1.0).abs());
            }
            x += 1e-4;
        }
        assert!(worst <= 2e-15, "largest relative difference {worst:e}");
        assert_eq!(tan_sq(0.0), 0.0);
        assert!(tan_sq(f64::NAN).is_nan());
    }
}
