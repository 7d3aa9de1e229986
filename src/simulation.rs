//! One run: a scene, its initial state, a solver and the metric definitions,
//! executed and measured. This is the executor for a single simulation; the
//! study runner fans many of them out over threads.

use crate::integrate::{Method, OdeSystem, SolverOptions, Stiffness, solve};
use crate::metrics::observer::{Series, SettlingObserver};
use crate::metrics::{MetricOptions, Outcome, RunMetrics};
use crate::model::frame::{RotatingSystem, rotating_frame_obstacle};
use crate::model::quasi_static::slow_mode;
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
    /// Formulation: analytic, rotating, full, or auto (rotating when exact for the scene).
    pub fidelity: Fidelity,
    /// Integration method: `auto` (dp5 in the inertial frame, radau5 in the
    /// rotating frame, whose fixed point only an A-stable method can step
    /// across in large steps), or `dp5`, `dop853`, `radau5`.
    pub method: MethodChoice,
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
            fidelity: Fidelity::Auto,
            method: MethodChoice::Auto,
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

/// The integrator a study asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MethodChoice {
    /// dp5 for the inertial frame, radau5 for the rotating frame.
    #[default]
    Auto,
    /// Dormand–Prince 5(4).
    Dp5,
    /// Dormand–Prince 8(5,3).
    Dop853,
    /// Radau IIA order 5.
    Radau5,
}

impl MethodChoice {
    /// The method for a run in the rotating (true) or inertial (false) frame.
    pub fn resolve(self, rotating: bool) -> Method {
        match self {
            MethodChoice::Auto if rotating => Method::Radau5,
            MethodChoice::Auto | MethodChoice::Dp5 => Method::Dp5,
            MethodChoice::Dop853 => Method::Dop853,
            MethodChoice::Radau5 => Method::Radau5,
        }
    }

    /// snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            MethodChoice::Auto => "auto",
            MethodChoice::Dp5 => "dp5",
            MethodChoice::Dop853 => "dop853",
            MethodChoice::Radau5 => "radau5",
        }
    }
}

/// Which formulation computes a run (the fidelity ladder, cheapest first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// Closed-form slow mode (quasi-static, `model::quasi_static`): microseconds,
    /// a settling estimate ln(1/δ)/|Re λ| and nothing else.
    Analytic,
    /// Eigenvalues of the linearisation about the balanced state
    /// (`model::linear`): stability and the slowest decay rate σ; a settling
    /// estimate ln((r₀/A_ref)/δ)/σ. Milliseconds.
    Linear,
    /// Exact equations in the rotor-fixed frame: autonomous for isotropic
    /// supports at constant speed without in-plane gravity.
    Rotating,
    /// Exact equations in the inertial frame: anything.
    Full,
    /// `rotating` when the scene allows it, `full` otherwise.
    #[default]
    Auto,
}

impl Fidelity {
    /// snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Analytic => "analytic",
            Fidelity::Linear => "linear",
            Fidelity::Rotating => "rotating",
            Fidelity::Full => "full",
            Fidelity::Auto => "auto",
        }
    }
}

