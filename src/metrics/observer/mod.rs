//! The step observer that measures a run: samples r and ε on dense output,
//! detects settling, watches for divergence, and optionally records a series.
//!
//! Its concerns live in files of their own, each an `impl` of the observer
//! or the types it holds, and a sample passes through them in a loop
//! ([`SettlingObserver::PARTS`]): `window` (the hold window, the holds and
//! the planes' watch), `twins` (identical weights that meet), `series` (the
//! recorded history), `repeats` (the never-settles watch), `tail` (the
//! certified tail on the tracked flow) and `finish` (metrics and outcome at
//! the end). This file keeps the state, the measurement of a sample and the
//! divergence test.

use super::certify::{BOUND_SLACK, ERROR_GROWTH, HoldCertifier, MARGIN, Tracked, residual_share};
use super::never_settles::{
    Criteria, FIRST_REVS, LAG, NeverSettles, RepeatWatch, Stroboscope, WINDOW,
};
use super::reference::{
    a_ref, balancing_error, plane_a_refs, plane_balancing_errors, reference_unbalance, vibration,
};
use super::{MetricOptions, Outcome, RunMetrics};
use crate::design::transient::position_parameter;
use crate::integrate::{Events, Failure, Flow, OdeSystem, SolveReport, Status, Step, StepObserver};
use crate::model::gap::{ClosestApproach, GapGauge};
use crate::model::start::is_plane_translation;
use crate::model::system::RotorSystem;
use crate::model::unbalance::{BalancingGauge, BandCheck, BandDecider, planar_norm};
use std::f64::consts::PI;

mod finish;
mod repeats;
mod series;
mod tail;
mod twins;
mod window;

pub use series::Series;
use tail::{CONTACT_MARGIN, TailPlan};
use twins::{coincident_pair, identical_pairs};
use window::{Hold, SquareRing, inside};

/// Measures one run of a [`RotorSystem`]; see the definitions in [`super`].
pub struct SettlingObserver<'a> {
    system: &'a RotorSystem,
    options: MetricOptions,
    a_ref: f64,
    /// The whirl divergence is measured against: A_ref, or the larger whirl
    /// the weights' own unbalance can drive (U + Σ m l)/U · A_ref.
    divergence_scale: f64,
    u_ref: f64,
    balancing: BalancingGauge,
    /// Decides ε ≤ δ without computing ε where a bound settles it.
    eps_band: BandDecider,
    band: f64,
    window: f64,
    dt: f64,
    t0: f64,
    next_index: u64,
    scratch: Vec<f64>,
    ring: SquareRing,
    r_hold: Hold,
    eps_hold: Hold,
    peak_r: f64,
    gap: Option<GapGauge>,
    /// Whether r is the plane rotor's |(x, y)| (decided once, not per sample).
    plane: bool,
    /// The smallest gap between weights over the samples.
    closest: ClosestApproach,
    /// When the speed reaches its operating value, if known in advance.
    t_op: Option<f64>,
    /// The first sample at the operating speed (settling is judged from here).
    operating_since: Option<f64>,
    omega: f64,
    diverged: Option<String>,
    /// Pairs of weights with identical parameters in one plane (they can
    /// coincide and never part), and the reason once two did.
    twins: Vec<(usize, usize)>,
    /// The first pair that coincided, and when.
    merged: Option<(usize, usize, f64)>,
    series: Option<Series>,
    /// Each bearing's maps from rotor coordinates, when a series is recorded.
    bearing_maps: Vec<[crate::model::rotor::DofVec; 2]>,
    frame: Option<f64>,
    certifier: Option<HoldCertifier<'a>>,
    /// The integrated system's events (rigid contact), which decide whether
    /// a state is clear of touches and partings in place of the gaps.
    events: Option<&'a dyn Events>,
    /// How much the certified hold may move Σ r² over the window.
    residual_share: f64,
    /// The sample (t, state) at which a certified hold ended the run.
    certified: Option<(f64, Vec<f64>)>,
    /// The rest of the window as the tracked flow predicts it.
    plan: Option<TailPlan>,
    /// Per watched plane, for rotors with several: A_ref and r² over the window.
    planes: Option<PlaneWatch>,
    /// Watches the state once per revolution for a repeat outside the band.
    repeats: Option<RepeatWatch>,
    /// The sample index of the next revolution boundary the watch sees
    /// (the first [`FIRST_REVS`] revolutions in).
    next_watch: u64,
    /// The certificate that ended the run as never settling, the boundary
    /// time and the state there.
    never: Option<(NeverSettles, f64, Vec<f64>)>,
}

