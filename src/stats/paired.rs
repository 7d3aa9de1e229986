//! Paired comparisons of two designs run on the same random samples.
//!
//! Designs in one study share their sampled rotors and disturbances (common
//! random numbers), so run i of design A and run i of design B differ only by
//! the design. Comparing them pair by pair removes the run-to-run spread that
//! a two-sample test would have to see through.
//!
//! - Settling time is right-censored at the horizon: [`compare_settling`]
//!   counts in how many pairs each design settled sooner and tests the counts
//!   with the exact two-sided sign test ([`sign_test_p_value`]; Dixon & Mood
//!   1946), p = min(1, 2·P(X ≤ min(k, m − k))) with X ~ Binomial(m, ½) over the
//!   m untied pairs, as SciPy's `binomtest(k, m, 0.5)`. The sign test needs only
//!   which run settled first, and censoring never hides that (unless both are
//!   censored, a tie); rank tests on the differences would need their sizes,
//!   which censoring hides. The effect size is the median of t_B − t_A with a
//!   censored time taken as +∞, and its percentile bootstrap interval (Efron &
//!   Tibshirani 1993, ch. 13) over resampled pairs.
//! - Residual vibration is always observed: [`wilcoxon_signed_rank`]
//!   (Wilcoxon 1945; ties and normal approximation as in Hollander, Wolfe &
//!   Chicken 2014, §3.1) reproduces `scipy.stats.wilcoxon(a, b)` of SciPy
//!   1.17.1 with its defaults (`zero_method="wilcox"`, `correction=False`,
//!   `method="auto"`).
//! - [`median_ratio`]: median of a_i / b_i, with the same bootstrap interval.
//!
//! Shares get Wilson's (1927) score interval, as in [`super::interval`], but
//! at the caller's level. Bootstrap intervals take [`CI_RESAMPLES`] resamples
//! of the pairs and the percentiles by nearest rank, as [`super::bootstrap`].

use super::bootstrap::CI_RESAMPLES;
use super::interval::wilson_interval_at;
use super::quantile::{Interpolation, quantile_sorted};
use rand::{Rng, RngExt};
use statrs::distribution::{ContinuousCDF, Normal};
use statrs::function::factorial::ln_binomial;
use statrs::function::gamma::gamma_ur;
use std::f64::consts::LN_2;

/// Most pairs for which the Wilcoxon p-value is exact when there are no ties or zeros (SciPy's `method="auto"` limit).
pub const WILCOXON_EXACT_LIMIT: usize = 50;

/// Most pairs for which the Wilcoxon p-value is exact despite ties or zeros (SciPy enumerates all 2^n sign flips).
pub const WILCOXON_ENUMERATION_LIMIT: usize = 13;

/// How one run settled: at a time, or not by the horizon (right-censored).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Settling {
    /// Settled at this time (finite, in the study's time unit).
    Settled(f64),
    /// Did not settle by the horizon: its settling time is only known to exceed it.
    Censored,
}

impl Settling {
    /// `Settled(time)` when `settled`, otherwise `Censored` (the time is then ignored).
    pub fn new(time: f64, settled: bool) -> Self {
        if settled {
            Self::Settled(time)
        } else {
            Self::Censored
        }
    }
}

/// d = t_b − t_a with a censored time at +∞ and 0 for two censored runs
/// (∞ − ∞ would be NaN). Its sign is the ordering rule: positive when `a`
/// settled sooner (a settled run beats a censored one), 0 for a tie.
fn difference(a: Settling, b: Settling) -> f64 {
    match (a, b) {
        (Settling::Settled(x), Settling::Settled(y)) => y - x,
        (Settling::Settled(_), Settling::Censored) => f64::INFINITY,
        (Settling::Censored, Settling::Settled(_)) => f64::NEG_INFINITY,
        (Settling::Censored, Settling::Censored) => 0.0,
    }
}

