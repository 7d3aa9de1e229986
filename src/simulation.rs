//! One run: a scene, its initial state, a solver and the metric definitions,
//! executed and measured. This is the executor for a single simulation; the
//! study runner fans many of them out over threads.

use crate::integrate::{Failure, Method, SolverOptions, Status, solve};
use crate::metrics::observer::{Series, SettlingObserver};
use crate::metrics::{MetricOptions, RunMetrics};
use crate::model::scene::{Scene, SceneError};
use crate::model::start::{StartMode, initial_state};
use crate::model::system::RotorSystem;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Integrator choice and accuracy.
///
/// `atol` is relative to the problem's scales: displacements get atol·A_ref,
/// velocities atol·A_ref·ω, angles atol (rad), angular rates atol·ω. The
/// settled amplitude sits at a noise floor of roughly 10–300 × the absolute
/// tolerance, so atol·A_ref must stay far below δ·A_ref: the default 1e-8
/// keeps the floor below 3e-6 A_ref, four decades under δ = 0.05.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSettings {
    /// Integration method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance relative to the problem's scales (see above).
    pub atol: f64,
    /// Step budget (accepted plus rejected).
    pub max_steps: u64,
    /// When an explicit method finds the problem stiff, runs out of steps or
    /// underflows its step size, re-run the whole simulation with Radau5 and
    /// record the switch (`method` becomes e.g. "dp5→radau5").
    pub implicit_fallback: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            method: Method::Dp5,
            rtol: 1e-6,
            atol: 1e-8,
            max_steps: 5_000_000,
            implicit_fallback: true,
        }
    }
}

/// Everything that defines one run.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// The physics.
    pub scene: Scene,
    /// How the run starts.
    pub start: StartMode,
    /// Initial cargo angles relative to the rotor (rad).
    pub initial_angles: Vec<f64>,
    /// Integrator settings.
    pub solver: SolverSettings,
    /// Metric definitions.
    pub metrics: MetricOptions,
}

/// The result of one run.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// Every metric.
    pub metrics: RunMetrics,
    /// The sampled time history, when requested.
    pub series: Option<Series>,
}

/// Per-component absolute tolerances for `system` (see [`SolverSettings`]).
pub fn scaled_atol(system: &RotorSystem, atol: f64, a_ref: f64, omega: f64) -> Vec<f64> {
    let lay = system.layout();
    let nq = lay.nq();
    let mut v = vec![atol; lay.dim()];
    for i in 0..lay.rotor_dof {
        v[i] = atol * a_ref;
        v[nq + i] = atol * a_ref * omega;
    }
    for i in lay.rotor_dof..nq {
        v[nq + i] = atol * omega;
    }
    v
}

impl Simulation {
    /// Build, integrate and measure the run; `record` keeps the sampled series.
    pub fn run(&self, record: bool) -> Result<RunResult, SceneError> {
        let system = self.scene.build()?;
        let n = system.cargo().len();
        if self.initial_angles.len() != n {
            return Err(SceneError::Invalid {
                field: "start.angles_deg".into(),
                value: format!("{} angles", self.initial_angles.len()),
                reason: format!("the balancer has {n} cargoes"),
            });
        }
        let omega = self.scene.speed.nominal_speed();
        let y0 = initial_state(&system, self.start, &self.initial_angles);
        let t_end = self.metrics.t_end_revs * 2.0 * PI / omega;
        let method = self.solver.method;
        let explicit = method != Method::Radau5;
        let attempt = |method: Method| {
            let mut observer = SettlingObserver::new(&system, omega, self.metrics.clone(), record);
            let options = SolverOptions {
                rtol: self.solver.rtol,
                atol: scaled_atol(&system, self.solver.atol, observer.a_ref(), omega),
                h0: None,
                h_max: f64::INFINITY,
                max_steps: self.solver.max_steps,
                detect_stiffness: explicit && self.solver.implicit_fallback,
            };
            let report = solve(method, &system, 0.0, &y0, t_end, &options, &mut observer);
            (report, observer)
        };
        let (report, observer) = attempt(method);
        let stalled = matches!(
            &report.status,
            Status::Failed(
                Failure::StiffnessDetected { .. }
                    | Failure::TooManySteps { .. }
                    | Failure::StepSizeUnderflow { .. }
            )
        );
        let (metrics, series) = if explicit && self.solver.implicit_fallback && stalled {
            let why = match &report.status {
                Status::Failed(f) => f.to_string(),
                _ => String::new(),
            };
            let (retry, observer) = attempt(Method::Radau5);
            let (mut metrics, series) = observer.finish(&retry);
            metrics.method = format!("{}→{}", method.name(), Method::Radau5.name());
            metrics.reason = format!("{} (switched to radau5: {why})", metrics.reason);
            metrics.steps += report.stats.steps;
            metrics.rhs_calls += report.stats.rhs_calls;
            (metrics, series)
        } else {
            let (mut metrics, series) = observer.finish(&report);
            metrics.method = method.name().to_string();
            (metrics, series)
        };
        Ok(RunResult { metrics, series })
    }
}

/// n angles evenly spaced around the race (a regular polygon: p = 0 and no net unbalance).
pub fn evenly_spaced(n: usize) -> Vec<f64> {
    (0..n).map(|j| 2.0 * PI * j as f64 / n as f64).collect()
}
