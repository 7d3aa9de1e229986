//! Start-up whirl: a run's largest whirl `peak_r` over its A_ref (the
//! steady whirl of the same unbalance with the balancer locked, at the
//! operating speed).
//!
//! A balancer that settles well can still throw the rotor far out on the
//! way: clustered weights add their own unbalance until they spread, and a
//! run-up passes the critical speed. Nothing else in the summary looks at
//! that peak, so a design 33 times A_ref at start-up could be picked for
//! its settling time alone.
//!
//! The ratio is to A_ref at the operating speed, not to the no-balancer
//! peak of a run-up: passing a critical speed without a balancer can whirl
//! more than A_ref, so on a run-up this ratio overstates the peak against
//! "no balancer" by that factor (docs/metrics.md).

use super::{Outcome, RunMetrics};
use crate::stats::quantile::{Interpolation, quantile_sorted};

/// `peak_r / a_ref` of a run with this outcome, or `None` for a run that
/// records no whole peak: a failed or out-of-budget run (cut short), a
/// merged one, or an estimate, which takes no step (its `peak_r` is 0).
/// A non-finite ratio (a diverged run) counts as +∞.
pub fn peak_over_a_ref(outcome: Outcome, peak_r: f64, a_ref: f64) -> Option<f64> {
    let whole = matches!(
        outcome,
        Outcome::Settled | Outcome::Censored | Outcome::NotSettled | Outcome::Diverged
    );
    if !whole || peak_r == 0.0 || a_ref.is_nan() || a_ref <= 0.0 {
        return None;
    }
    let ratio = peak_r / a_ref;
    Some(if ratio.is_nan() { f64::INFINITY } else { ratio })
}

/// [`peak_over_a_ref`] of one run's metrics.
pub fn of_run(m: &RunMetrics) -> Option<f64> {
    peak_over_a_ref(m.outcome, m.peak_r, m.a_ref)
}

/// The median and the 95th percentile (linear interpolation) of runs'
/// ratios; `None` when no run has one.
pub fn median_and_p95(ratios: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = ratios.into_iter().collect();
    v.sort_by(f64::total_cmp);
    Some((
        quantile_sorted(&v, 0.5, Interpolation::Linear)?,
        quantile_sorted(&v, 0.95, Interpolation::Linear)?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_runs_with_a_whole_peak_count() {
        assert_eq!(peak_over_a_ref(Outcome::Settled, 3.0, 1.5), Some(2.0));
        assert_eq!(
            peak_over_a_ref(Outcome::Diverged, f64::NAN, 1.0),
            Some(f64::INFINITY)
        );
        assert_eq!(peak_over_a_ref(Outcome::NotSettled, 0.0, 1.0), None);
        assert_eq!(peak_over_a_ref(Outcome::SolverFailed, 3.0, 1.0), None);
        assert_eq!(peak_over_a_ref(Outcome::Settled, 3.0, 0.0), None);
    }

    #[test]
    fn median_and_p95_interpolate_between_runs() {
        let (median, p95) = median_and_p95([4.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!(median, 2.5);
        // 0.95 of the way through four order statistics: 85 % from 3 to 4.
        assert!((p95 - 3.85).abs() < 1e-12, "{p95}");
        assert_eq!(median_and_p95([]), None);
    }
}
