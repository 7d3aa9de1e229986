//! Stepped speed sweeps that carry the state, as rigs are measured: the
//! speed is held at each step for a dwell, then stepped to the next, and
//! the run goes on from where the last step left the rotor and its weights,
//! up the speeds and (optionally) back down. Where the weights' end state
//! depends on where they came from, run-up and run-down differ: hysteresis.
//!
//! Each dwell is the scene at a constant speed, integrated in the inertial
//! frame (any rotor, any effect). The spin angle is carried across a step,
//! so the unbalance does not jump; the speed itself steps at once, and the
//! weights keep their speed relative to the race (carried along, as in oil
//! over a speed ramp much shorter than the dwell). The vibration is
//! measured over the last revolution of each dwell: the largest watched
//! plane's whirl and every bearing's orbit, peak and RMS, as a rig
//! measures the steady amplitude at each speed before stepping on.

use super::Simulation;
use crate::integrate::{Method, SolverOptions};
use crate::integrate::{NoObserver, Status, solve};
use crate::metrics::bearing_orbit::{Orbit, Revolution, integrate_revolution};
use crate::metrics::reference::{a_ref, balancing_error, reference_unbalance};
use crate::model::forced::{harmonic_response, plane_orbit_radius, unbalance_forcing};
use crate::model::rotor::DofVec;
use crate::model::scene::SceneError;
use crate::model::speed::SpeedLaw;
use crate::model::start::initial_state;
use crate::model::system::RotorSystem;
use polars::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// Which way the speed was going when a step was measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Run-up: the speed rises step by step.
    Up,
    /// Run-down: the speed falls step by step, from the top of the run-up.
    Down,
}

impl Direction {
    /// The name in output rows.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }
}

/// Whether a sweep over `speeds` (rad/s) holding each for `dwell` seconds
/// can be run: each dwell at least the revolution it measures, and the
/// whole sweep no more revolutions than any run may take
/// ([`crate::metrics::MAX_REVS`]): a day's dwell at millions of rpm is a
/// job that never ends, refused before it starts.
pub fn check_dwell(speeds: &[(Direction, f64)], dwell: f64) -> Result<(), SceneError> {
    let slowest = speeds.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
    let invalid = |reason: String| SceneError::Invalid {
        field: "dwell".into(),
        value: dwell.to_string(),
        reason,
    };
    if !(dwell.is_finite() && dwell * slowest >= 2.0 * PI) {
        return Err(invalid(format!(
            "each dwell must last at least one revolution, the one measured: {:.4} s at the slowest speed {slowest} rad/s",
            2.0 * PI / slowest
        )));
    }
    let revolutions: f64 = speeds.iter().map(|s| dwell * s.1 / (2.0 * PI)).sum();
    let most = crate::metrics::MAX_REVS;
    if revolutions > most {
        return Err(invalid(format!(
            "the sweep's {} dwells would turn the rotor {revolutions:.3e} revolutions, more than the {most:e} any run may take; shorten the dwell, narrow the speed range or take larger steps",
            speeds.len()
        )));
    }
    Ok(())
}

/// The speeds of a stepped sweep: from `lo` up to `hi` in steps of `step`
/// (both ends included; the last step shorter if need be) and, with
/// `down`, back to `lo` without repeating `hi`.
pub fn stepped_speeds(lo: f64, hi: f64, step: f64, down: bool) -> Vec<(Direction, f64)> {
    let count = ((hi - lo) / step - 1e-9).ceil().max(0.0) as usize;
    let mut up: Vec<f64> = (0..count).map(|i| lo + step * i as f64).collect();
    up.push(hi);
    let mut speeds: Vec<(Direction, f64)> = up.iter().map(|&w| (Direction::Up, w)).collect();
    if down {
        speeds.extend(up.iter().rev().skip(1).map(|&w| (Direction::Down, w)));
    }
    speeds
}

