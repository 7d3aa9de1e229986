//! Certified hold: end a settled run before its hold window is over, once
//! the rest of the window provably cannot change what the run reports.
//!
//! In the rotating frame at constant speed the equations are autonomous and,
//! once r is inside the band, the state sits close to a fixed point (or to
//! the family of balanced positions of n ≥ 3 weights). There the flow is the
//! linear (affine) one, ż ≈ f(z*) + J (z − z*), about the nearest fixed point
//! z*; over one sample interval it is a single matrix,
//! Φ = exp(dt·[[J, f(z*)], [0, 0]]).
//!
//! The hold window decides two outputs: the settling time (r stays inside
//! the band for W revolutions) and the residual (the RMS of r over the
//! window). Late in a settling run the rest of the window contributes almost
//! nothing to the residual, because r has decayed: the run can stop once
//! 1. **tracking**: Φ, started from the integrated state at a check, agrees
//!    with the integration on every sample for [`VERIFY_REVS`] (positions,
//!    to [`TRACKING_TOLERANCE`] of r at the check), and keeps agreeing;
//! 2. **bound**: on Φ from the current state, r is bounded sample by sample
//!    by the predicted r with [`BOUND_SLACK`] and [`ERROR_GROWTH`] times the
//!    tracking error added; the bound stays inside the band with [`MARGIN`]
//!    to the end of the window, ε inside its band, no contact between
//!    weights opens or closes and none comes closer than so far (the
//!    observer checks these);
//! 3. **negligible rest**: what the bounds allow beyond the prediction,
//!    Σ (bound² − predicted r²) over the rest of the window, is at most
//!    [`residual_share`] of the window's Σ r² so far, so the reported
//!    residual, which sums the predicted r² for the rest, is within half of
//!    that of the full hold's.
//!
//! The observer then takes the predicted samples' r for the rest of the
//! window and ends the run at the current sample, with the integrated
//! state. The prediction's accuracy matters only through the bound, which
//! has the slack. This is a checked bound, not a proof:
//! `tests/it/certified_hold.rs` compares it run by run with the full hold on
//! every shipped study. A failed tracking is retried [`RETRY_REVS`] later,
//! at most [`MAX_ATTEMPTS`] times per run.

use crate::integrate::OdeSystem;
use crate::integrate::lu::RealLu;

/// r inside the band for this many revolutions before the first check (the
/// observer also waits until r is deep inside it; see its `READY_FRACTION`).
pub const FIRST_CHECK_REVS: f64 = 1.0;
/// Revolutions over which the linearised flow must track the integration.
pub const VERIFY_REVS: f64 = 1.5;
/// Once tracked, a bound is tried every this many revolutions.
pub const USE_EVERY_REVS: f64 = 1.0;
/// A failed check is retried this many revolutions later.
pub const RETRY_REVS: f64 = 3.0;
/// Checks per run at most (each costs 2·dim + 1 right-hand sides).
pub const MAX_ATTEMPTS: u32 = 6;
/// Largest tracking error, as a fraction of r at the check (scaled state).
pub const TRACKING_TOLERANCE: f64 = 5e-2;
/// The bound on r must stay this fraction of the band inside it (and the
/// predicted ε this fraction inside its band).
pub const MARGIN: f64 = 0.02;
/// On the rest of the window r is bounded, sample by sample, by the
/// predicted r times 1 + this, plus [`ERROR_GROWTH`] times the largest
/// tracking error seen.
pub const BOUND_SLACK: f64 = 0.1;
/// How far the flow's absolute error may grow past what tracking saw.
pub const ERROR_GROWTH: f64 = 2.0;
/// The bounds may move Σ r² over the window by at most this fraction (the
/// residual, an RMS, then by at most half of it)...
pub const RESIDUAL_SHARE: f64 = 0.01;
/// ... or by this many times the integration's rtol, if less: at rtol 1e-6
/// (the default) the full share, as much as the integration's own error in
/// the residual there; a tighter tolerance asks for a residual as accurate.
pub const RESIDUAL_SHARE_PER_RTOL: f64 = 1e4;

