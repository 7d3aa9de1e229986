//! The approximate posterior of the unknowns: importance sampling with a
//! defensive mixture (Hesterberg 1995). Draws come from the priors (the
//! first stage, which also seeds the fit's restarts) and from a truncated
//! normal around the fit whose width is the first stage's weighted spread;
//! every draw is weighted by likelihood × prior / mixture density (the
//! balance heuristic over both stages), so the prior stage keeps the
//! estimate honest where the proposal is too narrow, and the proposal puts
//! draws where the likelihood is. Intervals are weighted quantiles; the
//! effective sample size says how many draws they rest on.
//!
//! Everything lives in the priors' probability coordinates u ∈ [0, 1]ᵏ,
//! where every prior is uniform (density 1).

use statrs::distribution::{Continuous, ContinuousCDF, Normal};

/// Narrowest proposal width along a coordinate (in u): a likelihood
/// sharper than this is still found by the draws near the fit.
const MIN_WIDTH: f64 = 0.01;

/// Widening of the first stage's weighted spread in the proposal: a
/// proposal wider than the target keeps the weights bounded.
const WIDEN: f64 = 2.0;

/// A truncated normal proposal on [0, 1]ᵏ with independent coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Proposal {
    /// Centre (u).
    pub centre: Vec<f64>,
    /// Width along each coordinate (u).
    pub width: Vec<f64>,
}

impl Proposal {
    /// The proposal around `centre`, as wide as `WIDEN` times the weighted
    /// spread of `draws` (u) under `log_weights`, at least [`MIN_WIDTH`].
    pub fn around(centre: &[f64], draws: &[Vec<f64>], log_weights: &[f64]) -> Self {
        let w = normalised(log_weights);
        let width = (0..centre.len())
            .map(|j| {
                let mean: f64 = draws.iter().zip(&w).map(|(u, w)| w * u[j]).sum();
                let var: f64 = draws
                    .iter()
                    .zip(&w)
                    .map(|(u, w)| w * (u[j] - mean).powi(2))
                    .sum();
                (WIDEN * var.sqrt()).max(MIN_WIDTH)
            })
            .collect();
        Proposal {
            centre: centre.to_vec(),
            width,
        }
    }

    fn coordinate(&self, j: usize) -> (Normal, f64, f64) {
        let n = Normal::new(self.centre[j], self.width[j]).expect("a positive width");
        let (lo, hi) = (n.cdf(0.0), n.cdf(1.0));
        (n, lo, hi)
    }

    /// The point at uniforms `v` (inverse CDF per coordinate).
    pub fn at(&self, v: &[f64]) -> Vec<f64> {
        v.iter()
            .enumerate()
            .map(|(j, &v)| {
                let (n, lo, hi) = self.coordinate(j);
                n.inverse_cdf(lo + (hi - lo) * v).clamp(0.0, 1.0)
            })
            .collect()
    }

    /// Its density at `u`.
    pub fn density(&self, u: &[f64]) -> f64 {
        u.iter()
            .enumerate()
            .map(|(j, &x)| {
                let (n, lo, hi) = self.coordinate(j);
                n.pdf(x) / (hi - lo)
            })
            .product()
    }
}

/// The log importance weight of a draw at `u` with log-likelihood
/// `log_likelihood`, drawn from the mixture of `prior_draws` prior draws
/// and `proposal_draws` from `proposal` (balance heuristic).
pub fn log_weight(
    log_likelihood: f64,
    u: &[f64],
    (prior_draws, proposal_draws): (usize, usize),
    proposal: Option<&Proposal>,
) -> f64 {
    let total = (prior_draws + proposal_draws) as f64;
    let q = match proposal {
        Some(p) => (prior_draws as f64 + proposal_draws as f64 * p.density(u)) / total,
        None => 1.0,
    };
    log_likelihood - q.ln()
}

/// Weights summing to one from log weights (−∞ for none).
pub fn normalised(log_weights: &[f64]) -> Vec<f64> {
    let top = log_weights
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return vec![0.0; log_weights.len()];
    }
    let w: Vec<f64> = log_weights.iter().map(|l| (l - top).exp()).collect();
    let sum: f64 = w.iter().sum();
    w.iter().map(|x| x / sum).collect()
}