/// Outcome of comparing the settling of two designs over paired runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SettlingComparison {
    /// Pairs compared.
    pub n: u64,
    /// Pairs where A settled sooner (including A settled, B censored).
    pub a_sooner: u64,
    /// Pairs where B settled sooner (including B settled, A censored).
    pub b_sooner: u64,
    /// Pairs with equal times or both censored.
    pub ties: u64,
    /// a_sooner / n: the share of all pairs, ties included, that A won.
    pub a_sooner_share: f64,
    /// Wilson score interval of `a_sooner_share` at the requested level.
    pub a_sooner_share_interval: (f64, f64),
    /// Two-sided exact sign test p-value of a_sooner against b_sooner (ties dropped); 1 when all pairs tie.
    pub sign_test_p: f64,
    /// Median of d = t_B − t_A over pairs (positive: A sooner), a censored
    /// time counting as +∞. +∞ means "B did not settle": in half of the pairs
    /// or more, A settled and B did not by the horizon. −∞ means "A did not
    /// settle", the same with A and B exchanged. Exactly half each way gives 0.
    pub median_difference: f64,
    /// Percentile bootstrap interval of `median_difference`; either end may be ±∞ in the same sense.
    pub median_difference_interval: (f64, f64),
}

/// Compares design A's settling with design B's over paired runs (run i of A
/// with run i of B). None when the lengths differ, there are no pairs, or a
/// settled time is not finite. The bootstrap draws [`CI_RESAMPLES`] resamples
/// of the pairs from `rng`, so the result is reproducible given its state.
/// Panics unless 0 < `level` < 1.
pub fn compare_settling(
    a: &[Settling],
    b: &[Settling],
    level: f64,
    rng: &mut impl Rng,
) -> Option<SettlingComparison> {
    compare_settling_with(a, b, level, |d| bootstrap_median(d, level, rng))
}

/// [`compare_settling`] with the median difference's interval read off the
/// sorted differences by the sign test's own order statistics (the
/// distribution-free interval of a median, normal approximation to the
/// binomial) instead of a bootstrap: no resampling, for a race's looks.
pub fn compare_settling_by_ranks(
    a: &[Settling],
    b: &[Settling],
    level: f64,
) -> Option<SettlingComparison> {
    compare_settling_with(a, b, level, |d| median_rank_interval(d, level))
}

/// [`compare_settling`] with the median difference's interval from `interval`.
fn compare_settling_with(
    a: &[Settling],
    b: &[Settling],
    level: f64,
    interval: impl FnOnce(&[f64]) -> (f64, f64),
) -> Option<SettlingComparison> {
    check_level(level);
    let finite = |s: &Settling| !matches!(s, Settling::Settled(t) if !t.is_finite());
    if a.len() != b.len() || a.is_empty() || !a.iter().chain(b).all(finite) {
        return None;
    }
    // Distinct finite times never subtract to 0, so the sign of d decides the pair.
    let differences: Vec<f64> = a.iter().zip(b).map(|(&x, &y)| difference(x, y)).collect();
    let a_sooner = differences.iter().filter(|&&d| d > 0.0).count() as u64;
    let b_sooner = differences.iter().filter(|&&d| d < 0.0).count() as u64;
    let n = a.len() as u64;
    let median_difference_interval = interval(&differences);
    Some(SettlingComparison {
        n,
        a_sooner,
        b_sooner,
        ties: n - a_sooner - b_sooner,
        a_sooner_share: a_sooner as f64 / n as f64,
        a_sooner_share_interval: wilson_interval_at(a_sooner, n, level),
        sign_test_p: sign_test_p_value(a_sooner, a_sooner + b_sooner),
        median_difference: median_in_place(&mut differences.clone()),
        median_difference_interval,
    })
}

