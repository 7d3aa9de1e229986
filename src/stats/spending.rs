//! Error spending over repeated looks at accumulating data (Lan and DeMets
//! 1983): a test that is looked at after every batch, and may stop at any
//! look, spends its level α over the looks so that the chance of any false
//! rejection, over all of them, stays at or below α.
//!
//! The level a look may use is the increment α(t_k) − α(t_{k−1}) of a
//! spending function α(t), t the share of the largest sample seen so far.
//! Taken as each look's own level (Bonferroni over the looks), the
//! increments sum to α(1) = α whatever the correlation between the looks'
//! statistics: valid for any test, conservative for the z-tests of a
//! classical group-sequential design, whose exact boundaries use the joint
//! normal law of the looks. This is what racing designs (F-Race, irace)
//! needs: a design leaves when a test rejects at its look's level, Holm
//! across the designs compared at that look ([`super::holm`]), so the true
//! best is dropped with probability at most α.

use statrs::distribution::{ContinuousCDF, Normal};

/// How a spending function spreads α over the information fraction t.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spending {
    /// O'Brien–Fleming type, α(t) = 2 − 2 Φ(z_{1−α/2}/√t): almost nothing
    /// early, nearly all of α at the end; the choice when early stops should
    /// be rare and the last look as strong as a single test.
    OBrienFleming,
    /// Pocock type, α(t) = α ln(1 + (e − 1) t): spent about evenly, early
    /// stops likelier, the last look weaker.
    Pocock,
}

impl Spending {
    /// α(t): the level spent by information fraction t (0 at t ≤ 0, α at
    /// t ≥ 1).
    pub fn spent(self, alpha: f64, t: f64) -> f64 {
        if t <= 0.0 {
            return 0.0;
        }
        // α itself at the end, not Φ(Φ⁻¹(1 − α/2)) to the inverse's accuracy.
        if t >= 1.0 {
            return alpha;
        }
        match self {
            Spending::OBrienFleming => {
                let normal = Normal::standard();
                let z = normal.inverse_cdf(1.0 - alpha / 2.0);
                2.0 * (1.0 - normal.cdf(z / t.sqrt()))
            }
            Spending::Pocock => alpha * (1.0 + (std::f64::consts::E - 1.0) * t).ln(),
        }
    }

    /// The level of each look at information fractions `fractions`
    /// (increasing, the last 1 when the study may run to its end): the
    /// increments of α(t), which sum to α(last fraction).
    pub fn look_levels(self, alpha: f64, fractions: &[f64]) -> Vec<f64> {
        let mut before = 0.0;
        fractions
            .iter()
            .map(|&t| {
                let now = self.spent(alpha, t);
                let level = (now - before).max(0.0);
                before = now;
                level
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::test_stream::uniform;

    #[test]
    fn the_spending_functions_match_their_closed_forms() {
        let (obf, pocock) = (Spending::OBrienFleming, Spending::Pocock);
        for s in [obf, pocock] {
            assert_eq!(s.spent(0.05, 0.0), 0.0);
            assert!((s.spent(0.05, 1.0) - 0.05).abs() < 1e-15, "{s:?}");
            assert!((s.spent(0.05, 2.0) - 0.05).abs() < 1e-15, "{s:?}");
        }
        // 2 − 2 Φ(1.959964/√0.5) = 2 − 2 Φ(2.771808) = 0.005575 (tables of
        // Lan and DeMets's function); Pocock 0.05 ln((1 + e)/2) = 0.031006.
        assert!(
            (obf.spent(0.05, 0.5) - 0.005_575).abs() < 2e-6,
            "{}",
            obf.spent(0.05, 0.5)
        );
        assert!((pocock.spent(0.05, 0.5) - 0.031_006).abs() < 2e-6);
        // O'Brien–Fleming keeps nearly everything for the end.
        assert!(obf.spent(0.05, 0.25) < 1e-4);
    }

    #[test]
    fn the_looks_share_alpha_between_them() {
        let fractions: Vec<f64> = (1..=10).map(|k| k as f64 / 10.0).collect();
        for s in [Spending::OBrienFleming, Spending::Pocock] {
            let levels = s.look_levels(0.05, &fractions);
            assert!(levels.iter().all(|&l| l >= 0.0));
            let total: f64 = levels.iter().sum();
            assert!((total - 0.05).abs() < 1e-15, "{s:?}: {total}");
        }
    }

    /// Ten looks at a growing sample of a true null (a mean-zero normal,
    /// z-test on the running mean), each at its spent level: over 4 000
    /// repetitions the share with any rejection stays within α (plus three
    /// standard errors), where testing every look at α rejects far more.
    #[test]
    fn repeated_looks_at_spent_levels_keep_the_error_rate_at_alpha() {
        let normal = Normal::standard();
        let (alpha, looks, batch, reps) = (0.05, 10usize, 20usize, 4000usize);
        let fractions: Vec<f64> = (1..=looks).map(|k| k as f64 / looks as f64).collect();
        let levels = Spending::Pocock.look_levels(alpha, &fractions);
        let mut state = 20_261_127u64;
        let (mut spent_rejects, mut naive_rejects) = (0usize, 0usize);
        for _ in 0..reps {
            let (mut sum, mut n) = (0.0, 0usize);
            let (mut spent_hit, mut naive_hit) = (false, false);
            for level in &levels {
                for _ in 0..batch {
                    // Box–Muller from two uniforms in (0, 1].
                    let u1 = 1.0 - uniform(&mut state);
                    let u2 = uniform(&mut state);
                    sum += (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
                    n += 1;
                }
                let z = sum / (n as f64).sqrt();
                let p = 2.0 * (1.0 - normal.cdf(z.abs()));
                spent_hit |= p <= *level;
                naive_hit |= p <= alpha;
            }
            spent_rejects += usize::from(spent_hit);
            naive_rejects += usize::from(naive_hit);
        }
        let rate = spent_rejects as f64 / reps as f64;
        let se = (alpha * (1.0 - alpha) / reps as f64).sqrt();
        assert!(rate <= alpha + 3.0 * se, "spent: {rate}");
        // Ten looks at α each: about 0.19 (Armitage, McPherson and Rowe 1969).
        let naive = naive_rejects as f64 / reps as f64;
        assert!(naive > 0.12, "naive: {naive}");
    }
}
