//! Two-sample Kolmogorov–Smirnov test (two-sided), via statrs.
//!
//! statrs computes the exact p-value (Schröer & Trenkler 1995) only up to
//! m·n = 10 000 and otherwise Kolmogorov's limiting distribution with
//! n_e = m n / (m + n), as R's `ks.test` does for large samples. This wrapper
//! picks the exact method where statrs allows it, and handles the two cases
//! statrs does not: an empty sample (no test) and D = 0, where statrs's
//! asymptotic series never reaches its stopping term.

use statrs::stats_tests::NaNPolicy;
use statrs::stats_tests::ks_test::{KSTwoSampleAlternativeMethod, ks_twosample};

/// Largest m·n for which the exact p-value is computed (statrs's own limit).
pub const EXACT_LIMIT: usize = 10_000;

/// Outcome of a two-sample KS test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KsResult {
    /// D = sup |F_a − F_b|, the largest gap between the empirical CDFs.
    pub statistic: f64,
    /// Two-sided p-value.
    pub p_value: f64,
    /// True when the p-value is exact, false when asymptotic.
    pub exact: bool,
}

/// Two-sided two-sample KS test; None when either sample is empty or holds a NaN.
pub fn ks_two_sample(a: &[f64], b: &[f64]) -> Option<KsResult> {
    if a.is_empty() || b.is_empty() || a.iter().chain(b).any(|v| v.is_nan()) {
        return None;
    }
    let exact = a.len() * b.len() <= EXACT_LIMIT;
    let method = if exact {
        KSTwoSampleAlternativeMethod::TwoSidedExact
    } else {
        KSTwoSampleAlternativeMethod::TwoSidedAsymptotic
    };
    let statistic = two_sample_statistic(a, b);
    if statistic == 0.0 {
        return Some(KsResult {
            statistic,
            p_value: 1.0,
            exact,
        });
    }
    let (statistic, p) = ks_twosample(a.to_vec(), b.to_vec(), method, NaNPolicy::Error).ok()?;
    Some(KsResult {
        statistic,
        // The truncated alternating series can overshoot 1 by rounding.
        p_value: p.clamp(0.0, 1.0),
        exact,
    })
}

/// D computed directly, to recognise identical distributions before calling statrs.
fn two_sample_statistic(a: &[f64], b: &[f64]) -> f64 {
    let mut a = a.to_vec();
    let mut b = b.to_vec();
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (mut i, mut j, mut d) = (0, 0, 0.0_f64);
    while i < a.len() && j < b.len() {
        // Step past every copy of the smaller value in both samples, so ties move together.
        let x = a[i].min(b[j]);
        while i < a.len() && a[i] == x {
            i += 1;
        }
        while j < b.len() && b[j] == x {
            j += 1;
        }
        d = d.max((i as f64 / na - j as f64 / nb).abs());
    }
    d
}
