//! Quantiles and the median of a sample: the one implementation every
//! analysis uses, so that a "median" or a "p90" means the same everywhere.
//!
//! Positions follow Hyndman & Fan's type 7 (numpy's and polars's default):
//! quantile q of n sorted values sits at position h = q·(n − 1), between
//! values i = ⌊h⌋ and i + 1. The methods differ only in what they return
//! between two values, and each caller keeps the one its published numbers
//! were computed with:
//!
//! - [`Interpolation::Linear`] for the study summary (it was polars's
//!   `QuantileMethod::Linear`, also its `median`), the box plots and the p90
//!   objective of `study optimize`;
//! - [`Interpolation::Midpoint`] for [`median`], the mean of the middle pair,
//!   in regression checks and benchmarks;
//! - [`Interpolation::Higher`] for the upper median of the trade-off study;
//! - [`Interpolation::Nearest`] for the percentile bootstrap interval.
//!
//! Where h is a whole number every method returns that value itself, which
//! keeps results bit-identical to the formulas they replaced.

/// What a quantile falling between two sorted values v_i ≤ v_{i+1} returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// v_i + f·(v_{i+1} − v_i) with f = h − i (v_i itself when the two are equal), as polars computes it.
    Linear,
    /// ½·(v_i + v_{i+1}).
    Midpoint,
    /// v_{i+1}.
    Higher,
    /// The value at h rounded half away from zero (numpy rounds halves to even instead).
    Nearest,
}

/// Quantile `q` ∈ [0, 1] of values already sorted ascending; `None` when empty.
pub fn quantile_sorted(sorted: &[f64], q: f64, method: Interpolation) -> Option<f64> {
    assert!((0.0..=1.0).contains(&q), "quantile {q} outside [0, 1]");
    if sorted.is_empty() {
        return None;
    }
    let h = q * (sorted.len() - 1) as f64;
    let i = h.floor() as usize;
    let (lower, frac) = (sorted[i], h - i as f64);
    if frac == 0.0 {
        return Some(lower);
    }
    let upper = sorted[i + 1];
    Some(match method {
        Interpolation::Linear => linear_between(lower, upper, frac),
        Interpolation::Midpoint => 0.5 * (lower + upper),
        Interpolation::Higher => upper,
        Interpolation::Nearest => sorted[h.round() as usize],
    })
}

/// The linear interpolation between two neighbouring order statistics,
/// frac of the way from `lower` to `upper`; `lower` itself when they are
/// equal (so that two +∞ give +∞, not NaN). Every linear quantile here is
/// this one formula.
pub fn linear_between(lower: f64, upper: f64, frac: f64) -> f64 {
    if lower == upper {
        lower
    } else {
        frac * (upper - lower) + lower
    }
}

/// Quantile `q` of unsorted values (a sorted copy, NaNs ordered by `f64::total_cmp`).
pub fn quantile(values: &[f64], q: f64, method: Interpolation) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    quantile_sorted(&sorted, q, method)
}

/// Median: the middle value, or the mean of the middle pair for an even count; `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    quantile(values, 0.5, Interpolation::Midpoint)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Between two runs that never settled (+∞) the quantile is +∞, not NaN.
    #[test]
    fn linear_between_infinities_is_infinite() {
        assert_eq!(
            linear_between(f64::INFINITY, f64::INFINITY, 0.5),
            f64::INFINITY
        );
        assert_eq!(linear_between(1.0, f64::INFINITY, 0.5), f64::INFINITY);
        assert_eq!(linear_between(1.0, 3.0, 0.25), 1.5);
    }
    use Interpolation::*;

    /// The array of numpy's `percentile` documentation, `[[10, 7, 4], [3, 2, 1]]`
    /// flattened; `np.percentile(a, 50)` is 3.5 there.
    const A: [f64; 6] = [10.0, 7.0, 4.0, 3.0, 2.0, 1.0];

    #[test]
    fn linear_matches_numpy() {
        // Sorted 1 2 3 4 7 10, h = 5q; values by hand, all exact in binary:
        // numpy.percentile(A, [0, 10, 25, 50, 75, 90, 100], method="linear").
        let expected = [
            (0.0, 1.0),
            (0.1, 1.5),
            (0.25, 2.25),
            (0.5, 3.5),
            (0.75, 6.25),
            (0.9, 8.5),
            (1.0, 10.0),
        ];
        for (q, v) in expected {
            assert_eq!(quantile(&A, q, Linear), Some(v), "q = {q}");
        }
    }

    #[test]
    fn other_methods_match_numpy_at_the_median() {
        // numpy.percentile(A, 50, method=m): midpoint 3.5, higher 4.
        assert_eq!(quantile(&A, 0.5, Midpoint), Some(3.5));
        assert_eq!(quantile(&A, 0.5, Higher), Some(4.0));
        // h = 2.5: rounded away from zero to 3 (numpy's "nearest" gives index 2, value 3).
        assert_eq!(quantile(&A, 0.5, Nearest), Some(4.0));
        // h = 0.25·5 = 1.25 → index 1.
        assert_eq!(quantile(&A, 0.25, Nearest), Some(2.0));
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        assert_eq!(quantile(&[], 0.9, Linear), None);
    }

    #[test]
    fn a_whole_position_returns_the_value_itself() {
        for m in [Linear, Midpoint, Higher, Nearest] {
            assert_eq!(quantile(&[5.0], 0.9, m), Some(5.0));
            assert_eq!(quantile(&[1.0, 2.0, 3.0], 0.5, m), Some(2.0));
        }
    }

    #[test]
    fn midpoint_and_linear_differ_in_the_last_bit() {
        // Why the method is a parameter: ½(0.1 + 0.7) ≠ 0.1 + ½(0.7 − 0.1) in binary.
        let v = [0.1, 0.7];
        assert_eq!(quantile(&v, 0.5, Midpoint), Some(0.5 * (0.1 + 0.7)));
        assert_eq!(quantile(&v, 0.5, Linear), Some(0.5 * (0.7 - 0.1) + 0.1));
        assert_ne!(quantile(&v, 0.5, Midpoint), quantile(&v, 0.5, Linear));
    }

    #[test]
    fn higher_at_one_half_is_the_upper_median() {
        for n in 1..40 {
            let v: Vec<f64> = (0..n).map(f64::from).collect();
            assert_eq!(
                quantile_sorted(&v, 0.5, Higher),
                Some(v[v.len() / 2]),
                "n = {n}"
            );
        }
    }
}
