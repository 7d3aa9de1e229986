//! Numbers as a person reads them: a design's drag chosen by the optimiser
//! is 0.05000000000000001 in binary, and printing that digit for digit
//! reads as noise, so parameters are shown to a few significant digits.

/// `v` to `digits` significant digits, trailing zeros dropped
/// (0.05000000000000001 → "0.05", 1.071951795991578 → "1.072" at 4);
/// scientific notation below 10⁻⁴ and from 10⁶ up.
pub fn significant(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    let digits = digits.max(1);
    if !(1e-4..1e6).contains(&v.abs()) {
        return format!("{:.*e}", digits - 1, v)
            .replace(".0e", "e")
            .replace("00e", "e");
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::significant;

    #[test]
    fn parameters_read_as_a_person_writes_them() {
        assert_eq!(significant(0.050_000_000_000_000_01, 4), "0.05");
        assert_eq!(significant(1.071_951_795_991_578, 4), "1.072");
        assert_eq!(significant(7.7e-3, 4), "0.0077");
        assert_eq!(significant(250.0, 4), "250");
        assert_eq!(significant(12345.6, 4), "12346");
        assert_eq!(significant(-0.3333333, 3), "-0.333");
        assert_eq!(significant(0.0, 4), "0");
    }
}
