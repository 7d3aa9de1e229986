//! Stiffness detection for the explicit methods: Hairer's indicator, and a
//! power-iteration check for when the indicator is weak but persistent.
//!
//! Hairer's indicator h·|f(y₁) − f(y_s)|/|y₁ − y_s| estimates h·|λ| in the
//! direction of the last two stages, which is a mix of modes. Where the
//! stiffness is spread over a band of close eigenvalues (a chain of weights
//! resting in contact: 16 balls at half-race fill sit at DP5's stability
//! limit for 100 revolutions with the indicator steady at 1.9 of 3.25), the
//! mix never reaches the bound and the run crawls at 300 steps per
//! revolution. The check here follows the indicator's direction a few
//! Jacobian–vector products further (finite differences, one right-hand side
//! each), which pulls it towards the dominant eigenvalue: an estimate of
//! ρ(J) (from below where the dominant mode leads, as in a chain) that can
//! confirm the stability limit without a Jacobian matrix.

use super::norm::atol_of;
use super::{OdeSystem, SolverOptions, Stats};

/// Hairer's stiffness counting (DOPRI5, DOP853): this many accepted steps
/// held by stability in a row mean the problem is stiff ...
const STIFF_STEPS: u32 = 15;
/// ... unless this many steps held by accuracy come in between.
const NON_STIFF_STEPS: u32 = 6;

/// An indicator above this fraction of the method's bound, as persistently
/// as Hairer's counting asks, calls for the power-iteration check.
const HINT_FRACTION: f64 = 0.4;
/// Hint steps (counted like Hairer's) before the first check: Hairer's own
/// counting decides wherever it can (a run it hands over does so within
/// about 15 steps of the hint), so the check changes only runs it misses.
const FIRST_CHECK_AFTER: u32 = 100;
/// The check confirms stiffness when h·ρ(J) exceeds this fraction of the
/// bound: the step is then within reach of the stability limit, which an
/// accuracy-limited step (h·ρ well below 1) never is.
const CONFIRM_FRACTION: f64 = 0.75;
/// Jacobian–vector products per check at most.
const POWER_STEPS: usize = 12;
/// Products before the successive ratios are taken as an estimate.
const MIN_POWER_STEPS: usize = 5;
/// The check stops, not confirmed, once its estimate (after
/// [`MIN_POWER_STEPS`]) is below this fraction of the level it needs.
const ABANDON_FRACTION: f64 = 0.5;
/// Finite-difference step along the unit direction, relative to 1 + |y|:
/// small enough to stay on one side of a resting contact's kink (overlaps
/// of 1e-7 rad), large enough for the difference quotient.
const PROBE_STEP: f64 = 1e-9;

/// Hairer's indicator h·|Δf|/|Δy| for two stages at the same time.
pub(super) fn indicator(h: f64, f_a: &[f64], f_b: &[f64], y_a: &[f64], y_b: &[f64]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..f_a.len() {
        num += (f_a[i] - f_b[i]).powi(2);
        den += (y_a[i] - y_b[i]).powi(2);
    }
    if den > 0.0 {
        h * (num / den).sqrt()
    } else {
        0.0
    }
}

/// What the driver decides after an accepted explicit step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Verdict {
    /// Go on with the explicit method.
    Explicit,
    /// The indicator has been weak but persistent: run the power check.
    Check,
    /// Stiff: hand the run over.
    Stiff,
}

/// Hairer's counting of the indicator, with the weak-signal count beside it.
#[derive(Debug, Clone)]
pub(super) struct StiffnessWatch {
    bound: f64,
    stiff: u32,
    non_stiff: u32,
    hint: u32,
    non_hint: u32,
    /// Hint steps in a row the next check waits for: doubled after every
    /// check that does not confirm, so that checks cost a bounded share.
    hint_needed: u32,
}

impl StiffnessWatch {
    /// A watch for a method whose indicator bound is `bound`.
    pub(super) fn new(bound: f64) -> Self {
        StiffnessWatch {
            bound,
            stiff: 0,
            non_stiff: 0,
            hint: 0,
            non_hint: 0,
            hint_needed: FIRST_CHECK_AFTER,
        }
    }