/// One step of the per-sample pipeline ([`SettlingObserver::PARTS`]).
type Part<'a> = fn(&mut SettlingObserver<'a>, &mut Sample) -> Flow;

/// What one sample measured, handed to each part in turn; the planes' part
/// adds its verdict for the whirl's hold.
struct Sample {
    t: f64,
    /// The whirl r.
    r: f64,
    /// ε, when it was computed rather than decided by a bound.
    eps: Option<f64>,
    /// ε ≤ δ.
    eps_inside: bool,
    /// At the operating speed.
    operating: bool,
    /// Every watched plane inside its band (true for a single plane).
    planes_inside: bool,
}

/// Each watched plane's A_ref, its whirl at the latest sample and r² over
/// the last hold window (rotors with several planes).
#[derive(Debug)]
struct PlaneWatch {
    a_ref: Vec<f64>,
    r: Vec<f64>,
    rings: Vec<SquareRing>,
    /// Each plane's "r ≤ δ·A_ref of the plane" hold: the run settles only
    /// when every plane has.
    holds: Vec<Hold>,
}

impl<'a> SettlingObserver<'a> {
    /// The state holds rotor-frame (u, v) turning at `omega`: r and ε are the
    /// same, the recorded (x, y) are turned back to the inertial frame.
    pub fn in_rotating_frame(mut self, omega: f64) -> Self {
        self.frame = Some(omega);
        self
    }

    /// The integrated system has `events`: rigid contact between the
    /// weights. They keep the weights apart (no two can coincide) and say
    /// whether a state is clear of touches and partings.
    pub fn with_events(mut self, events: &'a dyn Events) -> Self {
        self.events = Some(events);
        self.twins.clear();
        self
    }

    /// End the hold window early when the affine flow of `ode` (autonomous,
    /// the system's state layout), integrated at `rtol`, bounds its rest;
    /// see [`super::certify`].
    pub fn certify_with(mut self, ode: &'a dyn OdeSystem, rtol: f64) -> Self {
        self.residual_share = residual_share(rtol);
        let lay = self.system.layout();
        let positions: Vec<f64> = (0..lay.nq())
            .map(|i| if i < lay.rotor_dof { self.a_ref } else { 1.0 })
            .collect();
        let scale = positions
            .iter()
            .copied()
            .chain(positions.iter().map(|s| s * self.omega))
            .collect();
        let rev = 2.0 * PI / self.omega;
        self.certifier = Some(HoldCertifier::new(
            ode,
            scale,
            rev,
            self.dt,
            self.options.delta,
        ));
        self
    }

    /// End a run that will not settle once its state repeats every
    /// revolution, contracting, outside the band or below the operating
    /// speed (plane rotors, and rotors whose watched planes fix their whole
    /// position; see [`super::never_settles`]).
    pub fn certify_not_settled(mut self) -> Self {
        let whole = (self.options.t_end_revs - self.options.t_end_revs.round()).abs() < 1e-9;
        // The horizon must fall on a revolution boundary: the run's final
        // state is then the boundary state the watch saw.
        let watched = self.plane || (self.planes.is_some() && planes_fix_the_rotor(self.system));
        if watched && whole {
            self.repeats = Some(RepeatWatch::default());
        }
        self
    }

