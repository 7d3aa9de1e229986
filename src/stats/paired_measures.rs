//! Two designs compared on one summary measure at a time: the difference of
//! their means, of a quantile, or of a share, with an interval and a
//! two-sided p-value, paired when the designs met the same samples.
//!
//! - Means of paired values: the paired t-test on d_i = a_i − b_i (Student
//!   1908), with its t interval. With hundreds of pairs the t reference is the
//!   normal one to three digits; it stays honest for the few-sample studies
//!   the tests run.
//! - Quantiles (p90 of settling, p95 of residuals): a percentile bootstrap
//!   of the difference of the two quantiles (Efron & Tibshirani 1993,
//!   ch. 13, 15), resampling pairs when paired and each sample on its own
//!   otherwise; its p-value is the two-sided share of resampled differences
//!   on the far side of 0, counted as (k + 1)/(B + 1) so that it is never 0.
//! - Shares of paired yes/no outcomes (settled by a time, residual under a
//!   level): McNemar's exact test, the sign test on the discordant pairs
//!   ([`super::paired::sign_test_p_value`]), with the Wald interval of the
//!   paired difference of proportions (Agresti 2013, §11.1).
//!
//! No p-value here is smaller than an exact distribution-free test on the
//! same data could ever give: 2^(1−n) for n pairs (every sign flip of the
//! differences), 2/C(n_a + n_b, n_a) for two unpaired samples (every
//! relabelling). Without that floor a bootstrap or t-test on three runs per
//! design would call a difference significant at 10⁻⁵ ([`exact_floor`]).
//!
//! Nothing here knows about rotors; callers bring the values.

use super::bootstrap::{CI_RESAMPLES, STD_ERROR_RESAMPLES};
use super::paired::sign_test_p_value;
use rand::{Rng, RngExt};
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};
use statrs::function::factorial::ln_binomial;

/// A difference a − b of one measure between two designs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Difference {
    /// The measure of A.
    pub a: f64,
    /// The measure of B.
    pub b: f64,
    /// a − b.
    pub difference: f64,
    /// Interval of the difference at the requested level.
    pub interval: (f64, f64),
    /// Two-sided p-value of "no difference"; in (0, 1], never 0.
    pub p_value: f64,
    /// Which test: "paired_t", "bootstrap_paired", "bootstrap",
    /// "bootstrap_se_paired", "bootstrap_se", "mcnemar", "two_proportion",
    /// or "point" where no spread was measured.
    pub test: &'static str,
    /// The size the smallest difference worth reporting is a share of:
    /// max(|a|, |b|) unless the measure sets another (a restricted mean
    /// takes its settled runs' times, which no horizon moves).
    pub scale: f64,
}

fn check_level(level: f64) {
    assert!(level > 0.0 && level < 1.0, "level must lie in (0, 1)");
}

/// The smallest positive p-value kept: a p-value that underflows is stored
/// as this upper bound, never as 0.
pub const P_FLOOR: f64 = f64::MIN_POSITIVE;

/// The smallest two-sided p-value an exact test can attain: a sign-flip
/// test on `n` pairs when `paired`, else a permutation test of samples of
/// sizes `n` and `m`.
pub fn exact_floor(n: usize, m: usize, paired: bool) -> f64 {
    let log = if paired {
        -((n.max(1) - 1) as f64) * std::f64::consts::LN_2
    } else {
        std::f64::consts::LN_2 - ln_binomial((n + m) as u64, n as u64)
    };
    log.exp().min(1.0)
}

/// A p-value clamped into [`P_FLOOR`], 1].
pub fn honest_p(p: f64) -> f64 {
    if p.is_nan() {
        1.0
    } else {
        p.clamp(P_FLOOR, 1.0)
    }
}