/// One step of a stepped sweep, measured over the last revolution of its dwell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepPoint {
    /// Run-up or run-down.
    pub direction: Direction,
    /// Speed ω of the step (rad/s).
    pub omega: f64,
    /// Peak over the revolution of r, the largest watched plane's whirl (m).
    pub whirl_peak: f64,
    /// RMS of r over the revolution (m).
    pub whirl_rms: f64,
    /// Peak radial displacement of each bearing (m; rotors with bearings).
    pub bearing_peak: Option<Vec<f64>>,
    /// RMS radial displacement of each bearing (m).
    pub bearing_rms: Option<Vec<f64>>,
    /// Each bearing's peak without the balancer's unbalance: the steady
    /// response to the rotor's own unbalance with the weights' mass but not
    /// their unbalance (A_ref's response, at the bearings), what a rig
    /// measures with its balls taken out (m).
    pub bearing_peak_without: Option<Vec<f64>>,
    /// Balancing error ε at the end of the dwell.
    pub balancing_error: f64,
    /// The weights' angles relative to the rotor at the end of the dwell (degrees).
    pub angles_deg: Vec<f64>,
}

/// Every sample a stepped sweep read, in time order: the windows at the
/// end of each dwell (what a rig's recorder keeps).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SweepSeries {
    /// The step's index in the sweep.
    pub step: Vec<u32>,
    /// Run-up or run-down.
    pub direction: Vec<Direction>,
    /// The step's speed (rad/s).
    pub omega: Vec<f64>,
    /// Time since the sweep began (s).
    pub t: Vec<f64>,
    /// The largest watched plane's radial displacement (m).
    pub whirl: Vec<f64>,
    /// Each bearing's radial displacement (m).
    pub bearings: Vec<Vec<f64>>,
}

impl SweepSeries {
    /// As a table: `step`, `direction`, `rpm`, `t`, `whirl` and `bearing_<b>` per bearing.
    pub fn to_dataframe(&self) -> PolarsResult<DataFrame> {
        let mut df = df!(
            "step" => self.step.clone(),
            "direction" => self.direction.iter().map(|d| d.name()).collect::<Vec<_>>(),
            "rpm" => self.omega.iter().map(|w| w * 30.0 / PI).collect::<Vec<f64>>(),
            "t" => self.t.clone(),
            "whirl" => self.whirl.clone(),
        )?;
        let bearings = self.bearings.first().map_or(0, Vec::len);
        for b in 0..bearings {
            let column: Vec<f64> = self.bearings.iter().map(|r| r[b]).collect();
            df.with_column(Column::new(format!("bearing_{b}").into(), column))?;
        }
        Ok(df)
    }
}

/// Why a stepped sweep could not go on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SteppedError {
    /// The scene or the settings are invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A dwell could not be integrated; the steps before it are kept.
    #[error("the solver stopped in the dwell at ω = {omega} rad/s: {why}")]
    Failed {
        /// The steps measured before it.
        done: Vec<StepPoint>,
        /// Speed of the dwell that failed.
        omega: f64,
        /// What the solver said.
        why: String,
    },
}

impl Simulation {
    /// Run the stepped sweep over `speeds` (rad/s, in order), holding each
    /// for `dwell` seconds, from this simulation's start at the first speed.
    pub fn stepped_sweep(
        &self,
        speeds: &[(Direction, f64)],
        dwell: f64,
    ) -> Result<Vec<StepPoint>, SteppedError> {
        self.stepped_sweep_windowed(speeds, dwell, None, None)
    }

