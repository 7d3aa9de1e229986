//! Confidence intervals of a proportion.
//!
//! Wilson's score interval rather than the textbook p ± z·√(p(1−p)/n): the
//! settled fraction of a good design is 1 or nearly, where the textbook
//! interval collapses to a point and Wilson's still says how sure 20 runs can be.

/// Normal quantile for 95 % two-sided intervals.
const Z95: f64 = 1.959_963_984_540_054;

/// Wilson score interval (95 %) of a proportion `successes / trials`.
pub fn wilson_interval(successes: u64, trials: u64) -> (f64, f64) {
    wilson_with_z(successes, trials, Z95)
}

/// Wilson score interval of `successes / trials` at two-sided `level`.
pub fn wilson_interval_at(successes: u64, trials: u64, level: f64) -> (f64, f64) {
    use statrs::distribution::{ContinuousCDF, Normal};
    let z = Normal::standard().inverse_cdf(0.5 + level / 2.0);
    wilson_with_z(successes, trials, z)
}

/// The one Wilson formula, for the normal quantile `z`; (0, 1) without trials.
fn wilson_with_z(successes: u64, trials: u64, z: f64) -> (f64, f64) {
    if trials == 0 {
        return (0.0, 1.0);
    }
    let n = trials as f64;
    let p = successes as f64 / n;
    let z2 = z * z;
    let centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
    let half = z * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / (1.0 + z2 / n);
    ((centre - half).max(0.0), (centre + half).min(1.0))
}
