//! Numbers for people: a fixed number of significant digits, so messages and tables read
//! `4.52 s` and `1.20 m`, not `4.5200000000000005 s` or `1.2022e0 m`. Plain decimals from 1e-3
//! up to 1e6, scientific notation (`1.20e-4`) outside; zero (either sign) is `0`.

use std::fmt;

/// `x` with `digits` significant digits (at least 1).
pub fn sig(x: f64, digits: usize) -> String {
    let digits = digits.max(1);
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let exponent = |v: f64| v.abs().log10().floor() as i32;
    let e = exponent(x);
    if !(-3..6).contains(&e) {
        let s = format!("{:.*e}", digits - 1, x);
        // Rounding can carry into the next decade (9.996e-5 -> 1.00e-4); Rust prints that right.
        return s;
    }
    let decimals = |e: i32| (digits as i32 - 1 - e).max(0) as usize;
    let s = format!("{:.*}", decimals(e), x);
    // Rounding carried into the next decade (9.996 -> 10.00): one decimal fewer.
    match s.parse::<f64>() {
        Ok(r) if r != 0.0 && exponent(r) > e => format!("{:.*}", decimals(e + 1), x),
        _ => s,
    }
}

/// Display wrapper: `Sig(x)` prints `x` with three significant digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sig(pub f64);

impl fmt::Display for Sig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&sig(self.0, 3))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_significant_digits() {
        assert_eq!(sig(4.5200000000000005, 3), "4.52");
        assert_eq!(sig(1.2022, 3), "1.20");
        assert_eq!(sig(0.9602, 4), "0.9602");
        assert_eq!(sig(-0.0, 3), "0");
        assert_eq!(sig(0.0, 3), "0");
        assert_eq!(sig(9.996, 3), "10.0");
        assert_eq!(sig(999.6, 3), "1000");
        assert_eq!(sig(4000.0, 3), "4000");
        assert_eq!(sig(-12.345, 2), "-12");
        assert_eq!(sig(0.001234, 3), "0.00123");
        assert_eq!(sig(1.234e-4, 3), "1.23e-4");
        assert_eq!(sig(-2.5e7, 2), "-2.5e7");
        assert_eq!(sig(f64::NAN, 3), "NaN");
        assert_eq!(Sig(0.15).to_string(), "0.150");
    }
}