    /// The stepped sweep with each step read over the last `window`
    /// seconds of its dwell (whole revolutions, at least one; `None`: one),
    /// as a rig reads its vibration over a time window; with `series`, every
    /// sample read is kept there, as a rig's recorder keeps them.
    pub fn stepped_sweep_windowed(
        &self,
        speeds: &[(Direction, f64)],
        dwell: f64,
        window: Option<f64>,
        mut series: Option<&mut SweepSeries>,
    ) -> Result<Vec<StepPoint>, SteppedError> {
        check_dwell(speeds, dwell)?;
        let mut points = Vec::with_capacity(speeds.len());
        let mut state: Option<Vec<f64>> = None;
        // The spin angle φ at the start of the next dwell (mod 2π).
        let mut phi = 0.0f64;
        for &(direction, omega) in speeds {
            let mut scene = self.scene.clone();
            scene.speed = SpeedLaw::Constant { omega };
            let system = scene.build()?;
            let y0 = match state.take() {
                Some(y) => y,
                None => initial_state(&system, self.start, &self.initial_angles),
            };
            // A constant speed law turns the rotor to φ = ω t: start the
            // dwell at the time whose angle is where the last one ended.
            let t0 = phi.rem_euclid(2.0 * PI) / omega;
            let rev = 2.0 * PI / omega;
            let method = self
                .solver
                .method
                .resolve(self.solver.rtol, scene.effects.stiff());
            let options =
                self.solver_options(&system, a_ref(&system, omega), omega, !method.is_implicit());
            let fail = |why: String, done: &[StepPoint]| SteppedError::Failed {
                done: done.to_vec(),
                omega,
                why,
            };
            // The revolutions read: the window's, whole, within the dwell.
            let read_revs = window.map_or(1.0, |w| (w / rev - 1e-9).ceil().max(1.0));
            let read_revs = read_revs.min((dwell / rev + 1e-9).floor().max(1.0));
            let settle_for = dwell - read_revs * rev;
            // Up to the revolutions read (none when the dwell is exactly them).
            let (t_settled, y_settled, measure_with) = if settle_for > 0.0 {
                let settle = solve(
                    method,
                    &system,
                    t0,
                    &y0,
                    t0 + settle_for,
                    &options,
                    &mut NoObserver,
                );
                if let Status::Failed(why) = &settle.status {
                    return Err(fail(why.to_string(), &points));
                }
                let ended_with = settle.ended_with(method);
                (settle.t, settle.y, ended_with)
            } else {
                (t0, y0, method)
            };
            let watch = system.watch_maps().to_vec();
            let bearings = system.rotor().bearing_maps();
            let maps: Vec<_> = watch.iter().chain(&bearings).copied().collect();
            let revolution = read_revolutions(
                (measure_with, &system, &options),
                (t_settled, &y_settled),
                omega,
                (read_revs as usize, self.metrics.samples_per_rev),
                &maps,
            )
            .ok_or_else(|| {
                let which = if read_revs > 1.0 { "a" } else { "the" };
                fail(format!("{which} measured revolution failed"), &points)
            })?;
            if let Some(series) = series.as_deref_mut() {
                // Time since the sweep began (each dwell's own clock starts
                // where its spin angle does); the revolutions are contiguous.
                let first = t_settled + dwell * points.len() as f64 - t0;
                let per_rev = revolution.radii.len() as f64 / read_revs;
                for (i, r) in revolution.radii.iter().enumerate() {
                    series.step.push(points.len() as u32);
                    series.direction.push(direction);
                    series.omega.push(omega);
                    series.t.push(first + rev * (i as f64 + 1.0) / per_rev);
                    series.whirl.push(largest(&r[..watch.len()]));
                    series.bearings.push(r[watch.len()..].to_vec());
                }
            }
            points.push(step_point(
                &system,
                (direction, omega),
                &revolution,
                watch.len(),
                &bearings,
            ));
            phi = omega * revolution.t;
            state = Some(revolution.y);
        }
        Ok(points)
    }
}

/// The largest of some radii (0 for none).
fn largest(radii: &[f64]) -> f64 {
    radii.iter().copied().fold(0.0, f64::max)
}

