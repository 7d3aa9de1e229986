//! How far a prediction lies from the measured points: each point's
//! standardised residual z = (model − measured)/sd, and a robust loss over
//! the fitted points, Σ ρ(z²) with the soft-L1 ρ(s) = 2(√(1+s) − 1)
//! (SciPy's `least_squares(loss="soft_l1")`). It is z² for small
//! residuals and grows as |z| for large ones, so one reading far off (a
//! feature no parameter in range reproduces) cannot drag the fit away from
//! the others. The same loss is the negative log-likelihood of the
//! approximate posterior (its weight is exp(−loss/2)), so the fit is the
//! posterior's mode in the priors' probability coordinates.

use super::problem::Prediction;
use super::rig_file::{Point, Use};

/// Loss of a prediction that failed: the worst any point could plausibly
/// add, so the simplex steps away from it, with no weight in the posterior.
pub const FAILED: f64 = 1e12;

/// The soft-L1 loss of one squared standardised residual.
pub fn soft_l1(z_squared: f64) -> f64 {
    2.0 * ((1.0 + z_squared).sqrt() - 1.0)
}

/// A point's standardised residual (model − measured)/sd.
pub fn z(point: &Point, value: f64, predicted: f64) -> f64 {
    (predicted - value) / point.sd
}

/// The loss over the fitted points of `predictions` against `measured`
/// (one value per point, in the rig file's order); [`FAILED`] when any
/// fitted point could not be predicted.
pub fn loss(points: &[Point], measured: &[f64], predictions: &[Prediction]) -> f64 {
    let mut total = 0.0;
    for ((p, &value), predicted) in points.iter().zip(measured).zip(predictions) {
        if p.role != Use::Fit {
            continue;
        }
        match predicted {
            Ok(x) if x.is_finite() => total += soft_l1(z(p, value, *x).powi(2)),
            _ => return FAILED,
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Near zero the loss is the squared residual; far out it grows linearly.
    #[test]
    fn soft_l1_is_quadratic_then_linear() {
        for z in [1e-3, 1e-2] {
            assert!((soft_l1(z * z) / (z * z) - 1.0).abs() < 1e-4);
        }
        let (a, b) = (soft_l1(1e6f64.powi(2)), soft_l1(2e6f64.powi(2)));
        assert!((b / a - 2.0).abs() < 1e-5, "{a} {b}");
    }
}
