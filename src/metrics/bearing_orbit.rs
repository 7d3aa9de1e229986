//! The orbit each bearing describes at the end of a run, as a rig measures
//! it: the peak and the RMS of the bearing's radial displacement over one
//! revolution. Rigs report vibration at their bearings (the Bristol rig's
//! Ā_max is the mean of the peak radial displacements at its two bearings),
//! not at the balancer plane, so a comparison with a rig needs these.
//!
//! Measured by integrating one more revolution from the run's final state
//! with the run's own equations and method, sampled as the run's metrics
//! are: the run itself is not touched, and a run that ended early on a
//! certified hold gets an orbit it never integrated. The displacement is a
//! rotation of the rotor coordinates' pairs, so its radius is the same in
//! the inertial and the rotating frame.

use crate::integrate::{
    DenseOutput, Flow, Method, OdeSystem, SolverOptions, Status, Step, StepObserver, solve,
};
use crate::model::rotor::DofVec;
use crate::model::system::RotorSystem;
use std::f64::consts::PI;

/// Peak and RMS of one bearing's radial displacement over a revolution (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingOrbit {
    /// Largest radial displacement.
    pub peak: f64,
    /// Root mean square of the radial displacement.
    pub rms: f64,
}

/// Samples each bearing's radius at evenly spaced times.
struct OrbitSampler<'a> {
    maps: &'a [[DofVec; 2]],
    dof: usize,
    /// Start of the revolution, its length and its number of samples.
    t0: f64,
    rev: f64,
    samples: u32,
    /// The index (1..=samples) of the next sample.
    next: u32,
    q: Vec<f64>,
    peak: Vec<f64>,
    sum_sq: Vec<f64>,
    count: usize,
}

impl OrbitSampler<'_> {
    fn take(&mut self, dense: &dyn DenseOutput, t: f64) {
        dense.eval(t, &mut self.q);
        for (b, [gu, gv]) in self.maps.iter().enumerate() {
            let dot = |g: &DofVec| {
                g[..self.dof]
                    .iter()
                    .zip(&self.q)
                    .map(|(a, b)| a * b)
                    .sum::<f64>()
            };
            let r2 = dot(gu).powi(2) + dot(gv).powi(2);
            self.peak[b] = self.peak[b].max(r2.sqrt());
            self.sum_sq[b] += r2;
        }
        self.count += 1;
    }
}

impl StepObserver for OrbitSampler<'_> {
    fn step(&mut self, step: &Step<'_>) -> Flow {
        // Sample k at t0 + k/samples of a revolution, k = 1..=samples (the
        // last exactly at the end, which the final step reaches).
        while self.next <= self.samples {
            let at = if self.next == self.samples {
                self.t0 + self.rev
            } else {
                self.t0 + self.rev * f64::from(self.next) / f64::from(self.samples)
            };
            if at > step.t {
                break;
            }
            self.take(step.dense, at);
            self.next += 1;
        }
        Flow::Continue
    }
}

/// Each bearing's orbit over the revolution after `(t, y)`, integrating
/// `ode` (whose state has the layout of `system`) with `method`; `None`
/// when the rotor names no bearings or the revolution cannot be integrated.
#[allow(clippy::too_many_arguments)]
pub fn bearing_orbits<S: OdeSystem + ?Sized>(
    method: Method,
    ode: &S,
    system: &RotorSystem,
    t: f64,
    y: &[f64],
    omega: f64,
    samples_per_rev: u32,
    options: &SolverOptions,
) -> Option<Vec<BearingOrbit>> {
    let maps = system.rotor().bearing_maps();
    if maps.is_empty() || !y.iter().all(|v| v.is_finite()) {
        return None;
    }
    let rev = 2.0 * PI / omega;
    let samples = samples_per_rev.max(32);
    let dof = system.rotor().dof();
    let mut sampler = OrbitSampler {
        maps: &maps,
        dof,
        t0: t,
        rev,
        samples,
        next: 1,
        q: vec![0.0; dof],
        peak: vec![0.0; maps.len()],
        sum_sq: vec![0.0; maps.len()],
        count: 0,
    };
    let report = solve(method, ode, t, y, t + rev, options, &mut sampler);
    if matches!(report.status, Status::Failed(_)) || sampler.count == 0 {
        return None;
    }
    let n = sampler.count as f64;
    Some(
        sampler
            .peak
            .iter()
            .zip(&sampler.sum_sq)
            .map(|(&peak, &s)| BearingOrbit {
                peak,
                rms: (s / n).sqrt(),
            })
            .collect(),
    )
}
