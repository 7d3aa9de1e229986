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

/// Peak and RMS of one place's radial displacement over a revolution (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// Largest radial displacement.
    pub peak: f64,
    /// Root mean square of the radial displacement.
    pub rms: f64,
}

/// One revolution integrated and sampled: the radius of every mapped place
/// at each sample, and where the revolution ended.
#[derive(Debug, Clone)]
pub struct Revolution {
    /// `radii[s][m]`: map m's radius at sample s (samples at the end of each
    /// 1/samples of the revolution).
    pub radii: Vec<Vec<f64>>,
    /// Time at the end of the revolution.
    pub t: f64,
    /// State at the end of the revolution.
    pub y: Vec<f64>,
}

impl Revolution {
    /// Peak and RMS of map m's radius over the revolution.
    pub fn orbit(&self, m: usize) -> Orbit {
        self.orbit_of(|r| r[m])
    }

    /// Peak and RMS over the revolution of a radius built from each sample's radii.
    pub fn orbit_of(&self, radius: impl Fn(&[f64]) -> f64) -> Orbit {
        let (mut peak, mut sum_sq) = (0.0f64, 0.0);
        for r in self.radii.iter().map(|s| radius(s)) {
            peak = peak.max(r);
            sum_sq += r * r;
        }
        Orbit {
            peak,
            rms: (sum_sq / self.radii.len().max(1) as f64).sqrt(),
        }
    }
}

/// Samples each map's radius at evenly spaced times.
struct Sampler<'a> {
    maps: &'a [[DofVec; 2]],
    dof: usize,
    /// Start of the revolution, its length and its number of samples.
    t0: f64,
    rev: f64,
    samples: u32,
    /// The index (1..=samples) of the next sample.
    next: u32,
    q: Vec<f64>,
    radii: Vec<Vec<f64>>,
}

impl Sampler<'_> {
    fn take(&mut self, dense: &dyn DenseOutput, t: f64) {
        dense.eval(t, &mut self.q);
        let q = &self.q;
        let dot = |g: &DofVec| g[..self.dof].iter().zip(q).map(|(a, b)| a * b).sum::<f64>();
        self.radii.push(
            self.maps
                .iter()
                .map(|[gu, gv]| dot(gu).hypot(dot(gv)))
                .collect(),
        );
    }
}

impl StepObserver for Sampler<'_> {
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

/// The revolution (2π/ω) after `(t, y)`, integrating `ode` (whose state has
/// the layout of `system`) with `method`, sampled `samples_per_rev` times
/// (at least 32) at the places `maps`; `None` when it cannot be integrated.
#[allow(clippy::too_many_arguments)]
pub fn integrate_revolution<S: OdeSystem + ?Sized>(
    method: Method,
    ode: &S,
    system: &RotorSystem,
    (t, y): (f64, &[f64]),
    omega: f64,
    samples_per_rev: u32,
    options: &SolverOptions,
    maps: &[[DofVec; 2]],
) -> Option<Revolution> {
    if !y.iter().all(|v| v.is_finite()) {
        return None;
    }
    let rev = 2.0 * PI / omega;
    let samples = samples_per_rev.max(32);
    let dof = system.rotor().dof();
    let mut sampler = Sampler {
        maps,
        dof,
        t0: t,
        rev,
        samples,
        next: 1,
        q: vec![0.0; dof],
        radii: Vec::with_capacity(samples as usize),
    };
    let report = solve(method, ode, t, y, t + rev, options, &mut sampler);
    if matches!(report.status, Status::Failed(_)) || sampler.radii.len() != samples as usize {
        return None;
    }
    Some(Revolution {
        radii: sampler.radii,
        t: report.t,
        y: report.y,
    })
}

/// Each bearing's orbit over the revolution after `(t, y)` (see
/// [`integrate_revolution`]); `None` when the rotor names no bearings or the
/// revolution cannot be integrated.
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
) -> Option<Vec<Orbit>> {
    let maps = system.rotor().bearing_maps();
    if maps.is_empty() {
        return None;
    }
    let revolution = integrate_revolution(
        method,
        ode,
        system,
        (t, y),
        omega,
        samples_per_rev,
        options,
        &maps,
    )?;
    Some((0..maps.len()).map(|m| revolution.orbit(m)).collect())
}
