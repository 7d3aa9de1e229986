//! Holm's step-down correction for testing many hypotheses at once.
//!
//! A regression check tests three metrics for every design; at α each, a
//! study with ten designs would raise a false alarm on about a quarter of
//! nights. Holm (1979) keeps the chance of any false alarm at most α, like
//! Bonferroni, but rejects more: the k-th smallest p-value is compared with
//! α/(m − k + 1) instead of α/m. It needs no assumption about how the tests
//! depend on each other, which matters here: the metrics of one design share
//! its runs, and common random numbers couple the designs.

/// Holm-adjusted p-values, in the input order: reject hypothesis i when
/// `adjusted[i] ≤ α` (the same decisions as the step-down procedure).
pub fn holm_adjust(p_values: &[f64]) -> Vec<f64> {
    let m = p_values.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&i, &j| p_values[i].total_cmp(&p_values[j]));
    let mut adjusted = vec![0.0; m];
    let mut running = 0.0_f64;
    for (k, &i) in order.iter().enumerate() {
        // The running maximum keeps adjusted p-values in the order of the raw ones.
        running = running.max(((m - k) as f64 * p_values[i]).min(1.0));
        adjusted[i] = running;
    }
    adjusted
}

/// Which hypotheses Holm's procedure rejects at family-wise level `alpha`.
pub fn holm_reject(p_values: &[f64], alpha: f64) -> Vec<bool> {
    holm_adjust(p_values)
        .into_iter()
        .map(|p| p <= alpha)
        .collect()
}