/// Kish's effective sample size 1/Σw² of normalised weights.
pub fn effective_size(weights: &[f64]) -> f64 {
    let s: f64 = weights.iter().map(|w| w * w).sum();
    if s > 0.0 { 1.0 / s } else { 0.0 }
}

/// The weighted `q`-quantile of `values` (the inverse of the weighted
/// empirical CDF; NaN values and zero weights ignored).
pub fn weighted_quantile(values: &[f64], weights: &[f64], q: f64) -> Option<f64> {
    let mut pairs: Vec<(f64, f64)> = values
        .iter()
        .zip(weights)
        .filter(|(v, w)| v.is_finite() && **w > 0.0)
        .map(|(&v, &w)| (v, w))
        .collect();
    if pairs.is_empty() {
        return None;
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    let mut seen = 0.0;
    for (v, w) in &pairs {
        seen += w / total;
        if seen >= q - 1e-12 {
            return Some(*v);
        }
    }
    pairs.last().map(|p| p.0)
}

/// The `q`-quantile of the predictive distribution Σ wᵢ N(meanᵢ, sd²): a
/// model band widened by the measurement's own scatter (bisection on the
/// mixture's CDF).
pub fn predictive_quantile(means: &[f64], weights: &[f64], sd: f64, q: f64) -> Option<f64> {
    let pairs: Vec<(f64, f64)> = means
        .iter()
        .zip(weights)
        .filter(|(m, w)| m.is_finite() && **w > 0.0)
        .map(|(&m, &w)| (m, w))
        .collect();
    if pairs.is_empty() {
        return None;
    }
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    let unit = Normal::new(0.0, 1.0).expect("standard normal");
    let cdf = |x: f64| {
        pairs
            .iter()
            .map(|(m, w)| w * unit.cdf((x - m) / sd))
            .sum::<f64>()
            / total
    };
    let lo0 = pairs.iter().map(|p| p.0).fold(f64::INFINITY, f64::min) - 10.0 * sd;
    let hi0 = pairs.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max) + 10.0 * sd;
    let (mut lo, mut hi) = (lo0, hi0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Importance sampling from the defensive mixture recovers a known
    /// posterior: a Gaussian likelihood N(0.3, 0.05²) under a uniform prior
    /// on [0, 1] has mean 0.3 and 95 % interval 0.3 ± 1.96·0.05.
    #[test]
    fn mixture_weights_recover_a_gaussian_posterior() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let loglik = |u: f64| -0.5 * ((u - 0.3) / 0.05).powi(2);
        let prior: Vec<Vec<f64>> = (0..200).map(|_| vec![rng.random::<f64>()]).collect();
        let lw: Vec<f64> = prior.iter().map(|u| loglik(u[0])).collect();
        let proposal = Proposal::around(&[0.32], &prior, &lw);
        let more: Vec<Vec<f64>> = (0..4000)
            .map(|_| proposal.at(&[rng.random::<f64>()]))
            .collect();
        let all: Vec<Vec<f64>> = prior.iter().chain(&more).cloned().collect();
        let lw: Vec<f64> = all
            .iter()
            .map(|u| log_weight(loglik(u[0]), u, (200, 4000), Some(&proposal)))
            .collect();
        let w = normalised(&lw);
        let x: Vec<f64> = all.iter().map(|u| u[0]).collect();
        let mean: f64 = x.iter().zip(&w).map(|(x, w)| x * w).sum();
        assert!((mean - 0.3).abs() < 0.005, "{mean}");
        let lo = weighted_quantile(&x, &w, 0.025).unwrap();
        let hi = weighted_quantile(&x, &w, 0.975).unwrap();
        assert!((lo - (0.3 - 1.96 * 0.05)).abs() < 0.01, "{lo}");
        assert!((hi - (0.3 + 1.96 * 0.05)).abs() < 0.01, "{hi}");
        assert!(effective_size(&w) > 1000.0, "{}", effective_size(&w));
    }

    /// The predictive quantiles of one model value are the measurement's
    /// normal quantiles around it.
    #[test]
    fn predictive_band_of_one_value_is_normal() {
        let q = predictive_quantile(&[2.0], &[1.0], 0.5, 0.975).unwrap();
        assert!((q - (2.0 + 1.959_964 * 0.5)).abs() < 1e-5, "{q}");
        let q = weighted_quantile(&[3.0, 1.0, 2.0], &[0.2, 0.3, 0.5], 0.5).unwrap();
        assert_eq!(q, 2.0);
    }
}