/// `count` contiguous revolutions after `(t, y)`, their samples in one
/// [`Revolution`] ending where the last does; `None` when one fails.
fn read_revolutions(
    (method, system, options): (Method, &RotorSystem, &SolverOptions),
    (t, y): (f64, &[f64]),
    omega: f64,
    (count, samples_per_rev): (usize, u32),
    maps: &[[DofVec; 2]],
) -> Option<Revolution> {
    let read = |t: f64, y: &[f64]| {
        integrate_revolution(
            method,
            system,
            system,
            (t, y),
            omega,
            samples_per_rev,
            options,
            maps,
        )
    };
    let mut all = read(t, y)?;
    for _ in 1..count {
        let next = read(all.t, &all.y)?;
        all.radii.extend(next.radii);
        (all.t, all.y) = (next.t, next.y);
    }
    Some(all)
}

/// What a step reads from its window: the whirl (the largest of the first
/// `watched` radii), each bearing's orbit and the same without the
/// balancer's unbalance, ε and the weights' angles at the window's end.
fn step_point(
    system: &RotorSystem,
    (direction, omega): (Direction, f64),
    revolution: &Revolution,
    watched: usize,
    bearings: &[[DofVec; 2]],
) -> StepPoint {
    let whirl = revolution.orbit_of(|r| largest(&r[..watched]));
    let orbits: Vec<Orbit> = (watched..watched + bearings.len())
        .map(|m| revolution.orbit(m))
        .collect();
    let lay = system.layout();
    let psi = &revolution.y[lay.head()..lay.nq()];
    StepPoint {
        direction,
        omega,
        whirl_peak: whirl.peak,
        whirl_rms: whirl.rms,
        bearing_peak: (!orbits.is_empty()).then(|| orbits.iter().map(|o| o.peak).collect()),
        bearing_rms: (!orbits.is_empty()).then(|| orbits.iter().map(|o| o.rms).collect()),
        bearing_peak_without: (!bearings.is_empty())
            .then(|| without_balancer(system, omega, bearings)),
        balancing_error: balancing_error(system, psi, reference_unbalance(system)),
        angles_deg: psi
            .iter()
            .map(|p| p.rem_euclid(2.0 * PI).to_degrees())
            .collect(),
    }
}

/// Peak orbit radius at each of `maps` in the steady response to the
/// rotor's own unbalance with the weights locked and their unbalance left
/// out; infinite at an undamped resonance.
fn without_balancer(system: &RotorSystem, omega: f64, maps: &[[DofVec; 2]]) -> Vec<f64> {
    let (fc, fs) = unbalance_forcing(system, &[], true);
    match harmonic_response(system, &fc, &fs, omega) {
        Some(h) => maps.iter().map(|m| plane_orbit_radius(&h, m)).collect(),
        None => vec![f64::INFINITY; maps.len()],
    }
}

/// The steps as a table, one row per step in sweep order.
pub fn to_dataframe(points: &[StepPoint]) -> PolarsResult<DataFrame> {
    let list = |name: &str, pick: fn(&StepPoint) -> Option<Vec<f64>>| {
        let rows: Vec<Series> = points
            .iter()
            .map(|p| Series::new(PlSmallStr::EMPTY, pick(p).unwrap_or_default()))
            .collect();
        Column::new(name.into(), rows)
    };
    let mut df = df!(
        "direction" => points.iter().map(|p| p.direction.name()).collect::<Vec<_>>(),
        "omega" => points.iter().map(|p| p.omega).collect::<Vec<f64>>(),
        "rpm" => points.iter().map(|p| p.omega * 30.0 / PI).collect::<Vec<f64>>(),
        "whirl_peak" => points.iter().map(|p| p.whirl_peak).collect::<Vec<f64>>(),
        "whirl_rms" => points.iter().map(|p| p.whirl_rms).collect::<Vec<f64>>(),
        "balancing_error" => points.iter().map(|p| p.balancing_error).collect::<Vec<f64>>(),
    )?;
    df.with_column(list("bearing_peak", |p| p.bearing_peak.clone()))?;
    df.with_column(list("bearing_rms", |p| p.bearing_rms.clone()))?;
    df.with_column(list("bearing_peak_without", |p| {
        p.bearing_peak_without.clone()
    }))?;
    df.with_column(list("angles_deg", |p| Some(p.angles_deg.clone())))?;
    Ok(df)
}
