//! Numbers as bench-sph writes them for a reader (REPORT.md, merge's messages): never more
//! than three significant digits, since a mean of a few noisy runs does not know its fourth.

/// `v` to three significant digits, without exponent: `0.412`, `2.20`, `39.7`, `1230`.
pub fn sig(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".to_owned();
    }
    let magnitude = v.abs().log10().floor() as i32;
    if magnitude >= 2 {
        // Whole numbers: round away the digits beyond the third.
        let unit = 10f64.powi(magnitude - 2);
        return format!("{:.0}", (v / unit).round() * unit);
    }
    let places = (2 - magnitude) as usize;
    let text = format!("{v:.places$}");
    // Rounding can add a digit (9.996 → "10.00"): write it again at the new magnitude.
    let rounded: f64 = text.parse().unwrap_or(v);
    if rounded.abs().log10().floor() as i32 > magnitude {
        return sig(rounded);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::sig;

    #[test]
    fn numbers_have_at_most_three_significant_digits() {
        assert_eq!(sig(39.74), "39.7");
        assert_eq!(sig(0.54433), "0.544");
        assert_eq!(sig(2.0), "2.00");
        assert_eq!(sig(1234.5), "1230");
        assert_eq!(sig(9.996), "10.0");
        assert_eq!(sig(0.0), "0");
        assert_eq!(sig(-0.0123456), "-0.0123");
    }
}
