//! Two proportions compared with Fisher's exact test (two-sided), via statrs.
//!
//! The settled fraction is usually 1 or close to it, where the pooled
//! z-test's normal approximation fails (its variance vanishes at 0 and 1);
//! Fisher's test conditions on the margins and is exact at any count.

use statrs::stats_tests::{Alternative, fishers_exact};

/// Outcome of comparing successes_a / trials_a with successes_b / trials_b.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProportionResult {
    /// Proportion in the first sample.
    pub a: f64,
    /// Proportion in the second sample.
    pub b: f64,
    /// b − a, the effect size (a difference of proportions).
    pub difference: f64,
    /// Two-sided p-value of Fisher's exact test.
    pub p_value: f64,
}

/// Fisher's exact test of equal proportions; None when a sample has no trials.
pub fn fisher_two_proportions(
    successes_a: u64,
    trials_a: u64,
    successes_b: u64,
    trials_b: u64,
) -> Option<ProportionResult> {
    if trials_a == 0 || trials_b == 0 || successes_a > trials_a || successes_b > trials_b {
        return None;
    }
    let table = [
        successes_a,
        trials_a - successes_a,
        successes_b,
        trials_b - successes_b,
    ];
    // statrs forms the two-sided p as 1 − (the rest), which rounding can push
    // just below 0 (−4.2e-13 seen for 500/500 against 447/500): a p-value is
    // a probability, so keep it in [0, 1].
    let p_value = fishers_exact(&table, Alternative::TwoSided)
        .ok()?
        .clamp(0.0, 1.0);
    let (a, b) = (
        successes_a as f64 / trials_a as f64,
        successes_b as f64 / trials_b as f64,
    );
    Some(ProportionResult {
        a,
        b,
        difference: b - a,
        p_value,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extreme_tables_give_probabilities() {
        let raw = fishers_exact(&[500, 0, 447, 53], Alternative::TwoSided).unwrap();
        let result = fisher_two_proportions(500, 500, 447, 500).unwrap();
        assert!((0.0..=1.0).contains(&result.p_value), "{}", result.p_value);
        // The clamp only removes rounding: the raw value was already ~0.
        assert!(raw.abs() < 1e-9 && result.p_value < 1e-9, "{raw}");
        let same = fisher_two_proportions(500, 500, 500, 500).unwrap();
        assert_eq!(same.p_value, 1.0);
    }
}
