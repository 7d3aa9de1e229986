//! The series a run records: the sampled time history of the whirl, the
//! balancing error and the weights, and the part that records it.

use super::{Sample, SettlingObserver};
use crate::integrate::Flow;

/// A sampled time history: t, x, y, r, ε and every ψ_j.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Rotor coordinate x (shaft centre, or centre of mass on two supports).
    pub x: Vec<f64>,
    /// Rotor coordinate y.
    pub y: Vec<f64>,
    /// Vibration r (sqrt(x² + y²) for the plane rotor; see `reference::vibration`).
    pub r: Vec<f64>,
    /// Balancing error ε.
    pub eps: Vec<f64>,
    /// Cargo angles relative to the rotor, one vector per cargo (rad).
    pub psi: Vec<Vec<f64>>,
}

impl SettlingObserver<'_> {
    /// The part that appends the sample to the series, if one is recorded.
    pub(super) fn record(&mut self, s: &mut Sample) -> Flow {
        let Some(series) = &mut self.series else {
            return Flow::Continue;
        };
        let (t, y) = (s.t, &self.scratch);
        series.t.push(t);
        // The rotating frame integrates (u, v): report inertial (x, y).
        let (x, yy) = match self.frame {
            Some(w) => {
                let (sin, cos) = (w * t).sin_cos();
                (y[0] * cos - y[1] * sin, y[0] * sin + y[1] * cos)
            }
            None => (y[0], y[1]),
        };
        series.x.push(x);
        series.y.push(yy);
        series.r.push(s.r);
        series.eps.push(s.eps.unwrap_or(f64::NAN));
        let lay = self.system.layout();
        for (j, p) in y[lay.head()..lay.nq()].iter().enumerate() {
            series.psi[j].push(*p);
        }
        Flow::Continue
    }
}