/// The share of Σ r² the bounds may move for an integration at `rtol`.
pub fn residual_share(rtol: f64) -> f64 {
    (RESIDUAL_SHARE_PER_RTOL * rtol).min(RESIDUAL_SHARE)
}

/// Newton steps towards the fixed point at most.
const NEWTON_STEPS: usize = 6;
/// A Newton step this small (scaled) ends the iteration.
const NEWTON_SETTLED: f64 = 1e-9;
/// μ / max|JᵀJ|: enough to make the normal matrix regular on a family of
/// fixed points, small enough not to slow Newton elsewhere.
const NORMAL_RIDGE: f64 = 1e-12;
/// Degree of the Taylor polynomial in [`expm`].
const TAYLOR_DEGREE: u32 = 8;
/// [`expm`] scales its argument to at most this norm before the Taylor
/// polynomial (truncation error below 0.25⁹/9! ≈ 1e-11).
const EXPM_NORM: f64 = 0.25;

/// Relative step of the central differences: far below ε^(1/3), so that the
/// stencil stays on one side of a contact at rest (overlaps of 1e-7 rad);
/// the rounding error it costs, ≈ 1e-7 of the Jacobian, is far below what
/// the tracking tolerates.
const FD_STEP: f64 = 1e-9;

/// The affine flow over one sample interval, on the scaled state.
#[derive(Debug, Clone)]
pub struct AffineFlow {
    /// Expansion point: the fixed point nearest the state at the check.
    origin: Vec<f64>,
    /// Component scales (z = origin + scale ⊙ x).
    scale: Vec<f64>,
    /// Φ, (dim + 1)², row-major, acting on [x; 1].
    phi: Vec<f64>,
}

impl AffineFlow {
    /// Length of the state.
    pub fn dim(&self) -> usize {
        self.origin.len()
    }

    /// Scaled deviation [x; 1] of the state z.
    pub fn lift(&self, z: &[f64], x: &mut [f64]) {
        for (i, xi) in x.iter_mut().take(self.dim()).enumerate() {
            *xi = (z[i] - self.origin[i]) / self.scale[i];
        }
        x[self.dim()] = 1.0;
    }

    /// The state z of the scaled deviation x.
    pub fn lower(&self, x: &[f64], z: &mut [f64]) {
        for (i, zi) in z.iter_mut().enumerate() {
            *zi = self.origin[i] + self.scale[i] * x[i];
        }
    }

    /// x ← Φ x (tmp is work space of the same length). The last entry of
    /// [x; 1] stays 1 (Φ's last row is that of the identity), so it is
    /// neither computed nor multiplied.
    pub fn advance(&self, x: &mut [f64], tmp: &mut [f64]) {
        let m = x.len();
        let n = m - 1;
        let (state, _) = x.split_at(n);
        for (row, out) in self.phi.chunks_exact(m).zip(tmp[..n].iter_mut()) {
            // Four partial sums: the products are independent, and one
            // running sum would serialise them on the adder's latency.
            let mut acc = [0.0f64; 4];
            let (head, rest) = state.split_at(n - n % 4);
            for (a, b) in row[..head.len()].chunks_exact(4).zip(head.chunks_exact(4)) {
                for i in 0..4 {
                    acc[i] += a[i] * b[i];
                }
            }
            let mut sum = row[n] + (acc[0] + acc[1]) + (acc[2] + acc[3]);
            for (a, b) in row[head.len()..n].iter().zip(rest) {
                sum += a * b;
            }
            *out = sum;
        }
        x[..n].copy_from_slice(&tmp[..n]);
    }
}

