//! sin and cos of the angles in the equations of motion, by the `libm`
//! crate (musl's kernels in Rust) rather than the C library.
//!
//! Why: every right-hand-side call takes the sine and cosine of each weight's
//! angle, and glibc's `sincos` was a quarter of a study's time; `libm`'s takes
//! 6.0 ns against glibc's 10.5 ns on this machine (both within 1 ulp: they
//! differ by 1 ulp on 6 % of angles). Being plain Rust it also gives the same
//! bits on every machine and C library, where glibc picks its code path by CPU.

/// (sin x, cos x).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

/// cos x.
#[inline]
pub fn cos(x: f64) -> f64 {
    libm::cos(x)
}

#[cfg(test)]
mod tests {
    #[test]
    fn agrees_with_the_standard_library_to_one_ulp() {
        let ulps = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).abs();
        for i in 0..200_001 {
            let x = -100.0 + 1e-3 * f64::from(i) + 1e-9 * f64::from(i % 7);
            let (s, c) = super::sin_cos(x);
            let (s_std, c_std) = x.sin_cos();
            assert!(ulps(s, s_std) <= 1 && ulps(c, c_std) <= 1, "x = {x}");
            assert_eq!(super::cos(x).to_bits(), c.to_bits());
        }
    }
}