/// Two-sided exact sign test: p-value of `successes` out of `trials` under
/// Binomial(trials, ½), as SciPy's `binomtest(successes, trials, 0.5)`; 1 when
/// `trials` is 0. Panics if `successes > trials`.
pub fn sign_test_p_value(successes: u64, trials: u64) -> f64 {
    assert!(successes <= trials, "more successes than trials");
    let m = successes.min(trials - successes);
    if 2 * m == trials {
        return 1.0;
    }
    // P(X ≤ m) = C(n, m)/2^n · Σ_{j ≤ m} C(n, j)/C(n, m). The sum runs down from
    // j = m by the ratio C(n, j−1)/C(n, j) = j/(n − j + 1) < 1, so no term
    // overflows, and the tiny factor C(n, m)/2^n stays a logarithm until the
    // end: 2^−n underflows from n = 1075 on.
    let n = trials as f64;
    let (mut sum, mut term) = (1.0_f64, 1.0_f64);
    for j in (1..=m).rev() {
        let ratio = j as f64 / (n - j as f64 + 1.0);
        term *= ratio;
        sum += term;
        // Later ratios are smaller still, so the rest is below a geometric
        // series in `ratio`; stop once that bound no longer moves the sum.
        if term * ratio / (1.0 - ratio) < sum * f64::EPSILON / 4.0 {
            break;
        }
    }
    let log_tail = ln_binomial(trials, m) - n * LN_2 + sum.ln();
    (LN_2 + log_tail).exp().clamp(0.0, 1.0)
}

/// Outcome of a Wilcoxon signed-rank test on paired values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WilcoxonResult {
    /// Pairs ranked: those with a nonzero difference a_i − b_i.
    pub n: usize,
    /// Pairs with a_i = b_i, dropped before ranking (SciPy's `zero_method="wilcox"`).
    pub zeros: usize,
    /// W+: the sum of the (average) ranks of |a_i − b_i| over pairs with a_i > b_i.
    pub w_plus: f64,
    /// W−: the same over pairs with a_i < b_i; W+ + W− = n(n+1)/2, and SciPy's statistic is min(W+, W−).
    pub w_minus: f64,
    /// Two-sided p-value.
    pub p_value: f64,
    /// True when the p-value comes from the exact null distribution, false for the normal approximation.
    pub exact: bool,
}

/// Wilcoxon signed-rank test of a_i − b_i symmetric about 0, two-sided, as
/// SciPy 1.17.1's `wilcoxon(a, b)`: zero differences dropped, average ranks
/// for ties; exact p when `a.len()` ≤ [`WILCOXON_EXACT_LIMIT`] with no ties or
/// zeros, or `a.len()` ≤ [`WILCOXON_ENUMERATION_LIMIT`]; otherwise the normal
/// approximation with the tie correction of the variance and no continuity
/// correction (SciPy's default `correction=False`). None when the lengths
/// differ, a value is not finite, or every difference is zero (nothing to
/// rank, e.g. identical inputs; SciPy returns p = 1 or NaN there).
pub fn wilcoxon_signed_rank(a: &[f64], b: &[f64]) -> Option<WilcoxonResult> {
    if a.len() != b.len() || !a.iter().chain(b).all(|v| v.is_finite()) {
        return None;
    }
    let mut d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    d.retain(|&v| v != 0.0);
    let (n, zeros) = (d.len(), a.len() - d.len());
    if n == 0 {
        return None;
    }
    // Ranks are doubled so that average ranks of ties (halves) are integers:
    // sums stay exact, and the exact distribution is a table over integers.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| d[i].abs().total_cmp(&d[j].abs()));
    let mut rank2 = vec![0_usize; n];
    let (mut start, mut tie_sum) = (0, 0.0_f64);
    while start < n {
        let first = d[order[start]].abs();
        let end = start + order[start..].partition_point(|&i| d[i].abs() == first);
        // Sorted positions start..end share the ranks start+1 ..= end: average (start+1+end)/2.
        for &i in &order[start..end] {
            rank2[i] = start + 1 + end;
        }
        let t = (end - start) as f64;
        tie_sum += t * t * t - t;
        start = end;
    }
    let w_plus2: usize = (0..n).filter(|&i| d[i] > 0.0).map(|i| rank2[i]).sum();
    let w_minus2 = n * (n + 1) - w_plus2;
    let exact = a.len() <= WILCOXON_ENUMERATION_LIMIT
        || (a.len() <= WILCOXON_EXACT_LIMIT && tie_sum == 0.0 && zeros == 0);
    let p_value = if exact {
        exact_signed_rank_p(&rank2, w_plus2)
    } else {
        let nf = n as f64;
        let variance = (nf * (nf + 1.0) * (2.0 * nf + 1.0) - tie_sum / 2.0) / 24.0;
        let z = (w_plus2 as f64 / 2.0 - nf * (nf + 1.0) / 4.0) / variance.sqrt();
        // 2·Φ(−|z|) = erfc(|z|/√2) = Q(½, z²/2). statrs 0.19's erfc is off by
        // ~1e-10 relative (truncated constants, fixed after 0.19.1 by
        // statrs-dev/statrs#412); its incomplete gamma is good to ~1e-16 here.
        // (Its x must be positive: z = 0, which needs W+ at its mean, is p = 1.)
        let x = z * z / 2.0;
        if x > 0.0 { gamma_ur(0.5, x) } else { 1.0 }
    };
    Some(WilcoxonResult {
        n,
        zeros,
        w_plus: w_plus2 as f64 / 2.0,
        w_minus: w_minus2 as f64 / 2.0,
        p_value: p_value.clamp(0.0, 1.0),
        exact,
    })
}