/// Where a run's certification stands.
#[derive(Debug)]
enum Phase {
    /// No model; the next check comes at `next` (s), NaN for "one
    /// [`FIRST_CHECK_REVS`] into the stretch".
    Waiting { next: f64 },
    /// A model is compared with the integration sample by sample; from
    /// `until` (s) on it may be used, checked again at `next_use`.
    Tracking {
        flow: AffineFlow,
        predicted: Vec<f64>,
        until: f64,
        next_use: f64,
        tolerance: f64,
        /// The largest tracking error so far (scaled).
        seen: f64,
    },
    /// Gave up for this run (too many failed checks).
    Off,
}

/// A flow that has tracked the run so far.
#[derive(Debug)]
pub struct Tracked {
    /// The affine flow.
    pub flow: AffineFlow,
    /// The largest tracking error so far (positions scaled by A_ref, angles in rad).
    pub error: f64,
    /// Which check of the run made the flow (predictions from it stay comparable).
    pub check: u32,
}

/// Decides, sample by sample, when the affine flow has tracked the run long
/// enough to bound the rest of a hold window with it.
pub struct HoldCertifier<'a> {
    ode: &'a dyn OdeSystem,
    scale: Vec<f64>,
    rev: f64,
    dt: f64,
    /// The band δ·A_ref in scaled units (positions scale with A_ref).
    delta: f64,
    phase: Phase,
    attempts: u32,
    /// Right-hand-side calls spent on Jacobians.
    pub rhs_calls: u64,
    tmp: Vec<f64>,
}

impl<'a> HoldCertifier<'a> {
    /// A certifier for the autonomous `ode` whose components have typical
    /// sizes `scale` (positions in A_ref), sampled every `dt` with revolution
    /// `rev` (s), band δ.
    pub fn new(ode: &'a dyn OdeSystem, scale: Vec<f64>, rev: f64, dt: f64, delta: f64) -> Self {
        let n = scale.len();
        HoldCertifier {
            ode,
            scale,
            rev,
            dt,
            delta,
            phase: Phase::Waiting { next: f64::NAN },
            attempts: 0,
            rhs_calls: 0,
            tmp: vec![0.0; n + 1],
        }
    }

    /// Whether a check is due at t in a stretch that began at `since`: the
    /// observer then tells [`Self::observe`] whether the run is ready.
    pub fn wants_to_start(&self, t: f64, since: f64) -> bool {
        match self.phase {
            Phase::Waiting { next } => {
                let due = if next.is_nan() {
                    since + FIRST_CHECK_REVS * self.rev
                } else {
                    next
                };
                t + 1e-9 * self.dt >= due
            }
            _ => false,
        }
    }

    /// Sample at time t with state z (r/A_ref = `r_rel`); `inside_since` is
    /// the start of the current stretch inside the band, if any. Returns the
    /// flow when it has tracked the run and a bound may be tried now.
    pub fn observe(
        &mut self,
        t: f64,
        z: &[f64],
        r_rel: f64,
        inside_since: Option<f64>,
        ready: bool,
    ) -> Option<Tracked> {
        let Some(since) = inside_since else {
            // Left the band: whatever was being tracked no longer applies.
            if !matches!(self.phase, Phase::Off) {
                self.phase = Phase::Waiting { next: f64::NAN };
            }
            return None;
        };
        let on_grid = 1e-9 * self.dt;
        match &mut self.phase {
            Phase::Off => None,
            Phase::Waiting { next } => {
                if next.is_nan() {
                    *next = since + FIRST_CHECK_REVS * self.rev;
                }
                if t + on_grid >= *next {
                    if ready {
                        self.start_tracking(t, z, r_rel);
                    } else {
                        // Not yet: look again a revolution later.
                        *next = t + self.rev;
                    }
                }
                None
            }
            Phase::Tracking {
                flow,
                predicted,
                until,
                next_use,
                tolerance,
                seen,
            } => {
                flow.advance(predicted, &mut self.tmp);
                // Positions only: every output (r, ε, gaps, angles) is one of
                // them, and velocities carry the fast rotor modes' error.
                let dim = flow.dim();
                let off = (0..dim / 2)
                    .map(|i| ((z[i] - flow.origin[i]) / flow.scale[i] - predicted[i]).abs())
                    .fold(0.0, f64::max);
                if off.is_nan() || off > *tolerance {
                    self.retry(t);
                    return None;
                }
                *seen = seen.max(off);
                if t + on_grid >= *until && t + on_grid >= *next_use {
                    *next_use = t + USE_EVERY_REVS * self.rev;
                    return Some(Tracked {
                        flow: flow.clone(),
                        error: *seen,
                        check: self.attempts,
                    });
                }
                None
            }
        }
    }

