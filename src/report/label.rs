//! Numbers written as short labels for axes and colour bars.

/// An axis range end: multiples of π (like -π, π, 2π) by name, other values as [`compact`].
pub fn axis_text(v: f64) -> String {
    let k = v / std::f64::consts::PI;
    let kr = k.round();
    if v != 0.0 && kr != 0.0 && (k - kr).abs() < 1e-9 && kr.abs() <= 9.0 {
        match kr as i64 {
            1 => "π".into(),
            -1 => "-π".into(),
            n => format!("{n}π"),
        }
    } else {
        compact(v)
    }
}

/// A compact number: up to 3 significant digits in plain notation for 0.01 ≤ |v| < 10⁴,
/// otherwise a 2-digit mantissa with an exponent (`1.2e4`, `-3.5e-5`).
pub fn compact(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}").to_lowercase();
    }
    let a = v.abs();
    if (1e-2..1e4).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        return trim_zeros(&format!("{v:.decimals$}")).to_string();
    }
    let s = format!("{v:.1e}");
    match s.split_once('e') {
        Some((mant, exp)) => format!("{}e{exp}", trim_zeros(mant)),
        None => s,
    }
}

/// Drops trailing zeros after a decimal point, and the point itself if left bare.
fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn numbers_are_compact() {
        let cases = [
            (0.0, "0"),
            (12000.0, "1.2e4"),
            (-3.5, "-3.5"),
            (1.0, "1"),
            (0.05, "0.05"),
            (7.777, "7.78"),
            (123.4, "123"),
            (1e-5, "1e-5"),
            (-2.5e-7, "-2.5e-7"),
            (1e5, "1e5"),
            (f64::NAN, "nan"),
        ];
        for (v, s) in cases {
            assert_eq!(compact(v), s, "{v}");
        }
        assert_eq!(axis_text(-PI), "-π");
        assert_eq!(axis_text(2.0 * PI), "2π");
        assert_eq!(axis_text(-1.0), "-1");
    }
}
