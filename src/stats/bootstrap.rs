//! Bootstrap estimates: resample with replacement, recompute, look at the spread.
//!
//! The random stream is the caller's, so that each caller decides what its
//! results are reproducible by (a study seeds one stream per design).

use super::quantile::{Interpolation, quantile_sorted};
use rand::{Rng, RngExt};

/// Resamples for the confidence interval of a mean.
pub const CI_RESAMPLES: usize = 2000;

/// Resamples for a standard error, which needs fewer than an interval's tails.
pub const STD_ERROR_RESAMPLES: usize = 200;

/// Percentile bootstrap 95 % interval of the mean of `values`; `None` below two values.
pub fn mean_ci(values: &[f64], rng: &mut impl Rng) -> Option<(f64, f64)> {
    if values.len() < 2 {
        return None;
    }
    let n = values.len();
    let mut means: Vec<f64> = (0..CI_RESAMPLES)
        .map(|_| (0..n).map(|_| values[rng.random_range(0..n)]).sum::<f64>() / n as f64)
        .collect();
    means.sort_by(f64::total_cmp);
    // The 2.5 % and 97.5 % positions (49.975, 1949.025) are never a tie for rounding.
    let at = |q| quantile_sorted(&means, q, Interpolation::Nearest);
    Some((at(0.025)?, at(0.975)?))
}

/// Bootstrap standard error of `statistic` over `values`; zero below two values.
pub fn std_error(values: &[f64], statistic: impl Fn(&[f64]) -> f64, rng: &mut impl Rng) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    let n = values.len();
    let mut buf = vec![0.0; n];
    let stats: Vec<f64> = (0..STD_ERROR_RESAMPLES)
        .map(|_| {
            for b in buf.iter_mut() {
                *b = values[rng.random_range(0..n)];
            }
            statistic(&buf)
        })
        .collect();
    let mean = stats.iter().sum::<f64>() / STD_ERROR_RESAMPLES as f64;
    (stats.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (STD_ERROR_RESAMPLES - 1) as f64)
        .sqrt()
}