impl Simulation {
    /// The fidelity this run uses (`auto` resolved against the scene).
    pub fn resolved_fidelity(&self) -> Fidelity {
        match self.solver.fidelity {
            Fidelity::Auto if rotating_frame_obstacle(&self.scene).is_none() => Fidelity::Rotating,
            Fidelity::Auto => Fidelity::Full,
            f => f,
        }
    }

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
        let fidelity = self.resolved_fidelity();
        let (mut metrics, series) = match fidelity {
            Fidelity::Analytic => (self.analytic(&system, omega), None),
            Fidelity::Linear => (self.linear(&system, &y0, omega), None),
            Fidelity::Rotating => {
                let rotating = RotatingSystem::new(&self.scene)?;
                let nq = system.layout().nq();
                let [u, ud, v, vd] = rotating.from_inertial(0.0, y0[0], y0[nq], y0[1], y0[nq + 1]);
                let mut z0 = y0.clone();
                (z0[0], z0[1], z0[nq], z0[nq + 1]) = (u, v, ud, vd);
                self.integrate(&rotating, &system, &z0, Some(omega), record)
            }
            Fidelity::Full | Fidelity::Auto => self.integrate(&system, &system, &y0, None, record),
        };
        metrics.fidelity = fidelity.name().to_string();
        Ok(RunResult { metrics, series })
    }

    /// Integrate `ode` (whose state has the layout of `system`), switching to
    /// Radau5 when an explicit method stalls; `frame` is ω for the rotating frame.
    fn integrate<S: OdeSystem>(
        &self,
        ode: &S,
        system: &RotorSystem,
        y0: &[f64],
        frame: Option<f64>,
        record: bool,
    ) -> (RunMetrics, Option<Series>) {
        let omega = self.scene.speed.nominal_speed();
        let t_end = self.metrics.t_end_revs * 2.0 * PI / omega;
        let method = self.solver.method.resolve(frame.is_some());
        let explicit = method != Method::Radau5;
        let mut observer = SettlingObserver::new(system, omega, self.metrics.clone(), record);
        if let Some(w) = frame {
            observer = observer.in_rotating_frame(w);
        }
        let options = SolverOptions {
            rtol: self.solver.rtol,
            atol: scaled_atol(system, self.solver.atol, observer.a_ref(), omega),
            h0: None,
            h_max: f64::INFINITY,
            max_steps: self.solver.max_steps,
            stiffness: if explicit && self.solver.implicit_fallback {
                Stiffness::SwitchToImplicit
            } else {
                Stiffness::Ignore
            },
        };
        let report = solve(method, ode, 0.0, y0, t_end, &options, &mut observer);
        let (mut metrics, series) = observer.finish(&report);
        metrics.method = method.name().to_string();
        if let Some(switch) = &report.switched {
            metrics.method = format!("{}→{}", switch.from.name(), Method::Radau5.name());
            metrics.reason = format!(
                "{} (switched to radau5 at t = {:.4}: {})",
                metrics.reason, switch.t, switch.why
            );
        }
        (metrics, series)
    }

    /// The linearised estimate: settled when the balanced state is stable,
    /// with t_s = ln((r₀/A_ref)/δ)/σ from the run's initial amplitude r₀.
    fn linear(&self, system: &RotorSystem, y0: &[f64], omega: f64) -> RunMetrics {
        let mut m = self.analytic_base(system, omega);
        m.method = "eigenvalues".into();
        match crate::model::linear::analyse(system, None) {
            Ok(report) if report.stable && report.slowest_decay > 0.0 => {
                let r0 = y0[0].hypot(y0[1]) / m.a_ref;
                let delta = self.metrics.delta;
                let t = (r0.max(delta) / delta).ln() / report.slowest_decay;
                let rev = 2.0 * PI / omega;
                RunMetrics {
                    settled: true,
                    settling_time: Some(t),
                    settling_revs: Some(t / rev),
                    hold_complete: true,
                    outcome: Outcome::Settled,
                    reason: format!(
                        "linear estimate ln((r0/A_ref)/δ)/σ with σ = {:.4e} 1/s ({} neutral directions set aside)",
                        report.slowest_decay, report.neutral
                    ),
                    ..m
                }
            }
            Ok(report) => RunMetrics {
                reason: format!(
                    "linear: the balanced state is unstable (σ = {:.3e} 1/s)",
                    report.slowest_decay
                ),
                ..m
            },
            Err(e) => RunMetrics {
                reason: format!("linear: {e}"),
                ..m
            },
        }
    }

    /// Metrics of a run that was not integrated (estimates fill in what they know).
    fn analytic_base(&self, system: &RotorSystem, omega: f64) -> RunMetrics {
        RunMetrics {
            settled: false,
            settling_time: None,
            settling_revs: None,
            settling_time_err: 0.0,
            settling_time_eps: None,
            hold_complete: false,
            residual_abs: 0.0,
            residual_rel: 0.0,
            a_ref: crate::metrics::reference::a_ref(system, omega),
            balancing_error: 0.0,
            peak_r: 0.0,
            final_rel_angles_deg: Vec::new(),
            p_final: 0.0,
            outcome: Outcome::NotSettled,
            reason: String::new(),
            t_final: 0.0,
            steps: 0,
            rhs_calls: 0,
            method: "closed_form".into(),
            fidelity: String::new(),
        }
    }

    /// The closed-form estimate: settled when the slow mode decays, with
    /// t_s = ln(1/δ)/|Re λ|; no residual, no steps.
    fn analytic(&self, system: &RotorSystem, omega: f64) -> RunMetrics {
        let rev = 2.0 * PI / omega;
        let base = self.analytic_base(system, omega);
        match slow_mode(&self.scene) {
            Ok(mode) if mode.decay_rate < 0.0 => {
                let t = (1.0 / self.metrics.delta).ln() / -mode.decay_rate;
                RunMetrics {
                    settled: true,
                    settling_time: Some(t),
                    settling_revs: Some(t / rev),
                    hold_complete: true,
                    p_final: mode.p,
                    outcome: Outcome::Settled,
                    reason: format!(
                        "analytic estimate ln(1/δ)/|Re λ| with λ = {:.4e} 1/s at p = {:.3}",
                        mode.decay_rate, mode.p
                    ),
                    ..base
                }
            }
            Ok(mode) => RunMetrics {
                p_final: mode.p,
                reason: format!(
                    "analytic: the slow mode does not decay (Re λ = {:.3e})",
                    mode.decay_rate
                ),
                ..base
            },
            Err(e) => RunMetrics {
                reason: format!("analytic: {e}"),
                ..base
            },
        }
    }
}

/// n angles evenly spaced around the race (a regular polygon: p = 0 and no net unbalance).
pub fn evenly_spaced(n: usize) -> Vec<f64> {
    (0..n).map(|j| 2.0 * PI * j as f64 / n as f64).collect()
}