    /// Count the indicator `ratio` (h·|λ|) of an accepted step.
    pub(super) fn observe(&mut self, ratio: f64) -> Verdict {
        if ratio > self.bound {
            self.non_stiff = 0;
            self.stiff += 1;
            if self.stiff == STIFF_STEPS {
                return Verdict::Stiff;
            }
        } else {
            self.non_stiff += 1;
            if self.non_stiff == NON_STIFF_STEPS {
                self.stiff = 0;
            }
        }
        if ratio > HINT_FRACTION * self.bound {
            self.non_hint = 0;
            self.hint += 1;
            if self.hint >= self.hint_needed {
                return Verdict::Check;
            }
        } else {
            self.non_hint += 1;
            if self.non_hint == NON_STIFF_STEPS {
                self.hint = 0;
            }
        }
        Verdict::Explicit
    }

    /// The power check estimated h·ρ(J) = `h_rho`: stiff, or wait longer
    /// for the next check.
    pub(super) fn checked(&mut self, h_rho: f64) -> Verdict {
        if h_rho > self.confirm_level() {
            return Verdict::Stiff;
        }
        self.hint = 0;
        self.hint_needed = self.hint_needed.saturating_mul(2);
        Verdict::Explicit
    }

    /// The h·ρ above which [`StiffnessWatch::checked`] confirms.
    pub(super) fn confirm_level(&self) -> f64 {
        CONFIRM_FRACTION * self.bound
    }
}

/// Work vectors of the power check, allocated once per run.
pub(super) struct PowerProbe {
    v: Vec<f64>,
    w: Vec<f64>,
    fw: Vec<f64>,
}

impl PowerProbe {
    /// Buffers for a system of dimension `dim`.
    pub(super) fn new(dim: usize) -> Self {
        PowerProbe {
            v: vec![0.0; dim],
            w: vec![0.0; dim],
            fw: vec![0.0; dim],
        }
    }

