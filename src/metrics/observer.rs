//! The step observer that measures a run: samples r and ε on dense output,
//! detects settling, watches for divergence, and optionally records a series.

use super::reference::{a_ref, balancing_error, reference_unbalance, vibration};
use super::{MetricOptions, Outcome, RunMetrics};
use crate::design::transient::position_parameter;
use crate::integrate::{Failure, Flow, SolveReport, Status, Step, StepObserver};
use crate::model::gap::GapGauge;
use crate::model::system::RotorSystem;
use crate::model::unbalance::BalancingGauge;
use std::f64::consts::PI;

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

/// Tracks one "holds continuously" rule (r ≤ band or ε ≤ band).
#[derive(Debug, Clone, Copy, Default)]
struct Hold {
    stretch_start: Option<f64>,
    met_at: Option<f64>,
}

impl Hold {
    fn update(&mut self, t: f64, inside: bool, window: f64) {
        if self.met_at.is_some() {
            return;
        }
        if inside {
            let start = *self.stretch_start.get_or_insert(t);
            if t - start >= window {
                self.met_at = Some(start);
            }
        } else {
            self.stretch_start = None;
        }
    }

    /// t_s under the rule "for W revolutions or until the end", and whether the full window held.
    fn settling_time(&self) -> (Option<f64>, bool) {
        match self.met_at {
            Some(t) => (Some(t), true),
            None => (self.stretch_start, false),
        }
    }
}

/// Measures one run of a [`RotorSystem`]; see the definitions in [`super`].
pub struct SettlingObserver<'a> {
    system: &'a RotorSystem,
    options: MetricOptions,
    a_ref: f64,
    u_ref: f64,
    balancing: BalancingGauge,
    band: f64,
    window: f64,
    dt: f64,
    t0: f64,
    next_index: u64,
    scratch: Vec<f64>,
    ring: Vec<f64>,
    ring_pos: usize,
    ring_filled: usize,
    r_hold: Hold,
    eps_hold: Hold,
    peak_r: f64,
    gap: Option<GapGauge>,
    min_gap: f64,
    /// When the speed reaches its operating value, if known in advance.
    t_op: Option<f64>,
    /// The first sample at the operating speed (settling is judged from here).
    operating_since: Option<f64>,
    omega: f64,
    diverged: Option<String>,
    series: Option<Series>,
    frame: Option<f64>,
}

impl<'a> SettlingObserver<'a> {
    /// The state holds rotor-frame (u, v) turning at `omega`: r and ε are the
    /// same, the recorded (x, y) are turned back to the inertial frame.
    pub fn in_rotating_frame(mut self, omega: f64) -> Self {
        self.frame = Some(omega);
        self
    }

    /// An observer for `system` running at nominal speed `omega`.
    pub fn new(system: &'a RotorSystem, omega: f64, options: MetricOptions, record: bool) -> Self {
        let rev = 2.0 * PI / omega;
        let samples = options.samples_per_rev.max(32);
        let ring_len = ((options.hold_revs * f64::from(samples)).ceil() as usize).max(1);
        let a = a_ref(system, omega);
        SettlingObserver {
            system,
            a_ref: a,
            u_ref: reference_unbalance(system),
            balancing: BalancingGauge::new(system, reference_unbalance(system)),
            band: options.delta * a,
            window: options.hold_revs * rev,
            dt: rev / f64::from(samples),
            t0: 0.0,
            next_index: 0,
            scratch: vec![0.0; crate::integrate::OdeSystem::dim(system)],
            ring: vec![0.0; ring_len],
            ring_pos: 0,
            ring_filled: 0,
            r_hold: Hold::default(),
            eps_hold: Hold::default(),
            peak_r: 0.0,
            gap: GapGauge::new(system.cargo()),
            min_gap: f64::INFINITY,
            t_op: system.speed().operating_time(),
            operating_since: None,
            omega,
            diverged: None,
            series: record.then(|| Series {
                psi: vec![Vec::new(); system.cargo().len()],
                ..Series::default()
            }),
            frame: None,
            options,
        }
    }