/// 2·min(P(W ≥ w), P(W ≤ w)) for W the sum of the (doubled) ranks given a
/// random sign each, i.e. over all 2^n equally likely sign flips: Wilcoxon's
/// exact distribution without ties, SciPy's exhaustive permutation test with them.
fn exact_signed_rank_p(rank2: &[usize], w2: usize) -> f64 {
    let total: usize = rank2.iter().sum();
    // counts[s]: sign assignments with doubled W+ = s. Whole numbers up to 2^50
    // for 50 pairs, exact in f64, so the tails below are exact too.
    let mut counts = vec![0.0_f64; total + 1];
    counts[0] = 1.0;
    let mut reach = 0;
    for &r in rank2 {
        reach += r;
        for s in (r..=reach).rev() {
            counts[s] += counts[s - r];
        }
    }
    let lower: f64 = counts[..=w2].iter().sum();
    let upper: f64 = counts[w2..].iter().sum();
    2.0 * lower.min(upper) / 2_f64.powi(rank2.len() as i32)
}

/// Median of the paired ratios a_i / b_i with its percentile bootstrap
/// interval at `level`, meant for positive values such as residual vibration.
/// Pairs with b_i = 0 have no ratio and are skipped (the bootstrap resamples
/// the remaining pairs). None when the lengths differ, a value is not finite,
/// or no pair is left. One pair gives a degenerate interval (r, r). The
/// bootstrap draws [`CI_RESAMPLES`] resamples from `rng`. Panics unless 0 < `level` < 1.
pub fn median_ratio(
    a: &[f64],
    b: &[f64],
    level: f64,
    rng: &mut impl Rng,
) -> Option<(f64, (f64, f64))> {
    check_level(level);
    if a.len() != b.len() || !a.iter().chain(b).all(|v| v.is_finite()) {
        return None;
    }
    let pairs = a.iter().zip(b).filter(|&(_, &y)| y != 0.0);
    let ratios: Vec<f64> = pairs.map(|(x, y)| x / y).collect();
    if ratios.is_empty() {
        return None;
    }
    Some((
        median_in_place(&mut ratios.clone()),
        bootstrap_median(&ratios, level, rng),
    ))
}

fn check_level(level: f64) {
    assert!(0.0 < level && level < 1.0, "level {level} outside (0, 1)");
}

/// The median exactly as [`super::quantile::median`] computes it (the mean of
/// the middle pair for an even count), but by selection, O(n) instead of a
/// sort per bootstrap resample, and with 0 for a middle pair (−∞, +∞), which
/// is as far on one side as on the other, instead of NaN. Reorders `values`;
/// panics on an empty slice.
fn median_in_place(values: &mut [f64]) -> f64 {
    let odd = values.len() % 2 == 1;
    let (below, &mut upper, _) = values.select_nth_unstable_by(values.len() / 2, f64::total_cmp);
    if odd {
        return upper;
    }
    // f64::max may pick either zero of ±0, but either gives the same mean with `upper`.
    let lower = below.iter().fold(f64::NEG_INFINITY, |m, &v| v.max(m));
    if lower == f64::NEG_INFINITY && upper == f64::INFINITY {
        0.0
    } else {
        0.5 * (lower + upper)
    }
}

