//! One run: a scene, its initial state, a solver and the metric definitions,
//! built, integrated, observed and measured. This is the executor for a
//! single simulation; the study runner fans many of them out over threads.
//!
//! - [`settings`]: the solver settings a run asks for;
//! - [`estimate`]: the closed-form and linear rungs of the fidelity ladder;
//! - [`counterfactual`]: a run with one effect taken out.

pub mod counterfactual;
mod estimate;
pub mod settings;
pub mod stepped;

pub use settings::{Fidelity, MethodChoice, SolverSettings, scaled_atol};

use crate::integrate::{IMPLICIT_FALLBACK, OdeSystem, SolverOptions, Stiffness, solve};
use crate::metrics::bearing_orbit::bearing_orbits;
use crate::metrics::observer::{Series, SettlingObserver};
use crate::metrics::{MetricOptions, RunMetrics};
use crate::model::frame::{RotatingSystem, rotating_frame_obstacle};
use crate::model::scene::{Scene, SceneError};
use crate::model::start::{StartMode, initial_state};
use crate::model::system::RotorSystem;
use std::f64::consts::PI;

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
        /// Most samples a recorded series may hold (each a few f64 per weight).
        const MAX_SERIES_SAMPLES: f64 = 1e7;
        let system = self.scene.build()?;
        let n = system.cargo().len();
        if self.initial_angles.len() != n {
            return Err(SceneError::Invalid {
                field: "start.angles_deg".into(),
                value: format!("{} angles", self.initial_angles.len()),
                reason: format!("the balancer has {n} cargoes"),
            });
        }
        if let Some(bad) = self.initial_angles.iter().find(|a| !a.is_finite()) {
            return Err(SceneError::Invalid {
                field: "start.angles_deg".into(),
                value: bad.to_string(),
                reason: "every start angle must be a finite number of degrees".into(),
            });
        }
        // A recorded series keeps every sample of the run in memory.
        let samples = self.metrics.t_end_revs * f64::from(self.metrics.samples_per_rev);
        if record && samples > MAX_SERIES_SAMPLES {
            return Err(SceneError::Invalid {
                field: "metrics.t_end_revs".into(),
                value: self.metrics.t_end_revs.to_string(),
                reason: format!(
                    "a recorded series keeps every sample: t_end_revs × samples_per_rev = {samples:e}, more than {MAX_SERIES_SAMPLES:e}; shorten the run or sample less often"
                ),
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
                let (mut metrics, series) =
                    self.integrate(&rotating, &system, &z0, Some(omega), record);
                metrics.contact_model = rotating.contact_model();
                (metrics, series)
            }
            Fidelity::Full | Fidelity::Auto => {
                let (mut metrics, series) = self.integrate(&system, &system, &y0, None, record);
                metrics.contact_model = system.contact_model();
                (metrics, series)
            }
        };
        metrics.fidelity = fidelity.name().to_string();
        if self
            .scene
            .effects
            .rolling_resistance
            .as_ref()
            .is_some_and(|r| r.coefficient > 0.0)
            && !metrics.final_rel_angles_deg.is_empty()
        {
            metrics.balance_angle_error_deg =
                balance_angle_error(&self.scene, &metrics.final_rel_angles_deg);
        }
        Ok(RunResult { metrics, series })
    }

    /// The solver options of this simulation's runs of `system` at speed ω
    /// (absolute tolerances scaled by A_ref), for an explicit or implicit method.
    fn solver_options(
        &self,
        system: &RotorSystem,
        a_ref: f64,
        omega: f64,
        explicit: bool,
    ) -> SolverOptions {
        SolverOptions {
            rtol: self.solver.rtol,
            atol: scaled_atol(system, self.solver.atol(), a_ref, omega),
            h0: None,
            h_max: f64::INFINITY,
            max_steps: self.solver.max_steps,
            // Validated to a year at most; saturating all the same, so
            // that a settings value built in code cannot panic here.
            max_wall: Some(
                std::time::Duration::try_from_secs_f64(self.solver.max_wall_seconds)
                    .unwrap_or(std::time::Duration::from_secs(31_536_000)),
            ),
            reduce_second_order: !self.solver.full_newton,
            structured_newton: !self.solver.dense_newton,
            return_when_dearer: self.solver.return_when_dearer,
            stiffness: if explicit && self.solver.implicit_fallback {
                Stiffness::SwitchToImplicit
            } else {
                Stiffness::Ignore
            },
        }
    }

    /// Integrate `ode` (whose state has the layout of `system`), switching to
    /// Radau5 when an explicit method stalls; `frame` is ω for the rotating frame.
    fn integrate<'a, S: OdeSystem>(
        &self,
        ode: &'a S,
        system: &'a RotorSystem,
        y0: &[f64],
        frame: Option<f64>,
        record: bool,
    ) -> (RunMetrics, Option<Series>) {
        let omega = self.scene.speed.nominal_speed();
        let t_end = self.metrics.t_end_revs * 2.0 * PI / omega;
        let method = self.solver.method.resolve(
            self.solver.rtol,
            (frame.is_some() && !self.metrics.stop_when_settled) || self.scene.effects.stiff(),
        );
        let explicit = !method.is_implicit();
        let mut observer = SettlingObserver::new(system, omega, self.metrics.clone(), record);
        // A recorded series keeps every integrated sample.
        if self.metrics.certified_not_settled && !record {
            observer = observer.certify_not_settled();
        }
        if let Some(events) = ode.events() {
            observer = observer.with_events(events);
        }
        if let Some(w) = frame {
            observer = observer.in_rotating_frame(w);
            // A recorded series keeps every integrated sample.
            if self.metrics.certified_hold && self.metrics.stop_when_settled && !record {
                observer = observer.certify_with(ode, self.solver.rtol);
            }
        }
        let mut options = self.solver_options(system, observer.a_ref(), omega, explicit);
        // In the rotating frame a settling run tends to a fixed point, where
        // Radau5's steps grow without bound and the explicit method's stay at
        // its stability limit: Radau5's cost in a transient says nothing of
        // the rest (a return made the returned runs of paper_claims 4 times
        // dearer). In the inertial frame the settled state is an orbit at ω
        // whose steps are held by accuracy for both methods.
        options.return_when_dearer &= frame.is_none();
        let report = solve(method, ode, 0.0, y0, t_end, &options, &mut observer);
        let (mut metrics, series) = observer.finish(&report);
        if metrics.outcome.has_residual() {
            let continued = report.ended_with(method);
            let orbits = bearing_orbits(
                continued,
                ode,
                system,
                report.t,
                &report.y,
                omega,
                self.metrics.samples_per_rev,
                &options,
            );
            if let Some(orbits) = orbits {
                metrics.bearing_orbit_peak = Some(orbits.iter().map(|o| o.peak).collect());
                metrics.bearing_orbit_rms = Some(orbits.iter().map(|o| o.rms).collect());
            }
        }
        metrics.method = method.name().to_string();
        if let Some(switch) = &report.switched {
            metrics.method = format!("{}→{}", switch.from.name(), IMPLICIT_FALLBACK.name());
            metrics.reason = format!(
                "{} (switched to radau5 at t = {:.4}: {})",
                metrics.reason, switch.t, switch.why
            );
            if let Some(back) = &switch.back {
                let from = switch.from.name();
                metrics.method = format!("{}→{from}", metrics.method);
                metrics.reason = format!(
                    "{} (back to {from} at t = {:.4}: radau5 made {:.1} times its RHS calls per unit time)",
                    metrics.reason, back.t, back.ratio
                );
                if let Some(t) = back.stalled_at {
                    metrics.method = format!("{}→{}", metrics.method, IMPLICIT_FALLBACK.name());
                    metrics.reason = format!(
                        "{} (radau5 again at t = {t:.4}: {from} ran out of steps or step size)",
                        metrics.reason
                    );
                }
            }
        }
        (metrics, series)
    }
}

