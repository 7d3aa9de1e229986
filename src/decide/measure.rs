//! A criterion measured on a design's runs, and two designs compared on it
//! with the test that fits it (docs/statistics.md, "Ranking criteria").
//! The criterion itself, as the study file states it, is the plan's
//! (`crate::study::plan::criterion`).

use crate::stats::paired::{
    Settling, SettlingComparison, compare_settling, compare_settling_by_ranks,
};
use crate::stats::paired_measures::{
    Difference, Resampling, honest_p, mean_difference_bootstrap, mean_point_difference,
    paired_mean_difference, quantile_difference_by, share_difference,
};
use crate::study::plan::criterion::{Criterion, Within};
use crate::study::results::measured_runs::{DesignRuns, Scale};
use rand::Rng;

impl Criterion {
    /// The design's value of this measure; `None` when it lies beyond the
    /// run (a median or p90 no run reached) or there are no runs.
    pub fn value(self, runs: &DesignRuns, scale: &Scale) -> Option<f64> {
        match self {
            Criterion::Median => runs.kaplan_meier()?.median(),
            Criterion::Mean => Some(runs.kaplan_meier()?.restricted_mean(scale.tau).estimate),
            // The Kaplan–Meier median's convention (R's quantile.survfit),
            // so that the table's median and p90 are read off one curve
            // (before 2026-12-07 the p90 interpolated the raw times).
            Criterion::P90 => runs.kaplan_meier()?.quantile(0.9),
            Criterion::ResidualP95 => quantile(
                &runs.residual.iter().flatten().copied().collect::<Vec<_>>(),
                0.95,
            ),
            _ => {
                let yes = self.outcomes(runs, scale);
                (!yes.is_empty())
                    .then(|| yes.iter().filter(|&&y| y).count() as f64 / yes.len() as f64)
            }
        }
    }

    /// Per run: yes when the run meets a share criterion.
    fn outcomes(self, runs: &DesignRuns, scale: &Scale) -> Vec<bool> {
        let settled_by = |limit: f64| -> Vec<bool> {
            runs.settling
                .iter()
                .map(|o| o.settled && o.time <= limit)
                .collect()
        };
        match self {
            Criterion::SettledFraction => runs.settling.iter().map(|o| o.settled).collect(),
            Criterion::SettledBy(Within::Revs(x)) => settled_by(x),
            Criterion::SettledBy(Within::Seconds(x)) => settled_by(x / scale.rev_seconds),
            Criterion::ResidualBelow(m) => runs
                .residual_abs
                .iter()
                .map(|r| r.is_some_and(|r| r <= m))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Design A against design B on this measure (A − B), paired when
    /// `paired` (the caller checked that they share samples), with the
    /// verdicts' full interval ([`Spread::Interval`]).
    pub fn compare(
        self,
        a: &DesignRuns,
        b: &DesignRuns,
        paired: bool,
        scale: &Scale,
        level: f64,
        rng: &mut impl Rng,
    ) -> Option<Difference> {
        self.compare_with(a, b, paired, scale, level, Spread::Interval, rng)
    }

    /// [`Criterion::compare`] with the interval `spread` asks for.
    #[allow(clippy::too_many_arguments)]
    pub fn compare_with<R: Rng>(
        self,
        a: &DesignRuns,
        b: &DesignRuns,
        paired: bool,
        scale: &Scale,
        level: f64,
        spread: Spread,
        rng: &mut R,
    ) -> Option<Difference> {
        let look = spread != Spread::Interval;
        let resampling = match spread {
            Spread::Interval => Resampling::Interval,
            Spread::Look => Resampling::StandardError,
            Spread::Point => Resampling::PointOnly,
        };
        let quantile = |x: &[f64], y: &[f64], q: f64, paired: bool, rng: &mut R| {
            quantile_difference_by(x, y, q, (paired, level), resampling, rng)
        };
        match self {
            Criterion::Median if paired => {
                let to = |d: &DesignRuns| -> Vec<Settling> {
                    d.settling
                        .iter()
                        .map(|o| Settling::new(o.time, o.settled))
                        .collect()
                };
                let c = if look {
                    compare_settling_by_ranks(&to(a), &to(b), level)?
                } else {
                    compare_settling(&to(a), &to(b), level, rng)?
                };
                let value = |d| self.value(d, scale).unwrap_or(f64::INFINITY);
                Some(sign_difference(&c, value(a), value(b)))
            }
            Criterion::Median => quantile(&uncapped_times(a), &uncapped_times(b), 0.5, false, rng),
            Criterion::Mean => {
                let (x, y) = (capped_times(a, scale.tau), capped_times(b, scale.tau));
                let d = match (paired, spread) {
                    (true, _) => paired_mean_difference(&x, &y, level),
                    (false, Spread::Point) => mean_point_difference(&x, &y, level),
                    (false, _) => mean_difference_bootstrap(&x, &y, level, rng),
                };
                d.map(|d| Difference {
                    scale: settled_scale(a, b).unwrap_or(d.scale),
                    ..d
                })
            }
            Criterion::P90 => quantile(
                &capped_times(a, scale.tau),
                &capped_times(b, scale.tau),
                0.9,
                paired,
                rng,
            ),
            Criterion::ResidualP95 => {
                let (x, y): (Vec<f64>, Vec<f64>) = if paired {
                    a.residual
                        .iter()
                        .zip(&b.residual)
                        .filter_map(|(x, y)| x.zip(*y))
                        .unzip()
                } else {
                    (
                        a.residual.iter().flatten().copied().collect(),
                        b.residual.iter().flatten().copied().collect(),
                    )
                };
                quantile(&x, &y, 0.95, paired, rng)
            }
            _ => share_difference(
                &self.outcomes(a, scale),
                &self.outcomes(b, scale),
                paired,
                level,
            ),
        }
    }
}

/// How a comparison measures the spread of its difference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spread {
    /// The verdicts' interval: percentile bootstraps of 2 000 resamples
    /// where a measure needs one, and their p-values.
    Interval,
    /// A race's look, which needs a difference's standard error and not
    /// its tails: the sign test's rank interval for the paired median, and
    /// a normal interval from a 200-resample standard error (normal
    /// p-value) for the other quantiles. Means and shares, and the paired
    /// median's p-value, are the same as with `Interval`.
    Look,
    /// The point estimates alone where a spread would need resampling (an
    /// unbounded interval, p = 1; `Look` elsewhere), drawing no
    /// randomness: what a look checks before paying for a spread.
    Point,
}

/// The paired median comparison as a [`Difference`]: the Kaplan–Meier
/// medians `a` and `b` (+∞ beyond the run), the median of t_A − t_B over
/// pairs with its interval, and the sign test's p-value.
pub fn sign_difference(c: &SettlingComparison, a: f64, b: f64) -> Difference {
    Difference {
        a,
        b,
        scale: a.abs().max(b.abs()),
        difference: -c.median_difference,
        interval: (
            -c.median_difference_interval.1,
            -c.median_difference_interval.0,
        ),
        p_value: honest_p(c.sign_test_p),
        test: "sign",
    }
}

/// The larger of two designs' mean settling times over their settled runs
/// (`None` when neither settled): the scale of a restricted mean's
/// difference, which the horizon does not move.
pub fn settled_scale(a: &DesignRuns, b: &DesignRuns) -> Option<f64> {
    let mean = |d: &DesignRuns| d.settled_mean();
    match (mean(a), mean(b)) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, y) => x.or(y),
    }
}