/// Paired t-test of mean(a − b) = 0, with its t interval. None with fewer
/// than two pairs, lengths that differ or a value that is not finite.
pub fn paired_mean_difference(a: &[f64], b: &[f64], level: f64) -> Option<Difference> {
    check_level(level);
    let n = a.len();
    if n != b.len() || n < 2 || !a.iter().chain(b).all(|x| x.is_finite()) {
        return None;
    }
    let nf = n as f64;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / nf;
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let dm = mean(&d);
    let var = d.iter().map(|x| (x - dm).powi(2)).sum::<f64>() / (nf - 1.0);
    let se = (var / nf).sqrt();
    let t = StudentsT::new(0.0, 1.0, nf - 1.0).ok()?;
    let q = t.inverse_cdf(0.5 + level / 2.0);
    let p = if se == 0.0 {
        if dm == 0.0 { 1.0 } else { 0.0 }
    } else {
        2.0 * t.sf((dm / se).abs())
    };
    let p = p.max(exact_floor(n, n, true));
    let (ma, mb) = (mean(a), mean(b));
    Some(Difference {
        a: ma,
        b: mb,
        scale: ma.abs().max(mb.abs()),
        difference: dm,
        interval: (dm - q * se, dm + q * se),
        p_value: honest_p(p),
        test: "paired_t",
    })
}

/// The q-quantile (linear interpolation) of `values`, reordering them.
fn quantile_in_place(values: &mut [f64], q: f64) -> f64 {
    let h = q * (values.len() - 1) as f64;
    let lo = h.floor() as usize;
    let (_, x_lo, rest) = values.select_nth_unstable_by(lo, f64::total_cmp);
    let x_lo = *x_lo;
    if h == lo as f64 || rest.is_empty() {
        return x_lo;
    }
    let x_hi = rest.iter().copied().fold(f64::INFINITY, f64::min);
    super::quantile::linear_between(x_lo, x_hi, h - lo as f64)
}

/// The q-quantile of a and of b and a percentile bootstrap of their
/// difference ([`bootstrap_difference`]). Values may be +∞ (a run that never
/// settled) as long as the quantiles of the data come out finite.
pub fn quantile_difference(
    a: &[f64],
    b: &[f64],
    q: f64,
    paired: bool,
    level: f64,
    rng: &mut impl Rng,
) -> Option<Difference> {
    quantile_difference_by(a, b, q, (paired, level), Resampling::Interval, rng)
}

/// How a quantile difference measures its spread.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Resampling {
    /// A percentile bootstrap of [`CI_RESAMPLES`] resamples: its interval
    /// and its p-value ([`quantile_difference`]).
    Interval,
    /// A normal interval and p-value from the bootstrap standard error over
    /// [`STD_ERROR_RESAMPLES`] resamples: a tenth of an interval's
    /// resampling, for callers that need a spread and not the tails (a
    /// race's look). The p-value keeps [`exact_floor`].
    StandardError,
    /// None: the point estimates alone (an unbounded interval, p = 1),
    /// drawing no randomness, for a caller that checks them before paying
    /// for a spread.
    PointOnly,
}

/// The q-quantile of a and of b and their difference, its spread measured
/// as `resampling` says, `paired` and at `level` as [`quantile_difference`].
pub fn quantile_difference_by(
    a: &[f64],
    b: &[f64],
    q: f64,
    (paired, level): (bool, f64),
    resampling: Resampling,
    rng: &mut impl Rng,
) -> Option<Difference> {
    let at = |v: &mut [f64]| quantile_in_place(v, q);
    let (qa, qb) = statistics_of(a, b, &at, paired, level)?;
    let sizes = (a.len(), b.len());
    let resampler = || QuantileResampler::new(a, b, q, paired);
    Some(match resampling {
        Resampling::Interval => {
            let diffs = resampler().differences(CI_RESAMPLES, rng);
            percentile_difference((qa, qb), diffs, level, sizes, paired)
        }
        Resampling::StandardError => {
            let diffs = resampler().differences(STD_ERROR_RESAMPLES, rng);
            normal_difference((qa, qb), &diffs, level, sizes, paired)
        }
        Resampling::PointOnly => point_difference((qa, qb)),
    })
}