    /// Whether the sample at t will lift the full state (a check or a use
    /// of the flow is due), in a stretch inside the band since `since`.
    pub fn needs_full_state(&self, t: f64, since: f64) -> bool {
        match &self.phase {
            Phase::Waiting { .. } => self.wants_to_start(t, since),
            Phase::Tracking {
                until, next_use, ..
            } => t + 1e-9 * self.dt >= until.max(*next_use),
            Phase::Off => false,
        }
    }

    /// The flow in use may next be tried at t (s), not before.
    pub fn defer(&mut self, t: f64) {
        if let Phase::Tracking { next_use, .. } = &mut self.phase {
            *next_use = next_use.max(t);
        }
    }

    /// The prediction failed at t: try again later, or give up.
    fn retry(&mut self, t: f64) {
        self.phase = if self.attempts >= MAX_ATTEMPTS {
            Phase::Off
        } else {
            Phase::Waiting {
                next: t + RETRY_REVS * self.rev,
            }
        };
    }

    /// Linearise at (t, z) and start comparing.
    fn start_tracking(&mut self, t: f64, z: &[f64], r_rel: f64) {
        self.attempts += 1;
        let Some(flow) = self.linearise(z) else {
            self.retry(t);
            return;
        };
        let mut predicted = vec![0.0; z.len() + 1];
        flow.lift(z, &mut predicted);
        let until = t + VERIFY_REVS * self.rev;
        self.phase = Phase::Tracking {
            flow,
            predicted,
            until,
            next_use: until,
            seen: 0.0,
            // The residual can be far below the band: errors are judged
            // against the deviation now (r/A_ref is r in scaled units).
            tolerance: TRACKING_TOLERANCE * r_rel.min(self.delta),
        };
    }