/// Percentile bootstrap interval at `level` of the median of `values`.
/// The distribution-free `level` interval of the median of `values`: the
/// k-th smallest and k-th largest value, k from the normal approximation to
/// Binomial(n, ½) (Conover 1999, §3.2); unbounded when n is too small for
/// any k ≥ 1.
fn median_rank_interval(values: &[f64], level: f64) -> (f64, f64) {
    let n = values.len();
    let z = Normal::standard().inverse_cdf(0.5 + level / 2.0);
    let k = (0.5 * (n as f64 - z * (n as f64).sqrt())).floor();
    if k < 1.0 {
        return (f64::NEG_INFINITY, f64::INFINITY);
    }
    let k = k as usize;
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    (sorted[k - 1], sorted[n - k])
}

fn bootstrap_median(values: &[f64], level: f64, rng: &mut impl Rng) -> (f64, f64) {
    let n = values.len();
    let mut buf = vec![0.0; n];
    let mut medians: Vec<f64> = (0..CI_RESAMPLES)
        .map(|_| {
            for v in buf.iter_mut() {
                *v = values[rng.random_range(0..n)];
            }
            median_in_place(&mut buf)
        })
        .collect();
    medians.sort_by(f64::total_cmp);
    let tail = (1.0 - level) / 2.0;
    let at = |q| quantile_sorted(&medians, q, Interpolation::Nearest).expect("resamples");
    (at(tail), at(1.0 - tail))
}

#[cfg(test)]
mod tests {
    //! Reference values from SciPy 1.17.1 (NumPy 2.4.6), /tmp/paired-scratch/reference.py:
    //!
    //! ```python
    //! from scipy.stats import binomtest, wilcoxon
    //! binomtest(k, n, 0.5).pvalue           # for each (k, n) in SIGN_TEST
    //! wilcoxon(x, y)                        # x, y = EXACT_X, EXACT_Y
    //! xb = [float((7 * i) % 11) for i in range(60)]
    //! yb = [float((5 * i) % 13) for i in range(60)]
    //! wilcoxon(xb, yb); wilcoxon(xb[:13], yb[:13]); wilcoxon(xb[:30], yb[:30])
    //! xd = [float(i * i % 101) + 0.5 * i for i in range(1, 52)]
    //! yd = [float(i) for i in range(1, 52)]
    //! wilcoxon(xd[:50], yd[:50]); wilcoxon(xd, yd)
    //! ```
    use super::super::{interval::wilson_interval, quantile::median};
    use super::*;
    use Settling::{Censored, Settled};
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn rng() -> Xoshiro256PlusPlus {
        Xoshiro256PlusPlus::seed_from_u64(7)
    }

    fn assert_close(got: f64, want: f64, rel: f64) {
        assert!((got - want).abs() <= rel * want.abs(), "{got:e} {want:e}");
    }

    /// (k, n, `binomtest(k, n, 0.5).pvalue`).
    const SIGN_TEST: [(u64, u64, f64); 10] = [
        (3, 20, 0.0025768280029296875),
        (5, 20, 0.04138946533203125),
        (10, 20, 1.0),
        (0, 20, 1.9073486328125e-06),
        (480, 1000, 0.2174482932041415),
        (450, 1000, 0.0017305360849763027),
        (49_000, 100_000, 2.5887160383468943e-10),
        (45_000, 100_000, 8.600341645712794e-220),
        (0, 100_000, 0.0),
        (499_000, 1_000_000, 0.0456082998653896),
    ];

    #[test]
    fn the_rank_interval_of_a_median_is_the_tables() {
        // n = 100 at 95 %: the 40th and 61st smallest (Conover 1999, Table
        // A3's normal approximation); too few values for any rank: unbounded.
        let values: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        assert_eq!(median_rank_interval(&values, 0.95), (40.0, 61.0));
        let few = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(
            median_rank_interval(&few, 0.95),
            (f64::NEG_INFINITY, f64::INFINITY)
        );
    }

    #[test]
    fn sign_test_matches_scipy_binomtest() {
        for (k, n, p) in SIGN_TEST {
            // statrs's ln Γ (1e-16 of ln n! ≈ 1e6) limits large n to about 1e-10.
            let rel = if n <= 1000 { 1e-12 } else { 1e-9 };
            assert_close(sign_test_p_value(k, n), p, rel);
            assert_close(sign_test_p_value(n - k, n), p, rel);
        }
        assert_eq!(sign_test_p_value(0, 0), 1.0);
    }