/// The difference qa − qb with a normal interval and p-value from the
/// standard deviation of the resampled `diffs`, never below
/// [`exact_floor`] for samples of `sizes`.
fn normal_difference(
    (qa, qb): (f64, f64),
    diffs: &[f64],
    level: f64,
    sizes: (usize, usize),
    paired: bool,
) -> Difference {
    let n = diffs.len() as f64;
    let mean = diffs.iter().sum::<f64>() / n;
    // A resample whose quantile is infinite leaves the spread unbounded.
    let se = (diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let se = if se.is_nan() { f64::INFINITY } else { se };
    let d = qa - qb;
    let normal = Normal::standard();
    let z = normal.inverse_cdf(0.5 + level / 2.0);
    let p = if se > 0.0 {
        2.0 * normal.cdf(-(d / se).abs())
    } else if d == 0.0 {
        1.0
    } else {
        0.0
    };
    Difference {
        a: qa,
        b: qb,
        scale: qa.abs().max(qb.abs()),
        difference: d,
        interval: (d - z * se, d + z * se),
        p_value: honest_p(p.max(exact_floor(sizes.0, sizes.1, paired))),
        test: if paired {
            "bootstrap_se_paired"
        } else {
            "bootstrap_se"
        },
    }
}

/// The mean of a and of b and their difference, with no spread measured
/// ([`Resampling::PointOnly`]).
pub fn mean_point_difference(a: &[f64], b: &[f64], level: f64) -> Option<Difference> {
    let mean = |v: &mut [f64]| v.iter().sum::<f64>() / v.len() as f64;
    statistics_of(a, b, &mean, false, level).map(point_difference)
}

/// qa − qb as a [`Difference`] whose spread was not measured.
fn point_difference((qa, qb): (f64, f64)) -> Difference {
    Difference {
        a: qa,
        b: qb,
        scale: qa.abs().max(qb.abs()),
        difference: qa - qb,
        interval: (f64::NEG_INFINITY, f64::INFINITY),
        p_value: 1.0,
        test: "point",
    }
}

/// The mean of a and of b and a percentile bootstrap of their difference
/// (for samples that cannot be paired; paired ones take
/// [`paired_mean_difference`]).
pub fn mean_difference_bootstrap(
    a: &[f64],
    b: &[f64],
    level: f64,
    rng: &mut impl Rng,
) -> Option<Difference> {
    let mean = |v: &mut [f64]| v.iter().sum::<f64>() / v.len() as f64;
    bootstrap_difference(a, b, mean, false, level, rng)
}

/// `statistic` of a and of b and a percentile bootstrap of their difference
/// ([`CI_RESAMPLES`] resamples from `rng`): pairs resampled together when
/// `paired` (then the lengths must agree), each sample on its own otherwise.
/// An infinite difference in a resample counts on its side of 0. None for an
/// empty sample, a NaN, or a statistic of the data that is not finite.
pub fn bootstrap_difference(
    a: &[f64],
    b: &[f64],
    statistic: impl Fn(&mut [f64]) -> f64,
    paired: bool,
    level: f64,
    rng: &mut impl Rng,
) -> Option<Difference> {
    let (qa, qb) = statistics_of(a, b, &statistic, paired, level)?;
    let mut diffs = Vec::with_capacity(CI_RESAMPLES);
    let (mut ra, mut rb) = (vec![0.0; a.len()], vec![0.0; b.len()]);
    for _ in 0..CI_RESAMPLES {
        if paired {
            for k in 0..a.len() {
                let i = rng.random_range(0..a.len());
                ra[k] = a[i];
                rb[k] = b[i];
            }
        } else {
            for x in ra.iter_mut() {
                *x = a[rng.random_range(0..a.len())];
            }
            for x in rb.iter_mut() {
                *x = b[rng.random_range(0..b.len())];
            }
        }
        diffs.push(signed_difference(statistic(&mut ra), statistic(&mut rb)));
    }
    Some(percentile_difference(
        (qa, qb),
        diffs,
        level,
        (a.len(), b.len()),
        paired,
    ))
}

/// x − y, or ±∞ on the side of 0 where the infinite one puts it.
fn signed_difference(x: f64, y: f64) -> f64 {
    match (x.is_finite(), y.is_finite()) {
        (true, true) => x - y,
        _ if x == y => 0.0,
        _ if x > y => f64::INFINITY,
        _ => f64::NEG_INFINITY,
    }
}

/// The difference qa − qb with the percentile interval of the resampled
/// `diffs` (nearest rank) and their two-sided p-value, (k + 1)/(B + 1),
/// never below [`exact_floor`] for samples of `sizes`.
fn percentile_difference(
    (qa, qb): (f64, f64),
    mut diffs: Vec<f64>,
    level: f64,
    sizes: (usize, usize),
    paired: bool,
) -> Difference {
    diffs.sort_by(f64::total_cmp);
    let tail = (1.0 - level) / 2.0;
    let n = diffs.len();
    let lower = diffs[((tail * n as f64).floor() as usize).min(n - 1)];
    let upper = diffs[(((1.0 - tail) * n as f64).ceil() as usize).clamp(1, n) - 1];
    let below = diffs.iter().filter(|&&d| d <= 0.0).count();
    let above = diffs.iter().filter(|&&d| d >= 0.0).count();
    let p = (2.0 * (below.min(above) + 1) as f64 / (n + 1) as f64)
        .max(exact_floor(sizes.0, sizes.1, paired));
    Difference {
        a: qa,
        b: qb,
        scale: qa.abs().max(qb.abs()),
        difference: qa - qb,
        interval: (lower, upper),
        p_value: honest_p(p),
        test: if paired {
            "bootstrap_paired"
        } else {
            "bootstrap"
        },
    }
}

/// `statistic` of a and of b, both finite; None for an empty sample,
/// paired lengths that differ, or a NaN. Panics unless 0 < `level` < 1.
fn statistics_of(
    a: &[f64],
    b: &[f64],
    statistic: &impl Fn(&mut [f64]) -> f64,
    paired: bool,
    level: f64,
) -> Option<(f64, f64)> {
    check_level(level);
    if a.is_empty() || b.is_empty() || (paired && a.len() != b.len()) {
        return None;
    }
    if a.iter().chain(b).any(|x| x.is_nan()) {
        return None;
    }
    let (qa, qb) = (statistic(&mut a.to_vec()), statistic(&mut b.to_vec()));
    (qa.is_finite() && qb.is_finite()).then_some((qa, qb))
}

/// Bootstrap resamples of a q-quantile difference, each resample held as
/// how often it draws each value rather than as a copy: the quantile is
/// then read by walking the values' sorted order, with no selection per
/// resample. The draws from `rng` are those of [`bootstrap_difference`]
/// (n indices per resample, pairs together when paired), and a resample's
/// quantile is the same number, so the results are identical, several
/// times faster.
struct QuantileResampler<'v> {
    values: [&'v [f64]; 2],
    /// Each sample's indices in ascending order of value.
    order: [Vec<usize>; 2],
    /// Each value's place in its sample's `order`.
    rank: [Vec<usize>; 2],
    q: f64,
    paired: bool,
}

impl<'v> QuantileResampler<'v> {
    fn new(a: &'v [f64], b: &'v [f64], q: f64, paired: bool) -> Self {
        let sort = |v: &[f64]| {
            let mut order: Vec<usize> = (0..v.len()).collect();
            order.sort_by(|&i, &j| v[i].total_cmp(&v[j]));
            let mut rank = vec![0; v.len()];
            for (place, &i) in order.iter().enumerate() {
                rank[i] = place;
            }
            (order, rank)
        };
        let ((oa, ra), (ob, rb)) = (sort(a), sort(b));
        QuantileResampler {
            values: [a, b],
            order: [oa, ob],
            rank: [ra, rb],
            q,
            paired,
        }
    }

    /// `resamples` differences quantile(a*) − quantile(b*).
    fn differences(&self, resamples: usize, rng: &mut impl Rng) -> Vec<f64> {
        let [a, b] = self.values;
        let mut counts = [vec![0u32; a.len()], vec![0u32; b.len()]];
        let mut diffs = Vec::with_capacity(resamples);
        for _ in 0..resamples {
            counts.iter_mut().for_each(|c| c.fill(0));
            if self.paired {
                for _ in 0..a.len() {
                    let i = rng.random_range(0..a.len());
                    counts[0][self.rank[0][i]] += 1;
                    counts[1][self.rank[1][i]] += 1;
                }
            } else {
                for s in 0..2 {
                    for _ in 0..self.values[s].len() {
                        let i = rng.random_range(0..self.values[s].len());
                        counts[s][self.rank[s][i]] += 1;
                    }
                }
            }
            let (x, y) = (self.quantile(0, &counts[0]), self.quantile(1, &counts[1]));
            diffs.push(signed_difference(x, y));
        }
        diffs
    }

    /// The q-quantile (linear interpolation, as [`quantile_in_place`]) of
    /// the resample of sample `s` that draws its k-th smallest value
    /// `counts[k]` times.
    fn quantile(&self, s: usize, counts: &[u32]) -> f64 {
        let sorted = |k: usize| self.values[s][self.order[s][k]];
        let n = counts.len();
        let h = self.q * (n - 1) as f64;
        let lo = h.floor() as usize;
        // The resample's order statistics lo and lo + 1 (0-based).
        let (mut x_lo, mut x_hi) = (f64::NAN, f64::NAN);
        let mut seen = 0usize;
        for (k, &c) in counts.iter().enumerate() {
            seen += c as usize;
            if x_lo.is_nan() && seen > lo {
                x_lo = sorted(k);
            }
            if seen > lo + 1 {
                x_hi = sorted(k);
                break;
            }
        }
        if h == lo as f64 || x_hi.is_nan() {
            return x_lo;
        }
        super::quantile::linear_between(x_lo, x_hi, h - lo as f64)
    }
}

/// Shares of yes in a and in b, and their difference: McNemar's exact test
/// on paired outcomes (the discordant pairs under Binomial(·, ½)), or the
/// two-proportion z-test when not `paired`. None for an empty sample or
/// paired lengths that differ.
pub fn share_difference(a: &[bool], b: &[bool], paired: bool, level: f64) -> Option<Difference> {
    check_level(level);
    if a.is_empty() || b.is_empty() || (paired && a.len() != b.len()) {
        return None;
    }
    let share = |v: &[bool]| v.iter().filter(|&&x| x).count() as f64 / v.len() as f64;
    let (pa, pb) = (share(a), share(b));
    let z = Normal::standard().inverse_cdf(0.5 + level / 2.0);
    let d = pa - pb;
    let (se, p, test) = if paired {
        let n = a.len() as f64;
        let only_a = a.iter().zip(b).filter(|(x, y)| **x && !**y).count() as u64;
        let only_b = a.iter().zip(b).filter(|(x, y)| !**x && **y).count() as u64;
        let (n10, n01) = (only_a as f64, only_b as f64);
        let se = ((n10 + n01) - (n10 - n01).powi(2) / n).max(0.0).sqrt() / n;
        (se, sign_test_p_value(only_a, only_a + only_b), "mcnemar")
    } else {
        let (na, nb) = (a.len() as f64, b.len() as f64);
        let se = (pa * (1.0 - pa) / na + pb * (1.0 - pb) / nb).sqrt();
        let pooled = (pa * na + pb * nb) / (na + nb);
        let se0 = (pooled * (1.0 - pooled) * (1.0 / na + 1.0 / nb)).sqrt();
        let p = if se0 == 0.0 {
            1.0
        } else {
            2.0 * Normal::standard().sf((d / se0).abs())
        }
        .max(exact_floor(a.len(), b.len(), false));
        (se, p, "two_proportion")
    };
    Some(Difference {
        a: pa,
        b: pb,
        scale: pa.abs().max(pb.abs()),
        difference: d,
        interval: ((d - z * se).max(-1.0), (d + z * se).min(1.0)),
        p_value: honest_p(p),
        test,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Values with ties, an infinity and a spread, a and b correlated.
    fn tied_samples(n: usize) -> (Vec<f64>, Vec<f64>) {
        let a: Vec<f64> = (0..n)
            .map(|i| {
                if i % 17 == 3 {
                    f64::INFINITY
                } else {
                    ((i * 37) % 23) as f64
                }
            })
            .collect();
        let b: Vec<f64> = (0..n)
            .map(|i| ((i * 11) % 19) as f64 + 0.5 * (i % 3) as f64)
            .collect();
        (a, b)
    }

    #[test]
    fn quantile_resampling_by_counts_is_the_copying_bootstrap() {
        // The same draws give the same resample, so the same quantile and
        // the same interval and p-value, bit for bit, as selecting in a copy.
        let (a, b) = tied_samples(61);
        for (q, paired) in [
            (0.5, true),
            (0.9, true),
            (0.95, false),
            (0.25, false),
            (1.0, true),
        ] {
            let copy = |v: &mut [f64]| quantile_in_place(v, q);
            let mut r1 = Xoshiro256PlusPlus::seed_from_u64(11);
            let mut r2 = Xoshiro256PlusPlus::seed_from_u64(11);
            let by_counts = quantile_difference(
                &a,
                &b[..if paired { 61 } else { 40 }],
                q,
                paired,
                0.95,
                &mut r1,
            );
            let by_copy = bootstrap_difference(
                &a,
                &b[..if paired { 61 } else { 40 }],
                copy,
                paired,
                0.95,
                &mut r2,
            );
            assert_eq!(by_counts, by_copy, "q {q}, paired {paired}");
        }
    }

    #[test]
    fn a_looks_standard_error_agrees_with_the_percentile_interval() {
        // Normal-looking paired samples: the 200-resample standard error's
        // normal interval and the 2 000-resample percentile interval of the
        // p90 difference agree in width to within a fifth, and both hold
        // the same difference.
        let a: Vec<f64> = (0..400)
            .map(|i| 100.0 + ((i * 7919) % 400) as f64 / 10.0)
            .collect();
        let b: Vec<f64> = a
            .iter()
            .enumerate()
            .map(|(i, x)| x - 3.0 + ((i * 31) % 13) as f64 / 4.0)
            .collect();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let se = quantile_difference_by(
            &a,
            &b,
            0.9,
            (true, 0.95),
            Resampling::StandardError,
            &mut rng,
        )
        .unwrap();
        let full = quantile_difference(&a, &b, 0.9, true, 0.95, &mut rng).unwrap();
        assert_eq!(se.difference, full.difference);
        let (w_se, w_full) = (
            se.interval.1 - se.interval.0,
            full.interval.1 - full.interval.0,
        );
        assert!(
            (w_se / w_full - 1.0).abs() < 0.2,
            "widths {w_se} and {w_full}"
        );
        assert_eq!(se.test, "bootstrap_se_paired");
    }

    #[test]
    fn a_looks_standard_error_is_unbounded_when_a_resample_is() {
        // One run in three never settled: some resamples' p90 is infinite.
        let a: Vec<f64> = (0..30)
            .map(|i| if i % 3 == 0 { f64::INFINITY } else { i as f64 })
            .collect();
        let b: Vec<f64> = (0..30).map(|i| i as f64 + 1.0).collect();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let d = quantile_difference_by(
            &a,
            &b,
            0.5,
            (true, 0.95),
            Resampling::StandardError,
            &mut rng,
        )
        .unwrap();
        assert!(d.interval.0 == f64::NEG_INFINITY && d.interval.1 == f64::INFINITY);
        assert_eq!(d.p_value, 1.0);
    }

    #[test]
    fn paired_t_matches_scipy() {
        // b = 0.5, 1.0, …, 12; a = b + 1 + (1.5, −1.5, 0.5) repeated.
        // scipy.stats.ttest_rel(a, b) of SciPy 1.17: p = 0.00016758545582512964,
        // 95 % interval (0.6286850194031272, 1.7046483139302064).
        let b: Vec<f64> = (1..=24).map(|i| 0.5 * f64::from(i)).collect();
        let a: Vec<f64> = b
            .iter()
            .enumerate()
            .map(|(i, x)| x + 1.0 + [1.5, -1.5, 0.5][i % 3])
            .collect();
        let d = paired_mean_difference(&a, &b, 0.95).unwrap();
        assert!(
            (d.p_value / 0.000_167_585_455_825_129_64 - 1.0).abs() < 1e-8,
            "{}",
            d.p_value
        );
        assert!((d.interval.0 - 0.628_685_019_403_127_2).abs() < 1e-9);
        assert!((d.interval.1 - 1.704_648_313_930_206_4).abs() < 1e-9);
        // With eight pairs the t-test's 0.00059 is below what 2⁸ sign
        // patterns allow: the p-value is the exact floor 2^(1−8).
        let few = paired_mean_difference(
            &[2.0, 4.0, 6.0, 8.0, 2.0, 4.0, 6.0, 8.0],
            &[1.0, 2.0, 3.0, 4.0, 1.0, 2.0, 3.0, 4.0],
            0.95,
        )
        .unwrap();
        assert!((few.p_value / (2.0 * 0.5f64.powi(8)) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn mcnemar_uses_only_discordant_pairs() {
        // 8 pairs where only A says yes, 1 where only B: binomtest(8, 9) p = 0.0390625.
        let mut a = vec![true; 8];
        let mut b = vec![false; 8];
        a.push(false);
        b.push(true);
        a.extend([true; 20]);
        b.extend([true; 20]);
        let d = share_difference(&a, &b, true, 0.95).unwrap();
        assert!((d.p_value - 0.039_062_5).abs() < 1e-12, "{}", d.p_value);
        assert!((d.difference - 7.0 / 29.0).abs() < 1e-12);
    }

    #[test]
    fn bootstrap_sees_a_shifted_tail_and_not_noise() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let base: Vec<f64> = (0..400).map(|i| f64::from(i % 40)).collect();
        let shifted: Vec<f64> = base.iter().map(|x| x + 10.0).collect();
        let d = quantile_difference(&shifted, &base, 0.9, true, 0.95, &mut rng).unwrap();
        assert!((d.difference - 10.0).abs() < 1e-12);
        assert!(d.p_value < 0.01 && d.interval.0 > 0.0);
        let same = quantile_difference(&base, &base, 0.9, true, 0.95, &mut rng).unwrap();
        assert_eq!(same.difference, 0.0);
        assert!(same.p_value > 0.5);
    }

    #[test]
    fn three_pairs_never_give_a_smaller_p_than_a_sign_flip_test_can() {
        // Three pairs, all one way by a constant 100 ± 0.01: the t statistic is
        // huge, but only 2³ sign patterns exist: p ≥ 2^(1−3) = 0.25.
        let a = [100.0, 100.01, 99.99];
        let b = [0.0, 0.0, 0.0];
        let t = paired_mean_difference(&a, &b, 0.95).unwrap();
        assert!((t.p_value - 0.25).abs() < 1e-15);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let q = quantile_difference(&a, &b, 0.9, true, 0.95, &mut rng).unwrap();
        assert!((q.p_value - 0.25).abs() < 1e-15);
        // Unpaired 3 and 3: 2/C(6, 3) = 0.1.
        let u = quantile_difference(&a, &b, 0.9, false, 0.95, &mut rng).unwrap();
        assert!((u.p_value - 0.1).abs() < 1e-12, "{}", u.p_value);
    }

    #[test]
    fn no_p_value_is_zero() {
        let a = vec![true; 3000];
        let b = vec![false; 3000];
        let d = share_difference(&a, &b, true, 0.95).unwrap();
        assert!(d.p_value > 0.0 && d.p_value <= 1e-300);
    }
}