    /// The reference amplitude A_ref of this run.
    pub fn a_ref(&self) -> f64 {
        self.a_ref
    }

    /// Whether the rotor runs at its operating speed at sample time t (the
    /// scratch state): after the ramp, or for a motor or free rotor once φ̇
    /// is within δ of the nominal speed. Once reached, it stays reached.
    fn at_operating_speed(&mut self, t: f64) -> bool {
        if self.operating_since.is_none() {
            let reached = match self.t_op {
                // Samples sit on a grid: allow for rounding in t = t0 + k·dt.
                Some(t_op) => t >= t_op - 1e-9 * self.dt,
                None => {
                    let (_, rate) = self.system.spin(t, &self.scratch);
                    (rate - self.omega).abs() <= self.options.delta * self.omega
                }
            };
            if reached {
                self.operating_since = Some(t);
            }
        }
        self.operating_since.is_some()
    }

    /// Process one sample; returns Stop when the run should end.
    fn sample(&mut self, t: f64) -> Flow {
        let operating = self.at_operating_speed(t);
        let lay = self.system.layout();
        let y = &self.scratch;
        let r = vibration(self.system, y);
        let psi = &y[lay.head()..lay.nq()];
        let eps = self.balancing.error(self.system, psi);
        if !r.is_finite() || !eps.is_finite() {
            self.diverged = Some(format!("non-finite state at t = {t}"));
            return Flow::Stop;
        }
        self.peak_r = self.peak_r.max(r);
        if let Some(gauge) = &self.gap {
            self.min_gap = self.min_gap.min(gauge.min_gap(psi));
        }
        if r > self.options.divergence_factor * self.a_ref {
            self.diverged = Some(format!(
                "r = {r:.3e} exceeded {} A_ref at t = {t:.4}",
                self.options.divergence_factor
            ));
            return Flow::Stop;
        }
        self.ring[self.ring_pos] = r * r;
        // A compare, not `%`: an integer division per sample is measurable.
        self.ring_pos += 1;
        if self.ring_pos == self.ring.len() {
            self.ring_pos = 0;
        }
        self.ring_filled = (self.ring_filled + 1).min(self.ring.len());
        self.r_hold
            .update(t, operating && r <= self.band, self.window);
        self.eps_hold
            .update(t, operating && eps <= self.options.delta, self.window);
        if let Some(series) = &mut self.series {
            series.t.push(t);
            // The rotating frame integrates (u, v): report inertial (x, y).
            let (x, yy) = match self.frame {
                Some(w) => {
                    let (s, c) = (w * t).sin_cos();
                    (y[0] * c - y[1] * s, y[0] * s + y[1] * c)
                }
                None => (y[0], y[1]),
            };
            series.x.push(x);
            series.y.push(yy);
            series.r.push(r);
            series.eps.push(eps);
            for (j, p) in psi.iter().enumerate() {
                series.psi[j].push(*p);
            }
        }
        if self.options.stop_when_settled && self.r_hold.met_at.is_some() {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }

    /// Turn the observations and the solver's report into the run's metrics.
    pub fn finish(self, report: &SolveReport) -> (RunMetrics, Option<Series>) {
        let lay = self.system.layout();
        let psi = &report.y[lay.head()..lay.nq()];
        let rms = if self.ring_filled == 0 {
            0.0
        } else {
            let sum: f64 = if self.ring_filled == self.ring.len() {
                self.ring.iter().sum()
            } else {
                self.ring[..self.ring_filled].iter().sum()
            };
            (sum / self.ring_filled as f64).sqrt()
        };
        let (t_s, hold_complete) = self.r_hold.settling_time();
        let (t_eps, _) = self.eps_hold.settling_time();
        let rev = self.dt * f64::from(self.options.samples_per_rev.max(32));
        let (outcome, reason) = match (&self.diverged, &report.status) {
            (Some(why), _) => (Outcome::Diverged, why.clone()),
            (None, Status::Failed(Failure::NonFinite { t })) => {
                (Outcome::Diverged, format!("non-finite state at t = {t}"))
            }
            (
                None,
                Status::Failed(
                    f @ (Failure::TooManySteps { .. } | Failure::WallTimeExceeded { .. }),
                ),
            ) => (Outcome::BudgetExceeded, f.to_string()),
            (None, Status::Failed(f)) => (Outcome::SolverFailed, f.to_string()),
            (None, _) => match t_s {
                Some(t) if hold_complete => (
                    Outcome::Settled,
                    format!(
                        "r ≤ {} A_ref held for {} revolutions from t = {t:.4}",
                        self.options.delta, self.options.hold_revs
                    ),
                ),
                Some(t) => (
                    Outcome::Censored,
                    format!(
                        "censored: r ≤ {} A_ref from t = {t:.4} until the end of the run, shorter than the hold window of {} revolutions",
                        self.options.delta, self.options.hold_revs
                    ),
                ),
                None => (
                    Outcome::Censored,
                    match self.operating_since {
                        Some(_) => format!(
                            "censored: r/A_ref = {:.3} at the end (band {}), residual {:.3} A_ref",
                            vibration(self.system, &report.y) / self.a_ref,
                            self.options.delta,
                            rms / self.a_ref
                        ),
                        None => "censored: the speed never reached its operating value".to_string(),
                    },
                ),
            },
        };
        let settled = outcome == Outcome::Settled;
        let metrics = RunMetrics {
            settled,
            settling_time: if settled { t_s } else { None },
            settling_revs: if settled {
                t_s.map(|t| (t - self.t0) / rev)
            } else {
                None
            },
            settling_time_err: self.dt,
            settling_time_eps: t_eps,
            hold_complete: settled && hold_complete,
            residual_abs: rms,
            residual_rel: rms / self.a_ref,
            a_ref: self.a_ref,
            balancing_error: balancing_error(self.system, psi, self.u_ref),
            peak_r: self.peak_r,
            final_rel_angles_deg: psi
                .iter()
                .map(|p| p.to_degrees().rem_euclid(360.0))
                .collect(),
            p_final: position_parameter(psi),
            outcome,
            reason,
            t_final: report.t,
            steps: report.stats.steps,
            rhs_calls: report.stats.rhs_calls,
            method: String::new(),
            fidelity: String::new(),
            min_gap_rad: self.gap.as_ref().map(|_| self.min_gap),
            censoring_revs: (outcome == Outcome::Censored).then(|| {
                let t_op = self.operating_since.unwrap_or(report.t);
                ((report.t - self.window).max(t_op) - self.t0) / rev
            }),
            final_min_gap_rad: self.gap.as_ref().map(|g| g.min_gap(psi)),
            operating_time: self.operating_since,
            final_spin_rate: Some(self.system.spin(report.t, &report.y).1),
            balance_angle_error_deg: None,
        };
        (metrics, self.series)
    }
}

impl StepObserver for SettlingObserver<'_> {
    fn start(&mut self, t0: f64, y0: &[f64]) {
        self.t0 = t0;
        self.scratch.copy_from_slice(y0);
        self.next_index = 1;
        // The initial state is sample zero.
        let _ = self.sample(t0);
    }

    fn step(&mut self, step: &Step<'_>) -> Flow {
        loop {
            let t = self.t0 + self.next_index as f64 * self.dt;
            if t > step.t {
                return Flow::Continue;
            }
            // Samples read only positions, except a free rotor's spin rate
            // until it reaches its operating speed.
            let needed = if self.t_op.is_none() && self.operating_since.is_none() {
                self.scratch.len()
            } else {
                self.system.layout().nq()
            };
            step.dense.eval(t, &mut self.scratch[..needed]);
            self.next_index += 1;
            if self.sample(t) == Flow::Stop {
                return Flow::Stop;
            }
        }
    }
}