/// Settling times with a run that did not settle counted as τ.
fn capped_times(runs: &DesignRuns, tau: f64) -> Vec<f64> {
    runs.settling
        .iter()
        .map(|o| if o.settled { o.time.min(tau) } else { tau })
        .collect()
}

/// Settling times with a run that did not settle counted as +∞.
fn uncapped_times(runs: &DesignRuns) -> Vec<f64> {
    runs.settling
        .iter()
        .map(|o| if o.settled { o.time } else { f64::INFINITY })
        .collect()
}

/// The q-quantile by linear interpolation (polars's rule); +∞ values are
/// allowed and give +∞ when the quantile falls among them.
fn quantile(values: &[f64], q: f64) -> Option<f64> {
    crate::stats::quantile::quantile(values, q, crate::stats::quantile::Interpolation::Linear)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::survival::Observation;

    /// The p90 is read off the Kaplan–Meier curve by the median's
    /// convention: with ten runs settled at 1, 2, …, 10 rev the curve sits
    /// on 0.5 after 5 and on 0.1 after 9, so the median is 5.5 and the p90
    /// 9.5 (midpoints); interpolating the raw times gave a p90 of 9.1.
    #[test]
    fn the_p90_follows_the_medians_convention() {
        let runs = DesignRuns {
            design_id: 0,
            sample_ids: (0..10).collect(),
            settling: (1..=10)
                .map(|t| Observation {
                    time: f64::from(t),
                    settled: true,
                })
                .collect(),
            residual: vec![Some(0.01); 10],
            residual_abs: vec![Some(1e-6); 10],
        };
        let scale = Scale {
            tau: 100.0,
            rev_seconds: 0.01,
        };
        assert_eq!(Criterion::Median.value(&runs, &scale), Some(5.5));
        assert_eq!(Criterion::P90.value(&runs, &scale), Some(9.5));
        // Two runs of ten that never settled: the curve stays above 0.1.
        let mut late = runs.clone();
        for o in late.settling.iter_mut().skip(8) {
            o.settled = false;
        }
        assert_eq!(Criterion::P90.value(&late, &scale), None);
    }
}