    /// An estimate of h·ρ(J) at (t, y), where f(t, y) = `fy`, by power
    /// iteration from the direction `y − y_other`, in the error norm's
    /// scaled variables (D⁻¹JD has J's eigenvalues, and the scaling keeps
    /// positions and velocities comparable); stops early once it exceeds
    /// `enough`, or falls below [`ABANDON_FRACTION`] of it.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn h_rho<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        fy: &[f64],
        y_other: &[f64],
        h: f64,
        options: &SolverOptions,
        enough: f64,
        stats: &mut Stats,
    ) -> f64 {
        let (rtol, atol) = (options.rtol, options.atol.as_slice());
        let scale = |i: usize| atol_of(atol, i) + rtol * y[i].abs();
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        for (i, v) in self.v.iter_mut().enumerate() {
            *v = (y[i] - y_other[i]) / scale(i);
        }
        let y_norm = norm(y);
        let mut previous = f64::NAN;
        let mut estimate = 0.0f64;
        for k in 0..POWER_STEPS {
            let v_norm = norm(&self.v);
            if !(v_norm > 0.0 && v_norm.is_finite()) {
                break;
            }
            // The state moves by s·D·v̂, at most PROBE_STEP·(1 + |y|) in any unit.
            let reach = self
                .v
                .iter()
                .enumerate()
                .map(|(i, v)| (v * scale(i)).abs())
                .fold(0.0, f64::max)
                / v_norm;
            let s = PROBE_STEP * (1.0 + y_norm) / reach;
            for (i, w) in self.w.iter_mut().enumerate() {
                *w = y[i] + s * scale(i) * self.v[i] / v_norm;
            }
            system.rhs(t, &self.w, &mut self.fw);
            stats.rhs_calls += 1;
            // D⁻¹·J·D·v̂ ≈ D⁻¹(f(y + s·D·v̂) − f(y))/s: the next direction.
            for (i, v) in self.v.iter_mut().enumerate() {
                *v = (self.fw[i] - fy[i]) / (s * scale(i));
            }
            let ratio = h * norm(&self.v);
            if !ratio.is_finite() {
                break;
            }
            // Successive ratios approach |λ_max| from either side while the
            // non-normal transient lasts; the geometric mean of two (a complex
            // pair alternates) after a few products is the estimate.
            if k >= MIN_POWER_STEPS {
                estimate = (ratio * previous).sqrt();
                // Far below after the first products: the rest would have to
                // more than double it (they change it by a few per cent
                // where the dominant mode leads, as in a chain).
                if estimate > enough || estimate < ABANDON_FRACTION * enough {
                    break;
                }
            }
            previous = ratio;
        }
        estimate
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hairers_counting_decides_alone_where_the_indicator_reaches_its_bound() {
        let mut watch = StiffnessWatch::new(3.25);
        // Five non-stiff steps between stiff ones do not reset the count.
        for _ in 0..10 {
            assert_eq!(watch.observe(3.3), Verdict::Explicit);
        }
        for _ in 0..5 {
            assert_eq!(watch.observe(0.1), Verdict::Explicit);
        }
        for _ in 0..4 {
            assert_eq!(watch.observe(3.3), Verdict::Explicit);
        }
        assert_eq!(watch.observe(3.3), Verdict::Stiff);
        // Six in a row do.
        let mut watch = StiffnessWatch::new(3.25);
        for _ in 0..14 {
            watch.observe(3.3);
        }
        for _ in 0..6 {
            watch.observe(0.1);
        }
        for _ in 0..14 {
            assert_eq!(watch.observe(3.3), Verdict::Explicit);
        }
    }

    #[test]
    fn a_weak_persistent_indicator_is_checked_later_and_later() {
        let mut watch = StiffnessWatch::new(3.25);
        let weak = 0.5 * 3.25;
        let mut steps = 0;
        let mut checks = Vec::new();
        while checks.len() < 3 {
            steps += 1;
            if watch.observe(weak) == Verdict::Check {
                checks.push(steps);
                assert_eq!(watch.checked(0.5), Verdict::Explicit);
            }
        }
        let first = FIRST_CHECK_AFTER as usize;
        assert_eq!(checks, [first, first + 2 * first, first + 6 * first]);
        // A check that finds h·ρ near the stability limit confirms.
        assert_eq!(watch.checked(0.8 * 3.25), Verdict::Stiff);
        // Below the hint level nothing is ever checked.
        let mut watch = StiffnessWatch::new(3.25);
        for _ in 0..10_000 {
            assert_eq!(watch.observe(0.3 * 3.25), Verdict::Explicit);
        }
    }

    /// y' = J y for a chain of `n` equal weights joined by over-damped
    /// springs (k, c per unit inertia), free at both ends: positions q and
    /// velocities p, p' = −L(k q + c p) with L the path Laplacian.
    struct Chain {
        n: usize,
        k: f64,
        c: f64,
    }

    impl OdeSystem for Chain {
        fn dim(&self) -> usize {
            2 * self.n
        }
        fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
            let (q, p) = y.split_at(self.n);
            let (dq, dp) = dydt.split_at_mut(self.n);
            dq.copy_from_slice(p);
            for i in 0..self.n {
                let mut lq = 0.0;
                let mut lp = 0.0;
                for j in [i.wrapping_sub(1), i + 1] {
                    if j < self.n {
                        lq += q[i] - q[j];
                        lp += p[i] - p[j];
                    }
                }
                dp[i] = -(self.k * lq + self.c * lp);
            }
        }
    }

    impl Chain {
        /// ρ(J): the fast root of λ² + cμλ + kμ = 0 at the Laplacian's
        /// largest eigenvalue μ = 2 − 2cos((n − 1)π/n) (over-damped there).
        fn spectral_radius(&self) -> f64 {
            let n = self.n as f64;
            let mu = 2.0 - 2.0 * ((n - 1.0) * std::f64::consts::PI / n).cos();
            let (b, c) = (self.c * mu, self.k * mu);
            0.5 * (b + (b * b - 4.0 * c).sqrt())
        }
    }

    #[test]
    fn the_power_check_finds_the_spectral_radius_of_a_chain_in_contact() {
        // The contact of 16 balls: k = w², c = 2ζw per unit inertia with
        // w = 6 000 rad/s and ζ = 2 (as the contact effect builds it).
        let w = 6000.0;
        let chain = Chain {
            n: 16,
            k: w * w,
            c: 4.0 * w,
        };
        let dim = chain.dim();
        let rho = chain.spectral_radius();
        // A state with every mode in it, and a direction mostly along the
        // slow ones (what the last two stages of a step look like).
        let y: Vec<f64> = (0..dim).map(|i| 1.0 + 0.01 * (i as f64).sin()).collect();
        let mut fy = vec![0.0; dim];
        chain.rhs(0.0, &y, &mut fy);
        let other: Vec<f64> = (0..dim)
            .map(|i| y[i] - 1e-6 * (0.2 * i as f64).cos())
            .collect();
        let h = 3.0 / rho;
        let mut probe = PowerProbe::new(dim);
        let mut stats = Stats::default();
        let tol = SolverOptions {
            rtol: 1e-6,
            atol: vec![1e-8],
            ..SolverOptions::default()
        };
        let est = probe.h_rho(
            &chain, 0.0, &y, &fy, &other, h, &tol,
            4.0, // never reached, and not abandoned above 2
            &mut stats,
        );
        assert_eq!(stats.rhs_calls, POWER_STEPS as u64);
        // A lower estimate that reaches the confirm level at h·ρ = 3.
        assert!(est <= 3.0 * 1.001, "h·ρ estimated {est}, exact 3");
        assert!(est > 0.9 * 3.0, "h·ρ estimated {est}, exact 3");
        // Stopping early once the estimate is enough.
        let mut stats = Stats::default();
        let early = probe.h_rho(&chain, 0.0, &y, &fy, &other, h, &tol, 2.0, &mut stats);
        assert!(early > 2.0 && stats.rhs_calls < POWER_STEPS as u64);
        // An accuracy-limited step (h·ρ = 0.5) is given up after the first products.
        let mut stats = Stats::default();
        let small = probe.h_rho(
            &chain,
            0.0,
            &y,
            &fy,
            &other,
            h / 6.0,
            &tol,
            2.44,
            &mut stats,
        );
        assert!(small < 0.5 * 1.001, "h·ρ estimated {small}, exact 0.5");
        assert_eq!(stats.rhs_calls, MIN_POWER_STEPS as u64 + 1);
    }

    /// Each explicit stepper hands the check the right vectors: after a
    /// step on the chain near its stability limit, its own `power_check`
    /// finds h·ρ(J) as the probe does.
    #[test]
    fn each_explicit_stepper_checks_at_its_new_point() {
        use crate::integrate::dop853::Dop853;
        use crate::integrate::dp5::Dp5;
        use crate::integrate::stepper::{Stepper, Trial};

        fn check<St: Stepper>(chain: &Chain, fraction: f64) -> (f64, f64) {
            let dim = chain.dim();
            let options = SolverOptions {
                rtol: 1e-6,
                atol: vec![1.0],
                ..SolverOptions::default()
            };
            let mut stepper = St::new(dim, &options);
            let mut stats = Stats::default();
            // Far below atol: accuracy cannot hold the step, only stability.
            let y: Vec<f64> = (0..dim).map(|i| 1e-3 * (0.3 * i as f64).sin()).collect();
            stepper.start(chain, 0.0, &y, 1.0, &mut stats).unwrap();
            let rho = chain.spectral_radius();
            let h = fraction * St::STIFF_BOUND / rho;
            let trial = stepper.attempt(chain, 0.0, &y, h, &mut stats);
            assert!(matches!(trial, Trial::Accepted { .. }), "{trial:?}");
            let h_rho = stepper.power_check(chain, h, h, f64::INFINITY, &mut stats);
            (h_rho, h * rho)
        }
        let w = 6000.0;
        let chain = Chain {
            n: 16,
            k: w * w,
            c: 4.0 * w,
        };
        for (h_rho, exact) in [check::<Dp5>(&chain, 0.9), check::<Dop853>(&chain, 0.9)] {
            assert!(
                (h_rho / exact - 1.0).abs() < 0.1,
                "h·ρ estimated {h_rho}, exact {exact}"
            );
        }
    }
}