    const EXACT_X: [f64; 12] = [
        1.83, 0.5, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.3, 0.71, 2.12, 0.97,
    ];
    const EXACT_Y: [f64; 12] = [
        0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.19, 1.29, 0.66, 1.71, 0.86,
    ];

    fn check(x: &[f64], y: &[f64], statistic: f64, p: f64, exact: bool) {
        let r = wilcoxon_signed_rank(x, y).unwrap();
        assert_eq!((r.w_plus.min(r.w_minus), r.exact), (statistic, exact));
        assert_eq!(r.w_plus + r.w_minus, (r.n * (r.n + 1)) as f64 / 2.0);
        assert_close(r.p_value, p, 1e-12);
        // Swapping the samples swaps W+ and W− and keeps p.
        let s = wilcoxon_signed_rank(y, x).unwrap();
        assert_eq!((s.w_plus, s.w_minus), (r.w_minus, r.w_plus));
        assert_eq!(s.p_value, r.p_value);
    }

    fn modular(n: usize, k: usize, m: usize) -> Vec<f64> {
        (0..n).map(|i| ((k * i) % m) as f64).collect()
    }

    #[test]
    fn wilcoxon_matches_scipy() {
        // (a) Exact path, no ties: p = 66/4096.
        check(&EXACT_X, &EXACT_Y, 9.0, 0.01611328125, true);
        // (b) Normal path, n = 60 with 8 zeros and ties.
        let (xb, yb) = (modular(60, 7, 11), modular(60, 5, 13));
        check(&xb, &yb, 523.0, 0.12933211052816804, false);
        assert_eq!(wilcoxon_signed_rank(&xb, &yb).unwrap().zeros, 8);
        // n = 13 with a zero: SciPy enumerates all sign flips.
        check(&xb[..13], &yb[..13], 24.0, 0.443359375, true);
        // n = 30 with zeros: the normal approximation already.
        check(&xb[..30], &yb[..30], 143.0, 0.40789373229728965, false);
        // The largest exact case and the smallest normal one, no ties.
        let xd: Vec<f64> = (1..52)
            .map(|i| (i * i % 101) as f64 + 0.5 * i as f64)
            .collect();
        let yd: Vec<f64> = (1..52).map(|i| i as f64).collect();
        check(&xd[..50], &yd[..50], 41.0, 1.7687185049908294e-11, true);
        check(&xd, &yd, 41.0, 5.5329012098198405e-09, false);
    }

    #[test]
    fn swapping_designs_swaps_the_winners_and_keeps_p() {
        let mut draw = rng();
        for n in [1, 2, 7, 40, 301] {
            // Whole times so that ties occur, and censoring on either side.
            let mut run = |shift: f64| {
                let t = draw.random_range(1..20) as f64 + shift;
                Settling::new(t, t < 18.0)
            };
            let (a, b): (Vec<_>, Vec<_>) = (0..n).map(|_| (run(0.0), run(1.0))).unzip();
            let ab = compare_settling(&a, &b, 0.95, &mut rng()).unwrap();
            let ba = compare_settling(&b, &a, 0.95, &mut rng()).unwrap();
            assert_eq!((ab.a_sooner, ab.b_sooner), (ba.b_sooner, ba.a_sooner));
            assert_eq!((ab.ties, ab.a_sooner + ab.b_sooner + ab.ties), (ba.ties, n));
            assert_eq!(ab.sign_test_p, ba.sign_test_p);
            // The same resamples of negated differences: a mirrored median and interval.
            assert_eq!(ab.median_difference, -ba.median_difference);
            let (lo, hi) = ba.median_difference_interval;
            assert_eq!(ab.median_difference_interval, (-hi, -lo));
        }
    }