    /// An observer for `system` running at nominal speed `omega`.
    pub fn new(system: &'a RotorSystem, omega: f64, options: MetricOptions, record: bool) -> Self {
        let rev = 2.0 * PI / omega;
        let samples = options.samples_per_rev.max(32);
        let ring_len = ((options.hold_revs * f64::from(samples)).ceil() as usize).max(1);
        let a = a_ref(system, omega);
        // Divergence is judged against the whirl the start itself can throw:
        // with a tiny sampled unbalance A_ref is tiny, and the weights alone
        // (clustered, up to Σ m l out of balance) whirl the rotor up to
        // (U + Σ m l)/U times A_ref without anything diverging.
        let u = reference_unbalance(system);
        let weights: f64 = system.cargo().iter().map(|c| c.unbalance()).sum();
        let start_scale = if u > 0.0 { a * (u + weights) / u } else { a };
        // Only a recorded series reads the bearings.
        let bearing_maps = if record {
            system.rotor().bearing_maps()
        } else {
            Vec::new()
        };
        let balancing = BalancingGauge::new(system, reference_unbalance(system));
        SettlingObserver {
            system,
            a_ref: a,
            divergence_scale: a.max(start_scale),
            u_ref: u,
            eps_band: BandDecider::new(&balancing),
            balancing,
            band: options.delta * a,
            window: options.hold_revs * rev,
            dt: rev / f64::from(samples),
            t0: 0.0,
            next_index: 0,
            scratch: vec![0.0; crate::integrate::OdeSystem::dim(system)],
            ring: SquareRing::new(ring_len),
            r_hold: Hold::default(),
            eps_hold: Hold::default(),
            peak_r: 0.0,
            gap: GapGauge::new(system.cargo()),
            closest: ClosestApproach::default(),
            plane: is_plane_translation(system),
            t_op: system.speed().operating_time(),
            operating_since: None,
            omega,
            diverged: None,
            twins: identical_pairs(system.cargo(), system.effect_names().contains(&"contact")),
            merged: None,
            series: record.then(|| Series {
                psi: vec![Vec::new(); system.cargo().len()],
                bearing_x: vec![Vec::new(); bearing_maps.len()],
                bearing_y: vec![Vec::new(); bearing_maps.len()],
                ..Series::default()
            }),
            bearing_maps,
            frame: None,
            certifier: None,
            events: None,
            residual_share: 0.0,
            certified: None,
            plan: None,
            repeats: None,
            next_watch: FIRST_REVS * u64::from(samples),
            never: None,
            planes: (!is_plane_translation(system) && system.watch_maps().len() > 1).then(|| {
                let n = system.watch_maps().len();
                PlaneWatch {
                    a_ref: plane_a_refs(system, omega),
                    r: vec![0.0; n],
                    rings: vec![SquareRing::new(ring_len); n],
                    holds: vec![Hold::default(); n],
                }
            }),
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

    /// The state in inertial coordinates (the rotating frame integrates the
    /// plane rotor's (u, v): turn them and their rates back).
    fn inertial(&self, t: f64, y: &[f64]) -> Vec<f64> {
        let mut out = y.to_vec();
        if let Some(w) = self.frame {
            let nq = self.system.layout().nq();
            let (s, c) = (w * t).sin_cos();
            let (u, v, ud, vd) = (y[0], y[1], y[nq], y[nq + 1]);
            out[0] = u * c - v * s;
            out[1] = u * s + v * c;
            out[nq] = ud * c - vd * s - w * out[1];
            out[nq + 1] = ud * s + vd * c + w * out[0];
        }
        out
    }

    /// Process one sample: measure it, then hand it to each part in turn,
    /// in [`Self::PARTS`]' order, until one ends the run.
    fn sample(&mut self, t: f64) -> Flow {
        let mut sample = self.measure(t);
        for part in Self::PARTS {
            if part(self, &mut sample) == Flow::Stop {
                return Flow::Stop;
            }
        }
        Flow::Continue
    }

    /// The parts a sample passes through, as SciML's `CallbackSet` composes
    /// callbacks: each one concern, in its own file, reading what the parts
    /// before it wrote. The order is the measurement's: a diverged sample
    /// feeds no hold, the planes' verdict feeds the whirl's hold, and only a
    /// run that has not stopped is watched for repeats or certified.
    const PARTS: [Part<'a>; 8] = [
        Self::watch_divergence,
        Self::watch_twins,
        Self::watch_planes,
        Self::hold,
        Self::record,
        Self::stop_if_settled,
        Self::watch_repeats,
        Self::certify_tail,
    ];

    /// r, ε (or only whether ε ≤ δ) and the speed at sample time t.
    fn measure(&mut self, t: f64) -> Sample {
        let operating = self.at_operating_speed(t);
        let lay = self.system.layout();
        let y = &self.scratch;
        let r = self.whirl(y);
        let psi = &y[lay.head()..lay.nq()];
        // A recorded series keeps every ε; otherwise only ε ≤ δ matters.
        let check = if self.series.is_some() {
            BandCheck::Computed(self.balancing.error(self.system, psi))
        } else {
            self.eps_band
                .check(&self.balancing, self.system, psi, self.options.delta)
        };
        let (eps_inside, eps) = match check {
            BandCheck::Decided(inside) => (inside, None),
            BandCheck::Computed(eps) => (eps <= self.options.delta, Some(eps)),
        };
        Sample {
            t,
            r,
            eps,
            eps_inside,
            operating,
            planes_inside: true,
        }
    }

    /// A non-finite sample, or a whirl beyond what the unbalance and the
    /// weights can drive, ends the run as diverged; else the peak and the
    /// closest approach take the sample.
    fn watch_divergence(&mut self, s: &mut Sample) -> Flow {
        let (t, r) = (s.t, s.r);
        if !r.is_finite() || s.eps.is_some_and(|e| !e.is_finite()) {
            self.diverged = Some(format!("non-finite state at t = {t}"));
            return Flow::Stop;
        }
        self.peak_r = self.peak_r.max(r);
        if let Some(gauge) = &self.gap {
            let lay = self.system.layout();
            self.closest
                .sample(gauge, &self.scratch[lay.head()..lay.nq()]);
        }
        if r > self.options.divergence_factor * self.divergence_scale {
            self.diverged = Some(format!(
                "r = {r:.3e} m exceeded {} times the largest whirl the unbalance and the weights can drive ({:.3e} m) at t = {t:.4}",
                self.options.divergence_factor, self.divergence_scale
            ));
            return Flow::Stop;
        }
        Flow::Continue
    }

    /// Samples per revolution.
    fn per_rev(&self) -> u64 {
        u64::from(self.options.samples_per_rev.max(32))
    }

    /// Whether no two weights are within [`CONTACT_MARGIN`] of touching (in
    /// contact or apart) at the latest sample.
    fn contacts_settled(&self) -> bool {
        if let Some(events) = self.events {
            let t = self.sample_time(self.next_index.saturating_sub(1));
            return events.clear(t, &self.scratch);
        }
        let psi = &self.scratch[self.system.layout().head()..self.system.layout().nq()];
        self.gap
            .as_ref()
            .is_none_or(|g| g.same_contacts(psi, psi, CONTACT_MARGIN))
    }

    /// The largest r over the last revolution of samples.
    fn recent_peak(&self) -> f64 {
        let per_rev = self.options.samples_per_rev.max(32) as usize;
        self.ring.latest_max(per_rev).sqrt()
    }

    /// r at positions q, as [`vibration`] computes it.
    fn whirl(&self, q: &[f64]) -> f64 {
        if self.plane {
            planar_norm(q[0], q[1])
        } else {
            vibration(self.system, q)
        }
    }

    /// Time of sample k.
    fn sample_time(&self, k: u64) -> f64 {
        self.t0 + k as f64 * self.dt
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
            // The certifier linearises at full states inside the band.
            let certifying = match (&self.certifier, self.r_hold.stretch_start) {
                (Some(c), Some(since)) => c.needs_full_state(t, since),
                _ => false,
            };
            let watching = self.repeats.is_some() && self.next_index == self.next_watch;
            let needed = if certifying
                || watching
                || (self.t_op.is_none() && self.operating_since.is_none())
            {
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

/// Whether the watched planes' displacements (u, v) determine every one of
/// the rotor's coordinates: the maps, stacked, have full column rank. Only
/// then does a repeat of the planes' states mean a repeat of the rotor's.
fn planes_fix_the_rotor(system: &RotorSystem) -> bool {
    let k = system.rotor().dof();
    let mut rows: Vec<Vec<f64>> = system
        .watch_maps()
        .iter()
        .flat_map(|[gu, gv]| [gu[..k].to_vec(), gv[..k].to_vec()])
        .collect();
    // Gaussian elimination with partial pivoting, relative to the largest
    // entry: a rank test on at most a few rows, not worth a crate.
    let scale = rows.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 {
        return false;
    }
    let mut rank = 0;
    for col in 0..k {
        let Some(pivot) = (rank..rows.len())
            .max_by(|&a, &b| rows[a][col].abs().total_cmp(&rows[b][col].abs()))
            .filter(|&r| rows[r][col].abs() > 1e-9 * scale)
        else {
            continue;
        };
        rows.swap(rank, pivot);
        for r in rank + 1..rows.len() {
            let f = rows[r][col] / rows[rank][col];
            for c in col..k {
                rows[r][c] -= f * rows[rank][c];
            }
        }
        rank += 1;
    }
    rank == k
}
