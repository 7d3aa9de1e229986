//! The step observer that measures a run: samples r and ε on dense output,
//! detects settling, watches for divergence, and optionally records a series.

use super::certify::{BOUND_SLACK, ERROR_GROWTH, HoldCertifier, MARGIN, Tracked, residual_share};
use super::never_settles::{
    Criteria, FIRST_REVS, LAG, NeverSettles, RepeatWatch, Stroboscope, WINDOW,
};
use super::reference::{
    a_ref, balancing_error, plane_a_refs, plane_balancing_errors, plane_whirls,
    reference_unbalance, vibration,
};
use super::{MetricOptions, Outcome, RunMetrics};
use crate::design::transient::position_parameter;
use crate::integrate::{Failure, Flow, OdeSystem, SolveReport, Status, Step, StepObserver};
use crate::model::gap::{ClosestApproach, GapGauge};
use crate::model::start::is_plane_translation;
use crate::model::system::RotorSystem;
use crate::model::unbalance::{BalancingGauge, BandCheck, BandDecider, planar_norm};
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

/// r² of the last hold window's samples, for the residual (an RMS).
#[derive(Debug, Clone)]
struct SquareRing {
    values: Vec<f64>,
    pos: usize,
    filled: usize,
}

impl SquareRing {
    fn new(len: usize) -> Self {
        SquareRing {
            values: vec![0.0; len],
            pos: 0,
            filled: 0,
        }
    }

    fn len(&self) -> usize {
        self.values.len()
    }

    fn push(&mut self, r2: f64) {
        self.values[self.pos] = r2;
        // A compare, not `%`: an integer division per sample is measurable.
        self.pos += 1;
        if self.pos == self.values.len() {
            self.pos = 0;
        }
        self.filled = (self.filled + 1).min(self.values.len());
    }

    /// Σ of the `count` most recent values (all there are, if fewer).
    fn latest_sum(&self, count: usize) -> f64 {
        let (older, newer) = self.latest(count);
        older.iter().chain(newer).sum()
    }

    /// The `count` most recent values (all there are, if fewer), as the
    /// older and the newer part of the storage.
    fn latest(&self, count: usize) -> (&[f64], &[f64]) {
        let count = count.min(self.filled);
        let newer = &self.values[self.pos.saturating_sub(count)..self.pos];
        let older_len = count - newer.len();
        let older = &self.values[self.values.len() - older_len..];
        (older, newer)
    }

    /// The largest of the `count` most recent values (0 when empty).
    fn latest_max(&self, count: usize) -> f64 {
        let (older, newer) = self.latest(count);
        older.iter().chain(newer).fold(0.0, |m, &v| f64::max(m, v))
    }

    /// sqrt of the mean, 0 when empty; sums in storage order, as always.
    fn rms(&self) -> f64 {
        if self.filled == 0 {
            return 0.0;
        }
        let sum: f64 = if self.filled == self.values.len() {
            self.values.iter().sum()
        } else {
            self.values[..self.filled].iter().sum()
        };
        (sum / self.filled as f64).sqrt()
    }
}

