//! What a segment of a run costs per unit of simulated time, and the rule
//! that sends a run back from the implicit method to the explicit one it
//! left when the implicit one proves dearer.
//!
//! The hand-over to Radau5 assumes that a method held at its stability
//! boundary is dearer than an implicit one. On a contact law with a kink it
//! need not be: the implicit steps are held by the kink too, and each costs
//! a Newton iteration and finite-difference Jacobians. LSODA (Petzold 1983)
//! switches both ways on predicted step sizes weighted by cost; here the
//! cost is measured, in RHS calls, the unit both methods share (Radau5's
//! factorisations are left out, so the rule leans towards keeping Radau5).
//! One return per run at most: the return experiment of docs/benchmarks.md
//! showed that runs handed back and forth gather an error that a single
//! method does not make.

/// Accepted steps over which the implicit method's cost rate is measured
/// (its Jacobians make its calls per step lumpy).
pub(crate) const COST_WINDOW: usize = 64;

/// Accepted steps over which the explicit method's cost rate is taken when
/// it stalls: about the run of steps at the stability boundary that found
/// it stiff, and no further back (a run that turns stiff at its start would
/// otherwise count its start-up's small steps).
pub(crate) const STALL_WINDOW: usize = 16;

/// How much dearer (RHS calls per unit time) the implicit method must prove
/// than the explicit one was just before the hand-over for the run to
/// return: a margin for the explicit method's cost rising later (more
/// weights pressed together) and for Radau5's falling later (a transient
/// ending), which a window of the past cannot see. Measured on the shipped
/// studies (docs/integrators.md): 1.5 returned runs that Radau5 would have
/// finished cheaper, 5 kept runs that DP5 would have; 3 is the best of the
/// three.
pub(crate) const DEARER_BY: f64 = 3.0;

/// The implicit method's cost is compared every this many accepted steps
/// (after its start-up, the first Jacobian and a small first step, the
/// first time), each time over the latest [`COST_WINDOW`].
pub(crate) const TRIAL_STEPS: u64 = 2 * COST_WINDOW as u64;

/// RHS calls per unit of simulated time over the last `N` accepted steps
/// of a segment (`M` = N + 1 records: Rust cannot yet write N + 1 in a
/// const generic's use).
#[derive(Debug, Clone)]
pub(crate) struct CostWindow<const N: usize, const M: usize> {
    t: [f64; M],
    calls: [u64; M],
    next: usize,
    filled: usize,
}

/// The explicit method's window.
pub(crate) type StallWindow = CostWindow<STALL_WINDOW, { STALL_WINDOW + 1 }>;
/// The implicit method's window.
pub(crate) type TrialWindow = CostWindow<COST_WINDOW, { COST_WINDOW + 1 }>;

impl<const N: usize, const M: usize> CostWindow<N, M> {
    /// A window that starts at (t0, calls0).
    pub(crate) fn new(t0: f64, calls0: u64) -> Self {
        let mut w = CostWindow {
            t: [0.0; M],
            calls: [0; M],
            next: 0,
            filled: 0,
        };
        w.record(t0, calls0);
        w
    }

    /// The segment reached t having made `calls` RHS calls in all.
    pub(crate) fn record(&mut self, t: f64, calls: u64) {
        self.t[self.next] = t;
        self.calls[self.next] = calls;
        self.next = (self.next + 1) % M;
        self.filled = (self.filled + 1).min(M);
    }

    /// RHS calls per unit time from the oldest record kept to the newest;
    /// `None` before a full window or over no time.
    pub(crate) fn rate(&self) -> Option<f64> {
        if self.filled < M {
            return None;
        }
        let newest = (self.next + N) % M;
        let oldest = self.next;
        let dt = self.t[newest] - self.t[oldest];
        let calls = self.calls[newest] - self.calls[oldest];
        (dt > 0.0).then(|| calls as f64 / dt)
    }
}

/// The comparison a segment makes every [`TRIAL_STEPS`] accepted steps
/// against the method it took over from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CostTrial {
    /// The other method's RHS calls per unit time when it was left.
    pub(crate) rival_rate: f64,
    /// How much dearer this segment must be to stop.
    pub(crate) margin: f64,
}

impl CostTrial {
    /// This segment's cost rate over the rival's, when it is more than the
    /// margin: the run should change method.
    pub(crate) fn dearer(&self, rate: f64) -> Option<f64> {
        let ratio = rate / self.rival_rate;
        (ratio > self.margin).then_some(ratio)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_measures_the_latest_steps_only() {
        let mut w = TrialWindow::new(0.0, 0);
        // A dear start (100 calls per step of 0.1), then 6 calls per 0.1.
        for k in 1..=10u64 {
            w.record(0.1 * k as f64, 100 * k);
        }
        assert_eq!(w.rate(), None, "not a full window yet");
        let mut calls = 1000;
        for k in 11..=10 + COST_WINDOW as u64 {
            calls += 6;
            w.record(0.1 * k as f64, calls);
        }
        let rate = w.rate().expect("a full window");
        assert!((rate - 60.0).abs() < 1e-9, "{rate}");
    }

    #[test]
    fn only_a_clearly_dearer_implicit_method_sends_the_run_back() {
        let trial = CostTrial {
            rival_rate: 60.0,
            margin: DEARER_BY,
        };
        assert_eq!(trial.dearer(120.0), None);
        assert_eq!(trial.dearer(180.0), None);
        assert_eq!(trial.dearer(240.0), Some(4.0));
    }
}