    #[test]
    fn ties_and_censoring_follow_the_ordering_rule() {
        let a = [Settled(3.0), Censored, Settled(5.0), Censored];
        let b = [Settled(4.0), Settled(9.0), Censored, Censored];
        let c = compare_settling(&a, &b, 0.9, &mut rng()).unwrap();
        assert_eq!((c.n, c.a_sooner, c.b_sooner, c.ties), (4, 2, 1, 1));
        // Differences −∞, 0, 1, +∞: the middle pair (0, 1).
        assert_eq!(c.median_difference, 0.5);
        let tied = [Censored, Settled(2.0)];
        let c = compare_settling(&tied, &tied, 0.95, &mut rng()).unwrap();
        assert_eq!((c.ties, c.sign_test_p, c.median_difference), (2, 1.0, 0.0));
    }

    #[test]
    fn b_never_settling_gives_an_infinite_median() {
        let a = vec![Settled(2.0); 30];
        let mut b = vec![Censored; 30];
        b[0] = Settled(1.0);
        let c = compare_settling(&a, &b, 0.95, &mut rng()).unwrap();
        assert_eq!((c.a_sooner, c.b_sooner), (29, 1));
        assert_eq!(c.median_difference, f64::INFINITY);
        assert_eq!(c.median_difference_interval.1, f64::INFINITY);
        // P(X ≤ 1) = 31/2^30 for X ~ Binomial(30, ½).
        assert_close(c.sign_test_p, 2.0 * 31.0 / 2_f64.powi(30), 1e-12);
    }

    #[test]
    fn invalid_input_gives_none() {
        let a = [Settled(1.0), Censored];
        assert_eq!(compare_settling(&a, &a[..1], 0.95, &mut rng()), None);
        assert_eq!(compare_settling(&[], &[], 0.95, &mut rng()), None);
        let nan = [Settled(f64::NAN), Censored];
        assert_eq!(compare_settling(&a, &nan, 0.95, &mut rng()), None);
        // Identical inputs leave no nonzero difference to rank: None, not p = 1.
        assert_eq!(wilcoxon_signed_rank(&EXACT_X, &EXACT_X), None);
        assert_eq!(wilcoxon_signed_rank(&EXACT_X, &EXACT_Y[1..]), None);
        assert_eq!(wilcoxon_signed_rank(&[1.0, f64::NAN], &[2.0, 3.0]), None);
    }

    #[test]
    fn helpers_agree_with_the_house_functions() {
        for (k, n) in [(0, 20), (7, 20), (20, 20), (480, 1000)] {
            let ((lo, hi), (lo95, hi95)) = (wilson_interval_at(k, n, 0.95), wilson_interval(k, n));
            let close = |x: f64, y: f64| (x - y).abs() < 1e-12;
            assert!(close(lo, lo95) && close(hi, hi95), "{k}/{n}");
        }
        let mut draw = rng();
        for n in 1..60 {
            let v: Vec<f64> = (0..n)
                .map(|_| draw.random_range(-5..5) as f64 / 8.0)
                .collect();
            assert_eq!(median_in_place(&mut v.clone()), median(&v).unwrap());
        }
        let (inf, neg_inf) = (f64::INFINITY, f64::NEG_INFINITY);
        assert_eq!(median_in_place(&mut [inf, 1.0, neg_inf, 2.0]), 1.5);
        assert_eq!(median_in_place(&mut [inf, neg_inf]), 0.0);
    }

    #[test]
    fn median_ratio_skips_zero_denominators_and_is_reproducible() {
        let (a, b) = ([2.0, 3.0, 4.0, 5.0], [1.0, 1.0, 2.0, 0.0]);
        let (m, (lo, hi)) = median_ratio(&a, &b, 0.95, &mut rng()).unwrap();
        assert!(m == 2.0 && lo >= 2.0 && hi <= 3.0);
        assert_eq!(median_ratio(&a, &b, 0.95, &mut rng()), Some((m, (lo, hi))));
        assert_eq!(median_ratio(&[1.0], &[0.0], 0.95, &mut rng()), None);
        assert_eq!(median_ratio(&[1.0], &[f64::NAN], 0.95, &mut rng()), None);
        let one = median_ratio(&[3.0], &[2.0], 0.95, &mut rng());
        assert_eq!(one, Some((1.5, (1.5, 1.5))));
    }
}