/// x ≤ limit, false for NaN: a prediction that is not a number bounds nothing.
fn inside(x: f64, limit: f64) -> bool {
    x <= limit
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
    frame: Option<f64>,
    certifier: Option<HoldCertifier<'a>>,
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

/// The samples first..=last of a hold window predicted on a tracked flow:
/// reused, from a later sample on, while the same flow keeps tracking.
#[derive(Debug)]
struct TailPlan {
    check: u32,
    first: u64,
    last: u64,
    r: Vec<f64>,
}

/// Every pair of weights must stay this far (rad) from the touching angle,
/// apart or in contact, for the flow to be linearised: beyond the central
/// differences' step in an angle, 1e-9 × max(1, |ψ|) (≤ 6.3e-9 within a
/// turn; for angles far beyond, the tracking check still guards).
const CONTACT_MARGIN: f64 = 2.5e-8;

/// After a prediction that fails (ε or the gaps), the next try comes this
/// many revolutions later.
const REPLAN_REVS: f64 = 3.0;

/// On the affine flow, ε and the gaps are checked on every this many samples
/// (they move slowly next to r, which is checked on every sample).
const TAIL_CHECK_STRIDE: usize = 4;

/// Tracking starts once r has stayed below this fraction of the band for a
/// revolution: deep enough inside for the linearisation to hold.
const READY_FRACTION: f64 = 0.2;

/// Pairs (i, j) of weights in the same plane with identical parameters:
/// the only ones whose states can become equal and then stay equal. With
/// contact on, weights of finite size never meet (the contact force keeps
/// them 2α apart), so they are left out and cost nothing per sample.
fn identical_pairs(cargo: &[crate::model::cargo::Cargo], contact: bool) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for i in 0..cargo.len() {
        for j in i + 1..cargo.len() {
            let (a, b) = (&cargo[i], &cargo[j]);
            if a.plane == b.plane
                && !(contact && a.radius > 0.0)
                && a.mass == b.mass
                && a.track_radius == b.track_radius
                && a.drag == b.drag
                && a.kappa == b.kappa
                && a.rolling_coupling == b.rolling_coupling
                && a.rolling_inertia == b.rolling_inertia
                && a.radius == b.radius
            {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

/// Two angles (or rates) this close are the same number to the last bits:
/// a few units in the last place of the larger.
fn same_to_the_last_bits(a: f64, b: f64) -> bool {
    (a - b).abs() <= 8.0 * f64::EPSILON * a.abs().max(b.abs()).max(1.0)
}

/// The first of `pairs` whose angles (mod 2π) and rates are equal to the
/// last bits in state y.
fn coincident_pair(
    pairs: &[(usize, usize)],
    lay: crate::model::system::Layout,
    y: &[f64],
) -> Option<(usize, usize)> {
    let (head, nq) = (lay.head(), lay.nq());
    pairs.iter().copied().find(|&(i, j)| {
        let (a, b) = (y[head + i], y[head + j]);
        let gap = crate::model::effect::contact::wrapped(a - b);
        same_to_the_last_bits(a, a - gap)
            && same_to_the_last_bits(y[nq + head + i], y[nq + head + j])
    })
}

impl<'a> SettlingObserver<'a> {
    /// The state holds rotor-frame (u, v) turning at `omega`: r and ε are the
    /// same, the recorded (x, y) are turned back to the inertial frame.
    pub fn in_rotating_frame(mut self, omega: f64) -> Self {
        self.frame = Some(omega);
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
    /// speed (plane rotors; see [`super::never_settles`]).
    pub fn certify_not_settled(mut self) -> Self {
        let whole = (self.options.t_end_revs - self.options.t_end_revs.round()).abs() < 1e-9;
        // The horizon must fall on a revolution boundary: the run's final
        // state is then the boundary state the watch saw.
        if self.plane && whole {
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
                ..Series::default()
            }),
            frame: None,
            certifier: None,
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

    /// The first pair of identical weights whose angles (mod 2π) and rates
    /// are equal to the last bits in the scratch state, if any.
    fn coincident(&self) -> Option<(usize, usize)> {
        coincident_pair(&self.twins, self.system.layout(), &self.scratch)
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

    /// The growth rate (1/s) of the antisymmetric mode of weights i and j at
    /// state y: δ = ψ_i − ψ_j obeys δ̈ = a δ + b δ̇ to first order, from
    /// central differences of the right-hand side; positive when the pair,
    /// once apart, would part further (real weights would separate).
    fn parting_rate(&self, t: f64, y: &[f64], i: usize, j: usize) -> f64 {
        let lay = self.system.layout();
        let (head, nq) = (lay.head(), lay.nq());
        let y0 = self.inertial(t, y);
        let response = |offset: usize, h: f64| {
            let mut plus = y0.clone();
            let mut minus = y0.clone();
            plus[offset + head + i] += h;
            plus[offset + head + j] -= h;
            minus[offset + head + i] -= h;
            minus[offset + head + j] += h;
            let (mut dp, mut dm) = (vec![0.0; y0.len()], vec![0.0; y0.len()]);
            crate::integrate::OdeSystem::rhs(self.system, t, &plus, &mut dp);
            crate::integrate::OdeSystem::rhs(self.system, t, &minus, &mut dm);
            let ddot = |d: &[f64]| d[nq + head + i] - d[nq + head + j];
            (ddot(&dp) - ddot(&dm)) / (4.0 * h)
        };
        let a = response(0, 1e-7);
        let b = response(nq, 1e-7 * self.omega.max(1.0));
        // Largest real part of the roots of λ² − b λ − a.
        let disc = b * b + 4.0 * a;
        if disc >= 0.0 {
            0.5 * (b + disc.sqrt())
        } else {
            0.5 * b
        }
    }

    /// Process one sample; returns Stop when the run should end.
    fn sample(&mut self, t: f64) -> Flow {
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
        if !r.is_finite() || eps.is_some_and(|e| !e.is_finite()) {
            self.diverged = Some(format!("non-finite state at t = {t}"));
            return Flow::Stop;
        }
        self.peak_r = self.peak_r.max(r);
        if let Some(gauge) = &self.gap {
            self.closest.sample(gauge, psi);
        }
        if r > self.options.divergence_factor * self.divergence_scale {
            self.diverged = Some(format!(
                "r = {r:.3e} m exceeded {} times the largest whirl the unbalance and the weights can drive ({:.3e} m) at t = {t:.4}",
                self.options.divergence_factor, self.divergence_scale
            ));
            return Flow::Stop;
        }
        if self.merged.is_none() {
            self.merged = self.coincident().map(|(i, j)| (i, j, t));
        }
        self.ring.push(r * r);
        let mut planes_inside = true;
        if let Some(pw) = &mut self.planes {
            plane_whirls(self.system, &self.scratch, &mut pw.r);
            for (((ring, r), hold), a_ref) in pw
                .rings
                .iter_mut()
                .zip(&pw.r)
                .zip(&mut pw.holds)
                .zip(&pw.a_ref)
            {
                ring.push(r * r);
                let inside = *r <= self.options.delta * a_ref;
                hold.update(t, operating && inside, self.window);
                planes_inside &= inside;
            }
        }
        self.r_hold
            .update(t, operating && r <= self.band && planes_inside, self.window);
        self.eps_hold
            .update(t, operating && eps_inside, self.window);
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
            series.eps.push(eps.unwrap_or(f64::NAN));
            for (j, p) in psi.iter().enumerate() {
                series.psi[j].push(*p);
            }
        }
        if self.options.stop_when_settled && self.r_hold.met_at.is_some() {
            return Flow::Stop;
        }
        // A run that settled (and goes on, `stop_when_settled = false`) has
        // its answer; identical weights that coincided end as `merged` or
        // not at all.
        // Revolution boundaries are counted, not computed: a compare per sample.
        let boundary = self.repeats.is_some() && self.next_index - 1 == self.next_watch;
        if boundary {
            self.next_watch += self.per_rev();
        }
        if boundary && self.r_hold.met_at.is_none() && self.merged.is_none() && self.watch_open(t) {
            let state = self.stroboscope(t);
            // The stroboscope's last entry is the spin rate over ω.
            let spin_ratio = state.smooth.last().copied().unwrap_or(1.0);
            let criteria = self.repeat_criteria(t, operating, spin_ratio);
            if let Some(watch) = &mut self.repeats
                && let Some(never) = watch.observe(state, criteria)
                && self.eps_at_horizon(t).is_some()
            {
                self.never = Some((never, t, self.scratch.clone()));
                return Flow::Stop;
            }
        }
        if self.certifier.is_none() {
            return Flow::Continue;
        }
        let Some(start) = self.r_hold.stretch_start else {
            return Flow::Continue;
        };
        // Linearising costs a Newton solve: only once r is deep inside the
        // band, and never with two weights within CONTACT_MARGIN of touching
        // (the kink of the contact law, where no linearisation holds).
        let wants = self
            .certifier
            .as_ref()
            .is_some_and(|c| c.wants_to_start(t, start));
        let ready =
            wants && self.recent_peak() <= READY_FRACTION * self.band && self.contacts_settled();
        if let Some(certifier) = &mut self.certifier
            && let Some(tracked) =
                certifier.observe(t, &self.scratch, r / self.a_ref, Some(start), ready)
        {
            return self.end_on_flow(&tracked);
        }
        Flow::Continue
    }

    /// Samples per revolution.
    fn per_rev(&self) -> u64 {
        u64::from(self.options.samples_per_rev.max(32))
    }

    /// Whether, at revolution boundary t, the horizon is more than a hold
    /// window away (a later hold could still complete before it).
    fn watch_open(&self, t: f64) -> bool {
        let rev = self.dt * self.per_rev() as f64;
        t + self.window < self.t0 + self.options.t_end_revs * rev
    }

    /// The scratch state at a revolution boundary, as the watch compares
    /// it: the rotor's position and velocity in its body frame (scaled by
    /// A_ref and A_ref·ω), the weights' angles and rates (rates over ω), the
    /// spin rate over ω; and r/A_ref over the [`LAG`] revolutions that end here.
    fn stroboscope(&self, t: f64) -> Stroboscope {
        let lay = self.system.layout();
        let nq = lay.nq();
        let y = &self.scratch;
        // The rotating frame already holds body-frame (u, v); inertial (x, y)
        // are turned back by the spin angle.
        let (angle, rate) = self.system.spin(t, y);
        let (s, c) = match self.frame {
            Some(_) => (0.0, 1.0),
            None => (-angle).sin_cos(),
        };
        let turn = |a: f64, b: f64| (a * c - b * s, a * s + b * c);
        let (u, v) = turn(y[0], y[1]);
        let (ud, vd) = turn(y[nq], y[nq + 1]);
        let (a, w) = (self.a_ref, self.omega);
        let mut smooth = vec![u / a, v / a, ud / (a * w), vd / (a * w)];
        smooth.extend(y[nq + lay.head()..2 * nq].iter().map(|rate| rate / w));
        smooth.push(rate / w);
        let (older, newer) = self.ring.latest(LAG * self.per_rev() as usize);
        Stroboscope {
            smooth,
            angles: y[lay.head()..nq].to_vec(),
            r: older.iter().chain(newer).map(|r2| r2.sqrt() / a).collect(),
        }
    }

    /// The ε settling time the full run would report at the horizon, for a
    /// state that repeats every revolution from boundary t on: a hold met,
    /// or a stretch begun revolutions before the repeat, stands; a stretch
    /// begun in the last revolution begins again, at the same phase, in
    /// every later one. `None` when neither is sure (a stretch begun a few
    /// revolutions ago); `Some(None)` for no stretch at the boundary.
    #[allow(clippy::option_option)]
    fn eps_at_horizon(&self, t: f64) -> Option<Option<f64>> {
        let rev = self.dt * self.per_rev() as f64;
        let horizon = self.t0 + self.options.t_end_revs * rev;
        if let Some(met) = self.eps_hold.met_at {
            return Some(Some(met));
        }
        match self.eps_hold.stretch_start {
            None => Some(None),
            Some(start) if start <= t - (2 * WINDOW * LAG) as f64 * rev => Some(Some(start)),
            Some(start) if start > t - rev => Some(Some(start + (horizon - t))),
            Some(_) => None,
        }
    }

    /// The band, the speed and the revolutions left, at boundary time t.
    fn repeat_criteria(&self, t: f64, operating: bool, spin_ratio: f64) -> Criteria {
        let rev = self.dt * self.per_rev() as f64;
        Criteria {
            delta: self.options.delta,
            operating,
            spin_ratio,
            remaining_revs: (self.t0 + self.options.t_end_revs * rev - t) / rev,
        }
    }

    /// Whether no two weights are within [`CONTACT_MARGIN`] of touching (in
    /// contact or apart) at the latest sample.
    fn contacts_settled(&self) -> bool {
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

    /// The run has tracked a flow up to this sample: if the flow bounds the
    /// rest of the hold window (see [`super::certify`]), take its samples
    /// for the rest and stop; otherwise go on integrating, and tell the
    /// certifier when the bound is likely to hold.
    fn end_on_flow(&mut self, tracked: &Tracked) -> Flow {
        let (Some(start), Some(_)) = (self.r_hold.stretch_start, self.operating_since) else {
            return Flow::Continue;
        };
        // ε inside its band now, so that its stretch (or hold) stands; no
        // two weights within CONTACT_MARGIN of touching.
        let eps_inside = self.eps_hold.met_at.is_some() || self.eps_hold.stretch_start.is_some();
        if !eps_inside || !self.contacts_settled() {
            return Flow::Continue;
        }
        let first = self.next_index;
        // The sample at which `Hold::update` will find the window complete:
        // estimated, then settled by its own test on the same sample times.
        let ahead = ((start + self.window - self.sample_time(first)) / self.dt).floor();
        let mut last = first + ahead.max(0.0) as u64;
        while last > first && self.sample_time(last - 1) - start >= self.window {
            last -= 1;
        }
        while self.sample_time(last) - start < self.window {
            last += 1;
        }
        let rev = self.dt * f64::from(self.options.samples_per_rev.max(32));
        if self.sample_time(last) > self.t0 + self.options.t_end_revs * rev {
            return Flow::Continue;
        }
        let reusable = self
            .plan
            .as_ref()
            .is_some_and(|p| p.check == tracked.check && p.first <= first && p.last == last);
        if !reusable {
            self.plan = self.plan_tail(tracked, first, last);
        }
        let Some(plan) = &self.plan else {
            let t = self.sample_time(first) + REPLAN_REVS * rev;
            if let Some(c) = &mut self.certifier {
                c.defer(t);
            }
            return Flow::Continue;
        };
        let r = &plan.r[(first - plan.first) as usize..];
        // The samples of now that the window's last ring will still hold.
        let known = self
            .ring
            .latest_sum(self.ring.len().saturating_sub(r.len()));
        let limit = (1.0 - MARGIN) * self.band;
        let floor = ERROR_GROWTH * tracked.error * self.a_ref;
        // How far the bound lets r² exceed the prediction, sample by sample.
        let excess = |r: f64| {
            let bound = (1.0 + BOUND_SLACK) * r + floor;
            bound * bound - r * r
        };
        let max_r = r.iter().copied().fold(0.0, f64::max);
        if !inside((1.0 + BOUND_SLACK) * max_r + floor, limit) {
            self.plan = None;
            return Flow::Continue;
        }
        let total_excess: f64 = r.iter().map(|&r| excess(r)).sum();
        if !inside(total_excess, self.residual_share * known) {
            // On the prediction, the first later sample where it would hold.
            let (mut known_then, mut excess_then) = (known, total_excess);
            let mut wait = r.len();
            for (k, &rk) in r.iter().enumerate() {
                known_then += rk * rk;
                excess_then -= excess(rk);
                if excess_then <= self.residual_share * known_then {
                    wait = k + 1;
                    break;
                }
            }
            let t = self.sample_time(first - 1) + wait as f64 * self.dt;
            if let Some(c) = &mut self.certifier {
                c.defer(t);
            }
            return Flow::Continue;
        }
        let Some(plan) = self.plan.take() else {
            unreachable!("checked above")
        };
        for (k, &rk) in plan.r[(first - plan.first) as usize..].iter().enumerate() {
            let t = self.sample_time(first + k as u64);
            self.ring.push(rk * rk);
            self.peak_r = self.peak_r.max(rk);
            self.r_hold.update(t, true, self.window);
            self.eps_hold.update(t, true, self.window);
        }
        self.next_index = last + 1;
        // The run ends here: its final state is the integrated one, not
        // the prediction at the window's end.
        self.certified = Some((self.sample_time(first - 1), self.scratch.clone()));
        Flow::Stop
    }

    /// r on the tracked flow from the current state for samples first..=last,
    /// or None if ε would leave its band, a contact open or close, or two
    /// weights come closer than they have so far.
    fn plan_tail(&self, tracked: &Tracked, first: u64, last: u64) -> Option<TailPlan> {
        let flow = &tracked.flow;
        let system = self.system;
        let lay = system.layout();
        let psi = lay.head()..lay.nq();
        let dim = self.scratch.len();
        let eps_limit = (1.0 - MARGIN) * self.options.delta;
        let count = (last - first + 1) as usize;
        let mut x = vec![0.0; dim + 1];
        let mut tmp = vec![0.0; dim + 1];
        // Positions only: r, ε and the gaps need no more.
        let mut state = vec![0.0; lay.nq()];
        let mut r = Vec::with_capacity(count);
        flow.lift(&self.scratch, &mut x);
        for k in 0..count {
            flow.advance(&mut x, &mut tmp);
            let checked = k % TAIL_CHECK_STRIDE == 0 || k + 1 == count;
            // r needs the rotor's coordinates only; the angles, when checked.
            let needed = if checked { lay.nq() } else { lay.head() };
            flow.lower(&x, &mut state[..needed]);
            r.push(self.whirl(&state));
            if checked {
                let angles = &state[psi.clone()];
                if !inside(self.balancing.error(system, angles), eps_limit) {
                    return None;
                }
                // A contact that opens or closes would change the flow, and
                // the closest approach so far must stay the run's.
                if let Some(g) = &self.gap
                    && !(g.same_contacts(&self.scratch[psi.clone()], angles, CONTACT_MARGIN)
                        && g.min_gap(angles) >= self.closest.smallest())
                {
                    return None;
                }
            }
        }
        Some(TailPlan {
            check: tracked.check,
            first,
            last,
            r,
        })
    }

    /// Turn the observations and the solver's report into the run's metrics.
    pub fn finish(self, report: &SolveReport) -> (RunMetrics, Option<Series>) {
        let lay = self.system.layout();
        let rev = self.dt * f64::from(self.options.samples_per_rev.max(32));
        // The run's end as the integration computes it, to the last bit.
        let horizon = self.t0 + self.options.t_end_revs * 2.0 * PI / self.omega;
        // A certified hold ends the run at the sample that certified it; a
        // certified "not settled" at a revolution boundary, whose state every
        // later boundary, the horizon's too, repeats within the bound.
        let (t_final, y_final) = match (&self.certified, &self.never) {
            (Some((t, y)), _) => (*t, y.as_slice()),
            (None, Some((_, _, y))) => (horizon, y.as_slice()),
            (None, None) => (report.t, report.y.as_slice()),
        };
        let psi = &y_final[lay.head()..lay.nq()];
        let (t_s, hold_complete) = self.r_hold.settling_time();
        let (mut t_eps, _) = self.eps_hold.settling_time();
        // A run certified never to settle repeats its last revolutions to
        // the horizon: the last hold window's RMS is theirs.
        let rms = match &self.never {
            Some((_, t, _)) => {
                t_eps = self.eps_at_horizon(*t).flatten();
                let (older, newer) = self.ring.latest(LAG * self.per_rev() as usize);
                let count = older.len() + newer.len();
                (older.iter().chain(newer).sum::<f64>() / count.max(1) as f64).sqrt()
            }
            None => self.ring.rms(),
        };
        // Identical weights that met and are still one at the end: a result
        // only if the pair is stable there (real weights would stay together
        // too); where it is unstable, real weights would have parted.
        let merged_apart = self.merged.and_then(|(i, j, t_met)| {
            coincident_pair(&[(i, j)], lay, y_final)?;
            let rate = self.parting_rate(t_final, y_final, i, j);
            (rate > 1e-6 * self.omega).then(|| {
                format!(
                    "weights {i} and {j} (identical) coincided at t = {t_met:.4} and moved as one to the end, where the pair is unstable (once apart it would part at {rate:.3e} 1/s): the equations keep identical weights together for ever, real ones would separate; add [sampling.tolerances] to give them the differences real parts have"
                )
            })
        });
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
            (None, _) if merged_apart.is_some() => {
                (Outcome::Merged, merged_apart.clone().unwrap_or_default())
            }
            (None, _) if self.never.is_some() => {
                let (never, t, _) = self.never.as_ref().expect("checked");
                (
                    Outcome::NotSettled,
                    format!(
                        "not settled: from t = {t:.4} the state repeats every {LAG} revolutions (changing by at most {:.1e} per {LAG} revolutions, not growing: every later state within {:.1e} of it, scaled); {} to the horizon",
                        never.largest, never.tail, never.why
                    ),
                )
            }
            (None, _) => match t_s {
                Some(t) if hold_complete => (
                    Outcome::Settled,
                    match self.certified {
                        // Say which part of the window was integrated.
                        Some((t_end, _)) => format!(
                            "r ≤ {} A_ref held for {} revolutions from t = {t:.4} (certified: integrated to t = {t_end:.4}, the last {:.1} revolutions bounded on the linearised flow)",
                            self.options.delta,
                            self.options.hold_revs,
                            (t + self.window - t_end.min(t + self.window)) / rev
                        ),
                        None => format!(
                            "r ≤ {} A_ref held for {} revolutions from t = {t:.4}",
                            self.options.delta, self.options.hold_revs
                        ),
                    },
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
                            vibration(self.system, y_final) / self.a_ref,
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
            hold_certified: self.certified.is_some(),
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
            t_final,
            steps: report.stats.steps,
            rhs_calls: report.stats.rhs_calls + self.certifier.as_ref().map_or(0, |c| c.rhs_calls),
            method: String::new(),
            fidelity: String::new(),
            min_gap_rad: self.gap.as_ref().map(|_| self.closest.smallest()),
            censoring_revs: matches!(outcome, Outcome::Censored | Outcome::NotSettled).then(|| {
                let t_op = self.operating_since.unwrap_or(t_final);
                ((t_final - self.window).max(t_op) - self.t0) / rev
            }),
            final_min_gap_rad: self.gap.as_ref().map(|g| g.min_gap(psi)),
            operating_time: self.operating_since,
            final_spin_rate: Some(self.system.spin(t_final, y_final).1),
            balance_angle_error_deg: None,
            plane_a_ref: self.planes.as_ref().map(|p| p.a_ref.clone()),
            plane_residual_abs: self
                .planes
                .as_ref()
                .map(|p| p.rings.iter().map(SquareRing::rms).collect()),
            // Measured after the run, by the simulation (it needs the solver).
            bearing_orbit_peak: None,
            bearing_orbit_rms: None,
            plane_balancing_error: self
                .planes
                .as_ref()
                .and_then(|_| plane_balancing_errors(self.system, psi, self.u_ref)),
            plane_settling_revs: self.planes.as_ref().map(|p| {
                p.holds
                    .iter()
                    .map(|h| h.met_at.map(|t| (t - self.t0) / rev))
                    .collect()
            }),
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
