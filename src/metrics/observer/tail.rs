//! The certified tail: once the run is deep inside the band, the rest of
//! the hold window is predicted on the tracked linearised flow and the run
//! ends early when the prediction is certified (docs/metrics.md).

use super::*;

/// The samples first..=last of a hold window predicted on a tracked flow:
/// reused, from a later sample on, while the same flow keeps tracking.
#[derive(Debug)]
pub(super) struct TailPlan {
    pub(super) check: u32,
    pub(super) first: u64,
    pub(super) last: u64,
    pub(super) r: Vec<f64>,
}

/// Every pair of weights must stay this far (rad) from the touching angle,
/// apart or in contact, for the flow to be linearised: beyond the central
/// differences' step in an angle, 1e-9 × max(1, |ψ|) (≤ 6.3e-9 within a
/// turn; for angles far beyond, the tracking check still guards).
pub(super) const CONTACT_MARGIN: f64 = 2.5e-8;

/// With rigid contact, the predicted state is checked clear of touches and
/// partings on every this many samples: each check is a right-hand side
/// (a link's torque), and the torques move as slowly as ε deep in the band.
const EVENT_CHECK_STRIDE: usize = 4 * TAIL_CHECK_STRIDE;

/// With rigid contact, linked weights sit at their touching angle to
/// rounding: the predicted closest approach may differ from the run's by
/// this much (rad) and still be the same approach.
const LINKED_GAP_ROUNDING: f64 = 1e-12;

/// After a prediction that fails (ε or the gaps), the next try comes this
/// many revolutions later.
const REPLAN_REVS: f64 = 3.0;

/// On the affine flow, ε and the gaps are checked on every this many samples
/// (they move slowly next to r, which is checked on every sample).
const TAIL_CHECK_STRIDE: usize = 4;

/// Tracking starts once r has stayed below this fraction of the band for a
/// revolution: deep enough inside for the linearisation to hold.
pub(super) const READY_FRACTION: f64 = 0.2;

impl SettlingObserver<'_> {
    /// The part that, inside the band, tracks the linearised flow and ends
    /// the run when it certifies the rest of the hold window.
    pub(super) fn certify_tail(&mut self, s: &mut Sample) -> Flow {
        if self.certifier.is_none() {
            return Flow::Continue;
        }
        let Some(start) = self.r_hold.stretch_start else {
            return Flow::Continue;
        };
        let t = s.t;
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
                certifier.observe(t, &self.scratch, s.r / self.a_ref, Some(start), ready)
        {
            return self.end_on_flow(&tracked);
        }
        Flow::Continue
    }

    /// The run has tracked a flow up to this sample: if the flow bounds the
    /// rest of the hold window (see [`super::certify`]), take its samples
    /// for the rest and stop; otherwise go on integrating, and tell the
    /// certifier when the bound is likely to hold.
    pub(super) fn end_on_flow(&mut self, tracked: &Tracked) -> Flow {
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
    pub(super) fn plan_tail(&self, tracked: &Tracked, first: u64, last: u64) -> Option<TailPlan> {
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
        let mut state = vec![0.0; if self.events.is_some() { dim } else { lay.nq() }];
        let mut r = Vec::with_capacity(count);
        flow.lift(&self.scratch, &mut x);
        for k in 0..count {
            flow.advance(&mut x, &mut tmp);
            let checked = k % TAIL_CHECK_STRIDE == 0 || k + 1 == count;
            let events_checked =
                self.events.is_some() && (k % EVENT_CHECK_STRIDE == 0 || k + 1 == count);
            // r needs the rotor's coordinates only; the angles, when
            // checked; the whole state, for the events.
            let needed = if events_checked {
                dim
            } else if checked {
                lay.nq()
            } else {
                lay.head()
            };
            flow.lower(&x, &mut state[..needed]);
            if let Some(events) = self.events
                && events_checked
                && !events.clear(self.sample_time(first + k as u64), &state)
            {
                return None;
            }
            r.push(self.whirl(&state));
            if checked {
                let angles = &state[psi.clone()];
                if !inside(self.balancing.error(system, angles), eps_limit) {
                    return None;
                }
                // A contact that opens or closes would change the flow, and
                // the closest approach so far must stay the run's.
                // With rigid contact the events decide the first (above).
                let same = self.events.is_some()
                    || self.gap.as_ref().is_none_or(|g| {
                        g.same_contacts(&self.scratch[psi.clone()], angles, CONTACT_MARGIN)
                    });
                let slack = if self.events.is_some() {
                    LINKED_GAP_ROUNDING
                } else {
                    0.0
                };
                if let Some(g) = &self.gap
                    && !(same && g.min_gap(angles) >= self.closest.smallest() - slack)
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
}
