//! The one step loop every method runs in: step budget and step-size floor,
//! the end of the interval, acceptance bookkeeping, the observer's dense
//! output and early stop, and stiffness detection with the switch to the
//! implicit method. A [`Stepper`] supplies only the method itself.

use super::cost::{CostTrial, StallWindow, TRIAL_STEPS, TrialWindow};
use super::events::{
    EventFlow, crossed, first_root, lowest, may_dip, may_dip_unevenly, scan_for_dip,
};
use super::norm::check_step;
use super::stepper::{Stepper, Trial};
use super::stiffness::{StiffnessWatch, Verdict};
use super::{
    Failure, Flow, OdeSystem, SolveReport, SolverOptions, Stats, Status, Step, StepObserver,
    Stiffness,
};

/// Attempts between two looks at the wall clock.
const WALL_CHECK_EVERY: u64 = 256;

/// Run `St` from (t0, y0) towards t_end until it finishes, the observer
/// stops it or it fails. The observer's `start` is the caller's business, so
/// that a run can continue in a second segment with another stepper. With a
/// `trial`, the segment stops with [`Failure::Dearer`] when it proves
/// dearer than the method it took over from.
#[allow(clippy::too_many_arguments)]
pub(super) fn drive<St, S, O>(
    system: &S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    options: &SolverOptions,
    deadline: Option<std::time::Instant>,
    observer: &mut O,
    trial: Option<CostTrial>,
) -> SolveReport
where
    St: Stepper,
    S: OdeSystem + ?Sized,
    O: StepObserver + ?Sized,
{
    let mut stepper = St::new(y0.len(), options);
    let mut stats = Stats::default();
    let mut y = y0.to_vec();
    let h_max = options.h_max.min(t_end - t0);
    let watch_stiffness = options.stiffness.is_watched();
    // Only a segment that may hand over reports its cost rate.
    let measure_stall = options.stiffness == Stiffness::SwitchToImplicit;
    let mut window = StallWindow::new(t0, 0);
    let mut trial_window = TrialWindow::new(t0, 0);
    let report = |status, t, y, stats, window: &StallWindow| SolveReport {
        status,
        t,
        y,
        stats,
        switched: None,
        cost_rate: window.rate(),
    };

    let mut h = match stepper.start(system, t0, &y, h_max, &mut stats) {
        Ok(h) => h.min(h_max),
        Err(f) => return report(Status::Failed(f), t0, y, stats, &window),
    };
    let mut t = t0;
    let mut last_rejected = false;
    let mut watch = StiffnessWatch::new(St::STIFF_BOUND);
    // The events' values at the current point, a step's end, and scratch.
    let events = system.events();
    let n_events = events.map_or(0, |e| e.count());
    let (mut g_now, mut g_end) = (vec![0.0; n_events], vec![0.0; n_events]);
    let mut probe = vec![0.0; if n_events > 0 { y.len() } else { 0 }];
    // Their rates at the current point and a step's end, where cheap.
    let (mut r_now, mut r_end) = (vec![0.0; n_events], vec![0.0; n_events]);
    let mut has_rates = false;
    if let Some(ev) = events {
        ev.values(t, &y, &mut g_now);
        has_rates = ev.rates(t, &y, &mut r_now);
    }

    loop {
        if let Err(f) = check_step(t, h, &stats, options) {
            return report(Status::Failed(f), t, y, stats, &window);
        }
        // The clock is read every WALL_CHECK_EVERY attempts: a few ns per step.
        if let Some(deadline) = deadline
            && (stats.steps + stats.rejected).is_multiple_of(WALL_CHECK_EVERY)
            && std::time::Instant::now() > deadline
        {
            let limit_s = options.max_wall.map_or(0.0, |d| d.as_secs_f64());
            let f = Failure::WallTimeExceeded { t, limit_s };
            return report(Status::Failed(f), t, y, stats, &window);
        }
        let last = t + stepper.end_stretch() * h >= t_end;
        if last {
            h = t_end - t;
        }
        let h_new = match stepper.attempt(system, t, &y, h, &mut stats) {
            Trial::Failed(f) => return report(Status::Failed(f), t, y, stats, &window),
            Trial::Rejected { h_new } => {
                stats.rejected += 1;
                h = h_new;
                last_rejected = true;
                continue;
            }
            Trial::Accepted { h_new } => h_new,
        };
        stats.steps += 1;
        if watch_stiffness {
            let mut verdict = watch.observe(stepper.stiffness_indicator(h));
            if verdict == Verdict::Check {
                let enough = watch.confirm_level();
                verdict = watch.checked(stepper.power_check(system, t + h, h, enough, &mut stats));
            }
            if verdict == Verdict::Stiff {
                let f = Failure::StiffnessDetected { t };
                return report(Status::Failed(f), t, y, stats, &window);
            }
        }
        let t_prev = t;
        let committed = stepper.accept(system, t, h, &mut y, &mut stats);
        t = t_prev + h;
        if let Err(f) = committed {
            return report(Status::Failed(f), t, y, stats, &window);
        }
        // Back onto the mode's constraints: an explicit method keeps them
        // to rounding and changes nothing here; an implicit one takes f at
        // the new point afresh in `advance`, and an explicit one that did
        // drift starts afresh (its last stage was at the old state).
        let projected = events.is_some_and(|ev| ev.project(t, &mut y));
        // An implicit method takes f at the new point before its next step
        // anyway: with events, take it now, so that functions reading the
        // derivative (a contact torque) find it instead of a call of their
        // own. Wasted only on the step that ends the run or meets an event.
        let advanced = St::IMPLICIT && events.is_some();
        if advanced && let Err(f) = stepper.advance(system, t, &y, &mut stats) {
            return report(Status::Failed(f), t, y, stats, &window);
        }
        // The earliest event within the step, if any: the step ends there.
        let mut event = None;
        if let Some(ev) = events {
            ev.values(t, &y, &mut g_end);
            if has_rates {
                ev.rates(t, &y, &mut r_end);
            }
            for k in 0..n_events {
                let dense = stepper.dense();
                let mut g_at = |s: f64| {
                    dense.eval(s, &mut probe);
                    ev.value(k, s, &probe)
                };
                // The far end of the bracket: the step's end, or the bottom
                // of a dip below zero inside it.
                let far = if crossed(g_now[k], g_end[k]) {
                    (t, g_end[k])
                } else if has_rates
                    && may_dip((g_now[k], g_end[k]), (r_now[k], r_end[k]), h)
                    && let (bottom, low) = lowest(&mut g_at, t_prev, t)
                    && low <= 0.0
                {
                    (bottom, low)
                } else if has_rates
                    && may_dip_unevenly((g_now[k], g_end[k]), (r_now[k], r_end[k]), h)
                    && let (bottom, low) = scan_for_dip(&mut g_at, t_prev, t)
                    && low <= 0.0
                {
                    (bottom, low)
                } else {
                    continue;
                };
                let at = first_root(g_at, (t_prev, g_now[k]), far);
                if event.is_none_or(|(first, _)| at < first) {
                    event = Some((at, k));
                }
            }
            if let Some((at, _)) = event {
                t = at;
                stepper.dense().eval(at, &mut y);
            }
        }
        let flow = observer.step(&Step {
            t_prev,
            t,
            y: &y,
            dense: stepper.dense(),
        });
        if measure_stall {
            window.record(t, stats.rhs_calls);
        }
        if trial.is_some() {
            trial_window.record(t, stats.rhs_calls);
        }
        if flow == Flow::Stop {
            return report(Status::Stopped, t, y, stats, &window);
        }
        if let (Some(ev), Some((_, k))) = (events, event) {
            // The system acts at the event; the method starts afresh from
            // the state it leaves (its history belongs to the old one).
            if ev.handle(t, &mut y, k, g_now[k] > 0.0) == EventFlow::Stop {
                return report(Status::Stopped, t, y, stats, &window);
            }
            ev.values(t, &y, &mut g_now);
            if has_rates {
                ev.rates(t, &y, &mut r_now);
            }
            h = match stepper.start(system, t, &y, h_max.min(t_end - t), &mut stats) {
                Ok(h0) => h0.min(h_max),
                Err(f) => return report(Status::Failed(f), t, y, stats, &window),
            };
            watch = StiffnessWatch::new(St::STIFF_BOUND);
            last_rejected = false;
            continue;
        }
        std::mem::swap(&mut g_now, &mut g_end);
        std::mem::swap(&mut r_now, &mut r_end);
        if last || t >= t_end {
            return report(Status::Finished, t, y, stats, &window);
        }
        if let Some(trial) = &trial
            && stats.steps.is_multiple_of(TRIAL_STEPS)
            && let Some(rate) = trial_window.rate()
            && let Some(ratio) = trial.dearer(rate)
        {
            let f = Failure::Dearer { t, rate, ratio };
            return report(Status::Failed(f), t, y, stats, &window);
        }
        if projected && !St::IMPLICIT {
            h = match stepper.start(system, t, &y, h_max.min(t_end - t), &mut stats) {
                Ok(h0) => h0.min(h_max),
                Err(f) => return report(Status::Failed(f), t, y, stats, &window),
            };
            last_rejected = false;
            continue;
        }
        if !advanced && let Err(f) = stepper.advance(system, t, &y, &mut stats) {
            return report(Status::Failed(f), t, y, stats, &window);
        }
        // A step right after a rejection does not grow (Hairer).
        let mut h_next = h_new.min(h_max);
        if last_rejected {
            h_next = h_next.min(h);
        }
        last_rejected = false;
        let reaches_end = t + stepper.end_stretch() * h_next >= t_end;
        h = stepper.next_step(h, h_next, reaches_end);
    }
}

/// Did an explicit segment stop in a way the implicit method can get past?
pub(super) fn stalled(status: &Status) -> bool {
    matches!(
        status,
        Status::Failed(
            Failure::StiffnessDetected { .. }
                | Failure::TooManySteps { .. }
                | Failure::StepSizeUnderflow { .. }
        )
    )
}
