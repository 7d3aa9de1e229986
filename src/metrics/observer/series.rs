//! The series a run records: the sampled time history of the whirl, the
//! balancing error, the weights and the bearings, and the part that
//! records it.

use super::{Sample, SettlingObserver};
use crate::integrate::Flow;
use crate::model::rotor::DofVec;

/// A sampled time history: t, x, y, r, ε, every ψ_j and every bearing's x and y.
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
    /// Each bearing's displacement x (m), one vector per bearing in support
    /// order: rotors with bearings of their own (two supports), else none.
    pub bearing_x: Vec<Vec<f64>>,
    /// Each bearing's displacement y (m).
    pub bearing_y: Vec<Vec<f64>>,
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
        let turn = self.frame.map(|w| (w * t).sin_cos());
        let inertial = |u: f64, v: f64| match turn {
            Some((sin, cos)) => (u * cos - v * sin, u * sin + v * cos),
            None => (u, v),
        };
        let (x, yy) = inertial(y[0], y[1]);
        series.x.push(x);
        series.y.push(yy);
        series.r.push(s.r);
        series.eps.push(s.eps.unwrap_or(f64::NAN));
        let lay = self.system.layout();
        for (j, p) in y[lay.head()..lay.nq()].iter().enumerate() {
            series.psi[j].push(*p);
        }
        let dof = self.system.rotor().dof();
        let dot = |g: &DofVec| {
            g[..dof]
                .iter()
                .zip(y.iter())
                .map(|(a, b)| a * b)
                .sum::<f64>()
        };
        for (b, [gu, gv]) in self.bearing_maps.iter().enumerate() {
            let (bx, by) = inertial(dot(gu), dot(gv));
            series.bearing_x[b].push(bx);
            series.bearing_y[b].push(by);
        }
        Flow::Continue
    }
}