/// The largest angle (degrees) from the final cargo angles to the nearest
/// balanced state: the linear analysis' Newton iteration from them finds one
/// balanced state, which fixes each plane's correction unbalance T; the
/// nearest member of the whole balanced set {Σ c_j e^{iψ_j} = T} is then
/// found by [`crate::metrics::balance_angle`]. At rest the friction torque
/// vanishes, so the balanced states are those of the scene without it; it
/// is left out because its regularised sign has a slope that no
/// finite-difference Jacobian resolves. Gravity is left out too: in the
/// rotor's frame it turns once a revolution, so the weights swing about the
/// balanced state by about g/(l ω²) rather than move it, while the rotating
/// frame's steady state would take its value at one instant as a constant
/// load (41° of error reported for balls 0.1° from balance, before
/// 2026-11-27). `None` at variable speed or with no balanced state near.
fn balance_angle_error(scene: &Scene, final_deg: &[f64]) -> Option<f64> {
    let mut frictionless = scene.clone();
    frictionless.effects.rolling_resistance = None;
    frictionless.effects.gravity = None;
    let system = frictionless.build().ok()?;
    let frame = crate::model::linear::RotatingFrame::new(&system).ok()?;
    let psi: Vec<f64> = final_deg.iter().map(|d| d.to_radians()).collect();
    let state = crate::model::linear::steady_state(&frame, &psi).ok()?;
    let head = system.layout().head();
    let balanced = &state[head..head + psi.len()];
    let cargo = system.cargo();
    let planes = cargo.iter().map(|c| c.plane).max()? + 1;
    (0..planes)
        .filter_map(|p| {
            let members: Vec<usize> = (0..cargo.len()).filter(|&j| cargo[j].plane == p).collect();
            let c: Vec<f64> = members.iter().map(|&j| cargo[j].unbalance()).collect();
            let phi: Vec<f64> = members.iter().map(|&j| psi[j]).collect();
            let target: num_complex::Complex64 = members
                .iter()
                .map(|&j| num_complex::Complex64::from_polar(cargo[j].unbalance(), balanced[j]))
                .sum();
            let upper = members
                .iter()
                .map(|&j| crate::model::effect::contact::wrapped(psi[j] - balanced[j]).abs())
                .fold(0.0, f64::max);
            crate::metrics::balance_angle::nearest_balanced_angle(&c, &phi, target, upper)
        })
        .map(f64::to_degrees)
        .reduce(f64::max)
}

/// n angles evenly spaced around the race (a regular polygon: p = 0 and no net unbalance).
pub fn evenly_spaced(n: usize) -> Vec<f64> {
    (0..n).map(|j| 2.0 * PI * j as f64 / n as f64).collect()
}
