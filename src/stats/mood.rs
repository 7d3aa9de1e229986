//! Mood's median test with Fisher's exact p-value.
//!
//! A regression check asks whether the typical residual vibration moved, i.e. the
//! median, so the test is the one whose null hypothesis is exactly "equal
//! medians": count the values above the grand median in each sample and
//! compare the two proportions (a 2×2 table) with Fisher's exact test.
//! Why not Mann–Whitney: it tests P(X > Y) = ½, which a change of spread or
//! tail alone can reject, and residual vibration has a long tail from runs
//! that settle late in the hold window. Why not a bootstrap of the median
//! difference: its p-value cannot go below 1/(B + 1), too coarse once Holm
//! divides α by dozens of hypotheses, and it would add a random stream.
//! The price is power: about 2/3 of Mann–Whitney's for a normal shift.

use super::proportion::fisher_two_proportions;
use super::quantile::median;

/// Outcome of Mood's median test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MedianResult {
    /// Median of the first sample.
    pub median_a: f64,
    /// Median of the second sample.
    pub median_b: f64,
    /// Median of both samples pooled.
    pub grand_median: f64,
    /// Values above the grand median in the first and second sample.
    pub above: [u64; 2],
    /// Two-sided p-value (Fisher's exact test on the above/not-above table).
    pub p_value: f64,
}

/// Mood's median test; None when either sample is empty or holds a NaN.
pub fn mood_median_test(a: &[f64], b: &[f64]) -> Option<MedianResult> {
    if a.is_empty() || b.is_empty() || a.iter().chain(b).any(|v| v.is_nan()) {
        return None;
    }
    let pooled: Vec<f64> = a.iter().chain(b).copied().collect();
    let grand_median = median(&pooled)?;
    // Values equal to the grand median count as "not above" (scipy's ties="below").
    let above = |s: &[f64]| s.iter().filter(|&&v| v > grand_median).count() as u64;
    let (above_a, above_b) = (above(a), above(b));
    let test = fisher_two_proportions(above_a, a.len() as u64, above_b, b.len() as u64)?;
    Some(MedianResult {
        median_a: median(a)?,
        median_b: median(b)?,
        grand_median,
        above: [above_a, above_b],
        p_value: test.p_value,
    })
}