    /// The affine flow about the fixed point nearest z over one sample
    /// interval, or None if there is none near or the derivatives are not finite.
    fn linearise(&mut self, z: &[f64]) -> Option<AffineFlow> {
        let n = z.len();
        let mut jac = vec![0.0; n * n];
        let mut f = vec![0.0; n];
        // Expanding about z itself would freeze a Jacobian error of the size
        // of the deviation into the whole prediction; about the fixed point
        // the error shrinks with the deviation. Find it by Newton steps on
        // the normal equations (JᵀJ + μI) Δ = −Jᵀf: n ≥ 3 weights balance on a
        // family of fixed points, where J is singular and this gives the
        // nearest one.
        let mut origin = z.to_vec();
        let mut normal = vec![0.0; n * n];
        let mut lu = RealLu::new(n);
        let mut step = vec![0.0; n];
        let mut converged = false;
        for _ in 0..NEWTON_STEPS {
            self.scaled_jacobian(&origin, &mut jac);
            self.scaled_rhs(&origin, &mut f);
            for a in 0..n {
                for b in 0..n {
                    normal[a * n + b] =
                        -(0..n).map(|k| jac[k * n + a] * jac[k * n + b]).sum::<f64>();
                }
            }
            let size = normal.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if !lu.factor_shifted(NORMAL_RIDGE * size, &normal) {
                return None;
            }
            for (a, s) in step.iter_mut().enumerate() {
                *s = (0..n).map(|k| jac[k * n + a] * f[k]).sum();
            }
            lu.solve(&mut step);
            for i in 0..n {
                origin[i] -= step[i] * self.scale[i];
            }
            if step.iter().map(|v| v.abs()).fold(0.0, f64::max) < NEWTON_SETTLED {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        // The last Jacobian was taken less than NEWTON_SETTLED away: keep it.
        self.scaled_rhs(&origin, &mut f);
        let m = n + 1;
        let mut generator = vec![0.0; m * m];
        for row in 0..n {
            for col in 0..n {
                generator[row * m + col] = jac[row * n + col] * self.dt;
            }
            generator[row * m + n] = f[row] * self.dt;
        }
        if generator.iter().any(|v| !v.is_finite()) {
            return None;
        }
        Some(AffineFlow {
            origin,
            scale: self.scale.clone(),
            phi: expm(&generator, m),
        })
    }

    /// f(z) in scaled units per second.
    fn scaled_rhs(&mut self, z: &[f64], f: &mut [f64]) {
        self.ode.rhs(0.0, z, f);
        self.rhs_calls += 1;
        for (fi, s) in f.iter_mut().zip(&self.scale) {
            *fi /= s;
        }
    }

    /// ∂f/∂z in scaled units by central differences, row-major.
    fn scaled_jacobian(&mut self, z: &[f64], jac: &mut [f64]) {
        let n = z.len();
        let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        for col in 0..n {
            let h = FD_STEP * self.scale[col].max(z[col].abs());
            zp[col] = z[col] + h;
            zm[col] = z[col] - h;
            self.ode.rhs(0.0, &zp, &mut fp);
            self.ode.rhs(0.0, &zm, &mut fm);
            for row in 0..n {
                jac[row * n + col] =
                    (fp[row] - fm[row]) / (2.0 * h) * self.scale[col] / self.scale[row];
            }
            zp[col] = z[col];
            zm[col] = z[col];
        }
        self.rhs_calls += 2 * n as u64;
    }
}

/// exp(A) of a small dense m×m matrix (row-major) by scaling and squaring
/// with a Taylor polynomial of degree [`TAYLOR_DEGREE`] on ‖A‖∞ ≤
/// [`EXPM_NORM`]. Hand-written rather than nalgebra's `exp`:
/// this runs once per check on an 11×11 matrix, and in the dev profile a
/// dependency's generic code is not optimised (it cost more than the
/// integration it saves).
fn expm(a: &[f64], m: usize) -> Vec<f64> {
    let norm = (0..m)
        .map(|i| a[i * m..(i + 1) * m].iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > EXPM_NORM {
        (norm / EXPM_NORM).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(squarings);
    let scaled: Vec<f64> = a.iter().map(|v| v * scale).collect();
    let identity = |e: &mut [f64]| {
        e.fill(0.0);
        for i in 0..m {
            e[i * m + i] = 1.0;
        }
    };
    let multiply = |x: &[f64], y: &[f64], out: &mut [f64]| {
        for i in 0..m {
            for j in 0..m {
                out[i * m + j] = (0..m).map(|k| x[i * m + k] * y[k * m + j]).sum();
            }
        }
    };
    // Horner: e = I + A/1 (I + A/2 (… (I + A/d))).
    let mut e = vec![0.0; m * m];
    let mut t = vec![0.0; m * m];
    identity(&mut e);
    for k in (1..=TAYLOR_DEGREE).rev() {
        multiply(&scaled, &e, &mut t);
        for (i, v) in t.iter().enumerate() {
            e[i] = v / f64::from(k) + if i % (m + 1) == 0 { 1.0 } else { 0.0 };
        }
    }
    for _ in 0..squarings {
        multiply(&e, &e, &mut t);
        e.copy_from_slice(&t);
    }
    e
}
