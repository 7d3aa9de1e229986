//! The fit: the unknowns that minimise the robust loss over the fitted
//! points, found by argmin's Nelder–Mead from several starts. The response
//! of a rig to its unknowns is steep and can have more than one valley, so
//! one start is not enough: each restart begins at one of the best prior
//! draws (already evaluated), and the best end wins.
//!
//! The simplex moves in the priors' probability coordinates u ∈ [0, 1]ᵏ
//! (each unknown through its prior's CDF), so a log-uniform coefficient is
//! searched in decades and every coordinate has the same scale. The
//! simplex itself is unbounded: a coordinate is folded back into [0, 1]
//! (a triangle wave), which keeps the loss continuous at the bounds.

use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::neldermead::NelderMead;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Size of the starting simplex along each coordinate (in u).
const START_STEP: f64 = 0.08;

/// Most passes of one restart (each a fresh simplex, 3.7 times smaller).
const MAX_PASSES: i32 = 4;

/// Spread of the simplex's values at which it stops (the loss is a sum of
/// squared standardised residuals: 1e-7 is far below any difference that
/// matters, so the budget, not this, ends a search that is still moving).
const SD_TOLERANCE: f64 = 1e-7;

/// One restart's end.
#[derive(Debug, Clone, PartialEq)]
pub struct Restart {
    /// Where it started (u).
    pub start: Vec<f64>,
    /// Where it ended (u).
    pub end: Vec<f64>,
    /// The loss there.
    pub loss: f64,
    /// Evaluations it used.
    pub evaluations: u64,
    /// Why it stopped.
    pub stop: String,
}

/// A coordinate folded into [0, 1].
pub fn fold(s: f64) -> f64 {
    let t = s.rem_euclid(2.0);
    if t <= 1.0 { t } else { 2.0 - t }
}

/// The loss as argmin's cost, counting evaluations.
struct Folded<'a, F> {
    loss: &'a F,
    evaluations: AtomicU64,
}

impl<F: Fn(&[f64]) -> f64> CostFunction for Folded<'_, F> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, s: &Self::Param) -> Result<f64, ArgminError> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let u: Vec<f64> = s.iter().map(|&x| fold(x)).collect();
        Ok((self.loss)(&u))
    }
}

/// Nelder–Mead on `loss` from each of `starts` (in parallel), each for at
/// most `budget` evaluations; the restarts in the order of `starts`.
pub fn restarts<F: Fn(&[f64]) -> f64 + Sync>(
    loss: &F,
    starts: &[Vec<f64>],
    budget: u64,
) -> Vec<Restart> {
    starts
        .par_iter()
        .map(|start| one_restart(loss, start, budget))
        .collect()
}

fn one_restart<F: Fn(&[f64]) -> f64>(loss: &F, start: &[f64], budget: u64) -> Restart {
    // A simplex can collapse onto points of equal loss short of the
    // minimum (its only stop rule is their spread): a converged pass is
    // checked by a fresh, smaller simplex at its end, until one finds
    // nothing better or the budget is spent.
    let (mut at, mut best, mut used) = (start.to_vec(), f64::INFINITY, 0u64);
    let mut stop = String::from("budget");
    for pass in 0..MAX_PASSES {
        // Not a power of two: a simplex symmetric about the minimum would stop again.
        let step = START_STEP / 3.7f64.powi(pass);
        let left = budget.saturating_sub(used);
        if left <= at.len() as u64 + 1 {
            break;
        }
        let (end, value, evaluations, why) = one_pass(loss, &at, step, left);
        used += evaluations;
        let improved = !best.is_finite() || value < best - 1e-9 * best.abs().max(1.0);
        if value < best {
            (at, best) = (end, value);
        }
        stop = why;
        if !improved || !stop.contains("converged") {
            break;
        }
    }
    Restart {
        start: start.to_vec(),
        end: at,
        loss: best,
        evaluations: used,
        stop,
    }
}

/// One Nelder–Mead pass from `start` with a simplex of `step`: where it
/// ended, the loss there, the evaluations used and why it stopped.
fn one_pass<F: Fn(&[f64]) -> f64>(
    loss: &F,
    start: &[f64],
    step: f64,
    budget: u64,
) -> (Vec<f64>, f64, u64, String) {
    let k = start.len();
    // Step inwards from the start so the simplex begins inside the cube.
    let simplex: Vec<Vec<f64>> = std::iter::once(start.to_vec())
        .chain((0..k).map(|j| {
            let mut v = start.to_vec();
            v[j] += if v[j] > 0.5 { -step } else { step };
            v
        }))
        .collect();
    let cost = Folded {
        loss,
        evaluations: AtomicU64::new(0),
    };
    // Each iteration evaluates about two points (a shrink: k).
    let iterations = (budget.saturating_sub(k as u64 + 1) / 2).max(1);
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(SD_TOLERANCE)
        .expect("a positive tolerance");
    match Executor::new(cost, solver)
        .configure(|s| s.max_iters(iterations))
        .run()
    {
        Ok(r) => {
            let state = r.state();
            let end: Vec<f64> = state
                .get_best_param()
                .map_or_else(|| start.to_vec(), |p| p.iter().map(|&x| fold(x)).collect());
            let why = state
                .get_termination_reason()
                .map_or("done".to_string(), |t| t.text().to_string());
            let used = r
                .problem
                .problem
                .as_ref()
                .map_or(0, |c| c.evaluations.load(Ordering::Relaxed));
            (end, state.get_best_cost(), used, why)
        }
        Err(e) => (start.to_vec(), loss(start), 1, format!("error: {e}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fold is continuous and maps every real into [0, 1].
    #[test]
    fn fold_is_a_triangle_wave() {
        for (s, u) in [
            (0.3, 0.3),
            (1.2, 0.8),
            (-0.25, 0.25),
            (2.5, 0.5),
            (1.0, 1.0),
        ] {
            assert!((fold(s) - u).abs() < 1e-12, "{s}");
        }
    }

    /// The restarts find the minimum of a curved (Rosenbrock-like) valley
    /// inside the cube, and the best of several starts wins where one start
    /// sits in the wrong basin of a two-well loss.
    #[test]
    fn restarts_find_the_valley_and_the_better_well() {
        let valley = |u: &[f64]| {
            let (x, y) = (u[0] * 2.0 - 0.5, u[1] * 2.0 - 0.5);
            (1.0 - x).powi(2) + 100.0 * (y - x * x).powi(2)
        };
        let ends = restarts(&valley, &[vec![0.1, 0.9], vec![0.5, 0.2]], 2000);
        let best = ends
            .iter()
            .min_by(|a, b| a.loss.total_cmp(&b.loss))
            .unwrap();
        assert!(
            (best.end[0] - 0.75).abs() < 1e-2 && (best.end[1] - 0.75).abs() < 1e-2,
            "{best:?}"
        );
        let wells =
            |u: &[f64]| ((u[0] - 0.2).powi(2) * 50.0).min(0.5 + (u[0] - 0.8).powi(2) * 50.0);
        let ends = restarts(&wells, &[vec![0.85], vec![0.25]], 200);
        assert!((ends[0].end[0] - 0.8).abs() < 1e-2, "{:?}", ends[0]);
        let best = ends
            .iter()
            .min_by(|a, b| a.loss.total_cmp(&b.loss))
            .unwrap();
        assert!((best.end[0] - 0.2).abs() < 1e-2, "{best:?}");
    }
}
