//! Steppers against problems with exact solutions.
//!
//! Every test runs every method in [`Method::ALL`] unless it is about one
//! method's property; expectations that differ per method (order, counts)
//! are spelled out per method so that a new method must state its own.

use std::cell::Cell;

use crate::ode_problems::*;

use autobal::integrate::{
    DenseOutput, Failure, Flow, Method, NoObserver, OdeSystem, SolveReport, SolverOptions, Stats,
    Status, Step, StepObserver, solve,
};

/// The oscillator with its analytic Jacobian.
struct OscillatorWithJacobian;

impl OdeSystem for OscillatorWithJacobian {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        Oscillator.rhs(t, y, dydt);
    }
    fn jacobian(&self, _t: f64, _y: &[f64], jac: &mut [f64]) -> bool {
        jac.copy_from_slice(&[0.0, 1.0, -1.0, 0.0]);
        true
    }
}

/// y' = y², y(0) = 1: blows up at t = 1.
struct BlowUp;

impl OdeSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[0] * y[0];
    }
}

/// Robertson at t = 40 as published (Hairer & Wanner, Solving ODEs II,
/// section IV.10), to 10 digits.
const ROBERTSON_40: [f64; 3] = [0.715_827_068_7, 0.918_553_476_4e-5, 0.284_163_745_7];

fn options(rtol: f64, atol: f64) -> SolverOptions {
    SolverOptions {
        rtol,
        atol: vec![atol],
        ..SolverOptions::default()
    }
}

/// Tolerances so loose that every step is accepted and h stays at h_max:
/// a fixed-step run, for measuring the order of the formula itself.
fn fixed_step(h: f64) -> SolverOptions {
    SolverOptions {
        rtol: 1e6,
        atol: vec![1e6],
        h0: Some(h),
        h_max: h,
        ..SolverOptions::default()
    }
}

fn run<S: OdeSystem + ?Sized>(
    method: Method,
    system: &S,
    y0: &[f64],
    t_end: f64,
    o: &SolverOptions,
) -> SolveReport {
    let report = solve(method, system, 0.0, y0, t_end, o, &mut NoObserver);
    assert_eq!(report.status, Status::Finished, "{method:?}: {report:?}");
    assert_eq!(report.t, t_end, "{method:?}");
    report
}

/// Largest component error of `y` against `exact` at t.
fn error_at(exact: fn(f64, &mut [f64]), t: f64, y: &[f64]) -> f64 {
    let mut want = vec![0.0; y.len()];
    exact(t, &mut want);
    y.iter()
        .zip(&want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Checks the dense output of every step: against the exact solution inside
/// the step, and against the step's own states at both ends.
struct DenseCheck {
    exact: fn(f64, &mut [f64]),
    prev: Vec<f64>,
    /// Largest error against the exact solution at 19 interior points.
    interior: f64,
    /// Largest error of the state at the step's end points (global error).
    nodes: f64,
    /// Largest |dense(t_prev) − y(t_prev)| and |dense(t) − y(t)|, relative.
    ends: f64,
    steps: u64,
}

impl DenseCheck {
    fn new(exact: fn(f64, &mut [f64])) -> Self {
        DenseCheck {
            exact,
            prev: Vec::new(),
            interior: 0.0,
            nodes: 0.0,
            ends: 0.0,
            steps: 0,
        }
    }
}

impl StepObserver for DenseCheck {
    fn start(&mut self, _t0: f64, y0: &[f64]) {
        self.prev = y0.to_vec();
    }
    fn step(&mut self, step: &Step<'_>) -> Flow {
        let n = step.y.len();
        let mut y = vec![0.0; n];
        let rel = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .map(|(x, z)| (x - z).abs() / z.abs().max(1.0))
                .fold(0.0, f64::max)
        };
        step.dense.eval(step.t_prev, &mut y);
        self.ends = self.ends.max(rel(&y, &self.prev));
        step.dense.eval(step.t, &mut y);
        self.ends = self.ends.max(rel(&y, step.y));
        for i in 1..20 {
            let t = step.t_prev + (step.t - step.t_prev) * f64::from(i) / 20.0;
            step.dense.eval(t, &mut y);
            self.interior = self.interior.max(error_at(self.exact, t, &y));
        }
        self.nodes = self.nodes.max(error_at(self.exact, step.t, step.y));
        self.prev = step.y.to_vec();
        self.steps += 1;
        Flow::Continue
    }
}

#[test]
fn method_names_round_trip() {
    assert_eq!(Method::ALL.len(), 3);
    for &m in Method::ALL {
        assert_eq!(m.name().parse::<Method>(), Ok(m));
        let json = serde_json::to_string(&m).unwrap();
        assert_eq!(json, format!("\"{}\"", m.name()));
        assert_eq!(serde_json::from_str::<Method>(&json).unwrap(), m);
    }
    let err = "rk4".parse::<Method>().unwrap_err();
    assert!(err.to_string().contains("rk4") && err.to_string().contains("radau5"));
    assert_eq!(Method::default(), Method::Dp5);
}

/// Error at t_end on the oscillator and the forced problem must fall steadily
/// as the tolerance tightens, and stay within a small multiple of it.
#[test]
fn error_follows_the_tolerance() {
    for &m in Method::ALL {
        for p in &problems()[..2] {
            let reference = (p.reference)();
            let mut errors = Vec::new();
            for tol in [1e-4, 1e-6, 1e-8, 1e-10] {
                let report = run(m, p.system, p.y0, p.t_end, &options(tol, tol));
                errors.push(max_rel_error(&report.y, &reference, 1.0));
            }
            for w in errors.windows(2) {
                assert!(w[1] < w[0] / 10.0, "{m:?}, {}: {errors:?}", p.name);
            }
            assert!(errors[3] < 1e-8, "{m:?}, {}: {errors:?}", p.name);
        }
    }
}

/// Observed order of the adaptive runs on the oscillator: from rtol 1e-6 to
/// 1e-10, ln(error ratio) / ln(step-count ratio) must be the method's order.
#[test]
fn adaptive_runs_show_the_method_order() {
    for &m in Method::ALL {
        let p = match m {
            Method::Dp5 | Method::Radau5 => 5.0,
            Method::Dop853 => 8.0,
        };
        let [(e1, n1), (e2, n2)] = [1e-6, 1e-10].map(|tol| {
            let r = run(m, &Oscillator, &[1.0, 0.0], 20.0, &options(tol, tol));
            (error_at(oscillator_exact, 20.0, &r.y), r.stats.steps as f64)
        });
        let observed = (e1 / e2).ln() / (n2 / n1).ln();
        assert!((observed - p).abs() < 0.7, "{m:?}: order {observed}");
    }
}

/// Order of the formula with fixed steps: halving h divides the error by
/// 2^p. The oscillator shows the order cleanly; the time-dependent problem
/// catches a stage evaluated at the wrong time, which drops the order to 1 or
/// 2 there (its error constant is small, so it may look one order better).
/// Radau5 gets an exact Jacobian so that its single simplified Newton
/// iteration per step solves the linear stage equations exactly.
#[test]
fn fixed_step_order_matches_the_method() {
    let order =
        |errors: &[f64]| -> Vec<f64> { errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect() };
    for &m in Method::ALL {
        let (hs, p): (&[f64], f64) = match m {
            Method::Dp5 => (&[0.25, 0.125, 0.0625], 5.0),
            Method::Dop853 => (&[1.0, 0.5, 0.25], 8.0),
            Method::Radau5 => (&[0.5, 0.25, 0.125], 5.0),
        };
        let (mut osc, mut forced) = (Vec::new(), Vec::new());
        for &h in hs {
            let steps = (8.0 / h) as u64;
            let r = if m == Method::Radau5 {
                run(m, &OscillatorWithJacobian, &[1.0, 0.0], 8.0, &fixed_step(h))
            } else {
                run(m, &Oscillator, &[1.0, 0.0], 8.0, &fixed_step(h))
            };
            assert_eq!(r.stats.steps, steps, "{m:?}");
            osc.push(error_at(oscillator_exact, 8.0, &r.y));
            if m != Method::Radau5 {
                let r = run(m, &Forced, &[1.0], 8.0, &fixed_step(h));
                assert_eq!(r.stats.steps, steps, "{m:?}");
                forced.push(error_at(forced_exact, 8.0, &r.y));
            }
        }
        for q in order(&osc) {
            assert!((q - p).abs() < 0.3, "{m:?}: order {q} on {osc:?}");
        }
        for q in order(&forced) {
            assert!(q > p - 0.3 && q < p + 2.0, "{m:?}: order {q} on {forced:?}");
        }
    }
}

/// Order of the dense output with fixed steps: the worst interior error must
/// fall like h^(q+1) for dense-output order q (global error is of the same or
/// higher order), and the interpolant must reproduce both step ends.
#[test]
fn dense_output_order_and_end_points() {
    for &m in Method::ALL {
        let (hs, q): (&[f64], f64) = match m {
            Method::Dp5 => (&[0.25, 0.125, 0.0625], 4.0),
            Method::Dop853 => (&[0.5, 0.25, 0.125], 7.0),
            Method::Radau5 => (&[0.25, 0.125, 0.0625], 3.0),
        };
        let mut errors = Vec::new();
        for &h in hs {
            let mut check = DenseCheck::new(if m == Method::Radau5 {
                oscillator_exact
            } else {
                forced_exact
            });
            let report = if m == Method::Radau5 {
                solve(
                    m,
                    &OscillatorWithJacobian,
                    0.0,
                    &[1.0, 0.0],
                    8.0,
                    &fixed_step(h),
                    &mut check,
                )
            } else {
                solve(m, &Forced, 0.0, &[1.0], 8.0, &fixed_step(h), &mut check)
            };
            assert_eq!(report.status, Status::Finished);
            assert_eq!(check.steps, (8.0 / h) as u64);
            assert!(
                check.ends < 1e-14,
                "{m:?}: end points off by {}",
                check.ends
            );
            errors.push(check.interior);
        }
        for w in errors.windows(2) {
            let observed = (w[0] / w[1]).log2();
            assert!(
                observed > q + 0.5,
                "{m:?}: dense order {observed}, {errors:?}"
            );
        }
    }
}

/// Adaptive runs: dense output between steps is about as accurate as the
/// steps themselves, on the forced problem started at t0 = 1.5 (so that
/// mixing up t and t − t0 shows).
#[test]
fn dense_output_is_accurate_between_adaptive_steps() {
    for &m in Method::ALL {
        let mut check = DenseCheck::new(forced_exact);
        let (t0, t_end) = (1.5, 11.5);
        let y0 = exact(forced_exact, 1, t0);
        let tol = 1e-9;
        let report = solve(m, &Forced, t0, &y0, t_end, &options(tol, tol), &mut check);
        assert_eq!(report.status, Status::Finished);
        assert_eq!(report.t, t_end);
        assert!(check.ends < 1e-14, "{m:?}: {}", check.ends);
        assert!(check.nodes < 1e-7, "{m:?}: {}", check.nodes);
        // DOP853's interpolant is as good as its steps; DP5's is one order
        // below them; Radau5's cubic collocation polynomial is only as good
        // as its internal tolerance 0.1·rtol^(2/3) ≈ 1e-7, relative to |y| ≤ e.
        let bound = match m {
            Method::Dp5 => 20.0 * check.nodes.max(tol),
            Method::Dop853 => 2.0 * check.nodes.max(tol),
            Method::Radau5 => 3.0 * 0.1 * f64::powf(tol, 2.0 / 3.0),
        };
        assert!(
            check.interior < bound,
            "{m:?}: interior {} vs nodes {}",
            check.interior,
            check.nodes
        );
    }
}

/// Stops the run once t passes a limit.
struct StopAt(f64);

impl StepObserver for StopAt {
    fn step(&mut self, step: &Step<'_>) -> Flow {
        if step.t > self.0 {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }
}

#[test]
fn every_method_can_be_stopped_by_an_observer() {
    for &m in Method::ALL {
        let report = solve(
            m,
            &Oscillator,
            0.0,
            &[1.0, 0.0],
            100.0,
            &options(1e-6, 1e-6),
            &mut StopAt(5.0),
        );
        assert_eq!(report.status, Status::Stopped, "{m:?}");
        assert!(report.t > 5.0 && report.t < 10.0, "{m:?}: {}", report.t);
        assert!(
            error_at(oscillator_exact, report.t, &report.y) < 1e-4,
            "{m:?}"
        );
    }
}

#[test]
fn every_method_fails_cleanly_on_malformed_problems_and_budgets() {
    for &m in Method::ALL {
        let report = solve(
            m,
            &Oscillator,
            0.0,
            &[1.0],
            1.0,
            &options(1e-6, 1e-6),
            &mut NoObserver,
        );
        assert!(matches!(report.status, Status::Failed(Failure::Invalid(_))));
        for (h0, h_max) in [
            (Some(0.0), 1.0),
            (Some(-0.1), 1.0),
            (None, f64::NAN),
            (None, 0.0),
        ] {
            let o = SolverOptions {
                h0,
                h_max,
                ..options(1e-6, 1e-6)
            };
            let report = solve(m, &Oscillator, 0.0, &[1.0, 0.0], 1.0, &o, &mut NoObserver);
            assert!(
                matches!(report.status, Status::Failed(Failure::Invalid(_))),
                "{m:?}: h0 {h0:?}, h_max {h_max}: {report:?}"
            );
        }
        let mut bad = options(1e-6, 1e-6);
        bad.max_steps = 3;
        let report = solve(
            m,
            &Oscillator,
            0.0,
            &[1.0, 0.0],
            100.0,
            &bad,
            &mut NoObserver,
        );
        assert!(
            matches!(
                report.status,
                Status::Failed(Failure::TooManySteps { max: 3, .. })
            ),
            "{m:?}: {:?}",
            report.status
        );
        assert_eq!(report.stats.steps + report.stats.rejected, 3, "{m:?}");
        assert!(report.t > 0.0 && report.t < 100.0);
    }
}

/// y' = y² from 1 blows up at t = 1: every method must fail there, never
/// report success at t_end.
#[test]
fn blow_up_fails_at_the_singularity() {
    for &m in Method::ALL {
        let report = solve(
            m,
            &BlowUp,
            0.0,
            &[1.0],
            2.0,
            &options(1e-8, 1e-8),
            &mut NoObserver,
        );
        assert!(
            matches!(
                report.status,
                Status::Failed(
                    Failure::StepSizeUnderflow { .. }
                        | Failure::NonFinite { .. }
                        | Failure::NewtonFailure { .. }
                )
            ),
            "{m:?}: {:?}",
            report.status
        );
        // Adaptive steps follow the solution into the pole: the last state
        // is huge and its time within the tolerance of the true pole at 1 (the
        // numerical pole may lie a little past it).
        assert!((report.t - 1.0).abs() < 1e-6, "{m:?}: {report:?}");
        assert!(report.y[0] > 1e8, "{m:?}: {report:?}");
    }
}

/// A right-hand side that turns NaN is reported, not integrated through.
struct NanAfter(f64);

impl OdeSystem for NanAfter {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, t: f64, _y: &[f64], dydt: &mut [f64]) {
        dydt[0] = if t > self.0 { f64::NAN } else { 1.0 };
    }
}

#[test]
fn nan_right_hand_side_is_a_failure() {
    for &m in Method::ALL {
        let report = solve(
            m,
            &NanAfter(0.5),
            0.0,
            &[0.0],
            1.0,
            &options(1e-6, 1e-6),
            &mut NoObserver,
        );
        assert!(
            matches!(report.status, Status::Failed(_)),
            "{m:?}: {report:?}"
        );
        assert!(
            report.t <= 0.5 && report.y.iter().all(|v| v.is_finite()),
            "{m:?}: {report:?}"
        );
    }
}

/// The over-damped mode: Radau5 must be accurate and need far fewer steps
/// than the explicit methods, whose step is capped by stability (≈ 3.3/c).
#[test]
fn stiff_over_damped_mode_needs_few_implicit_steps() {
    let t_end = 1000.0;
    let o = options(1e-6, 1e-8);
    let implicit = run(Method::Radau5, &OVER_DAMPED, &[1.0, 0.0], t_end, &o);
    let explicit = run(Method::Dp5, &OVER_DAMPED, &[1.0, 0.0], t_end, &o);
    for r in [&implicit, &explicit] {
        let e = error_at(over_damped_exact, t_end, &r.y);
        assert!(e < 1e-6, "{e}: {r:?}");
    }
    let ratio = explicit.stats.steps as f64 / implicit.stats.steps as f64;
    assert!(
        ratio > 1000.0,
        "{ratio}: {:?} vs {:?}",
        explicit.stats,
        implicit.stats
    );
    assert!(
        explicit.stats.rhs_calls > 100 * implicit.stats.rhs_calls,
        "{:?} vs {:?}",
        explicit.stats,
        implicit.stats
    );
}

/// The driver's stiffness handling works for every explicit stepper: on the
/// over-damped mode (fast eigenvalue ≈ −1000), `Stop` ends the run with
/// `StiffnessDetected` early on, and `SwitchToImplicit` hands over to Radau5
/// and still meets the exact solution, at a small fraction of the explicit
/// method's work.
#[test]
fn every_explicit_stepper_detects_stiffness_and_hands_over() {
    use autobal::integrate::Stiffness;
    let t_end = 1000.0;
    for method in [Method::Dp5, Method::Dop853] {
        let stop = SolverOptions {
            stiffness: Stiffness::Stop,
            ..options(1e-6, 1e-8)
        };
        let stopped = solve(
            method,
            &OVER_DAMPED,
            0.0,
            &[1.0, 0.0],
            t_end,
            &stop,
            &mut NoObserver,
        );
        match stopped.status {
            Status::Failed(Failure::StiffnessDetected { t }) => {
                assert!(t < 1.0, "{method:?} noticed only at t = {t}")
            }
            ref other => panic!("{method:?}: {other:?}"),
        }
        assert!(stopped.switched.is_none());

        let switch = SolverOptions {
            stiffness: Stiffness::SwitchToImplicit,
            ..options(1e-6, 1e-8)
        };
        let handed = run(method, &OVER_DAMPED, &[1.0, 0.0], t_end, &switch);
        assert_eq!(handed.status, Status::Finished, "{method:?}");
        let e = error_at(over_damped_exact, t_end, &handed.y);
        assert!(e < 1e-6, "{method:?}: error {e}");
        let switch_info = handed.switched.as_ref().expect("a hand-over");
        assert_eq!(switch_info.from, method);
        assert!(matches!(switch_info.why, Failure::StiffnessDetected { .. }));
        // The totals include the explicit segment's work.
        assert!(handed.stats.steps > switch_info.before.steps);
        let crawling = run(
            method,
            &OVER_DAMPED,
            &[1.0, 0.0],
            t_end,
            &options(1e-6, 1e-8),
        );
        assert!(
            100 * handed.stats.rhs_calls < crawling.stats.rhs_calls,
            "{method:?}: {:?} vs {:?}",
            handed.stats,
            crawling.stats
        );
    }
}

/// Damping up to 1e12 over ten slow time constants: Radau5's step count
/// stays flat as the fast eigenvalue grows (L-stability), and the slow mode
/// stays within the absolute tolerance.
#[test]
fn radau5_handles_extreme_damping() {
    for c in [1e4, 1e8, 1e12] {
        let system = OverDamped(c);
        let t_end = 10.0 * c;
        let r = run(
            Method::Radau5,
            &system,
            &[1.0, 0.0],
            t_end,
            &options(1e-6, 1e-8),
        );
        let mut want = [0.0; 2];
        system.exact(t_end, &mut want);
        assert!(
            (r.y[0] - want[0]).abs() < 1e-8,
            "c = {c}: {r:?} vs {want:?}"
        );
        assert!(r.stats.steps + r.stats.rejected < 100, "c = {c}: {r:?}");
    }
}

/// Robertson to t = 40: Radau5 matches the published values and takes a
/// tiny fraction of DP5's steps.
#[test]
fn stiff_robertson_matches_reference_values() {
    let y0 = [1.0, 0.0, 0.0];
    let o = SolverOptions {
        rtol: 1e-8,
        atol: vec![1e-10, 1e-14, 1e-10],
        ..SolverOptions::default()
    };
    let implicit = run(Method::Radau5, &Robertson, &y0, 40.0, &o);
    let e = max_rel_error(&implicit.y, &ROBERTSON_40, 0.0);
    assert!(e < 1e-8, "{e}: {:?}", implicit.y);
    let explicit = run(Method::Dp5, &Robertson, &y0, 40.0, &o);
    let e = max_rel_error(&explicit.y, &ROBERTSON_40, 0.0);
    assert!(e < 1e-6, "{e}: {:?}", explicit.y);
    let ratio = explicit.stats.steps as f64 / implicit.stats.steps as f64;
    assert!(
        ratio > 100.0,
        "{ratio}: {:?} vs {:?}",
        explicit.stats,
        implicit.stats
    );
}

/// Counts how often the solver asks for the analytic Jacobian.
struct CountingJacobian(Cell<u64>);

impl OdeSystem for CountingJacobian {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        Oscillator.rhs(t, y, dydt);
    }
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) -> bool {
        self.0.set(self.0.get() + 1);
        OscillatorWithJacobian.jacobian(t, y, jac)
    }
}

/// Analytic and finite-difference Jacobians give the same Radau5 solution;
/// the analytic one is used whenever a Jacobian is due and saves the
/// difference quotients' RHS calls.
#[test]
fn radau5_uses_an_analytic_jacobian() {
    let o = options(1e-8, 1e-8);
    let fd = run(Method::Radau5, &Oscillator, &[1.0, 0.0], 20.0, &o);
    let system = CountingJacobian(Cell::new(0));
    let exact = run(Method::Radau5, &system, &[1.0, 0.0], 20.0, &o);
    assert!(exact.stats.jacobians > 0);
    assert_eq!(system.0.get(), exact.stats.jacobians);
    assert!(exact.stats.rhs_calls < fd.stats.rhs_calls);
    assert!((fd.y[0] - exact.y[0]).abs() < 1e-9 && (fd.y[1] - exact.y[1]).abs() < 1e-9);
    assert!(error_at(oscillator_exact, 20.0, &exact.y) < 1e-7);
}

/// Counts the right-hand-side calls of the wrapped system.
struct CountingRhs<'a, S: OdeSystem + ?Sized>(&'a S, Cell<u64>);

impl<S: OdeSystem + ?Sized> OdeSystem for CountingRhs<'_, S> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.1.set(self.1.get() + 1);
        self.0.rhs(t, y, dydt);
    }
}

/// `Stats::rhs_calls` counts every call, including DOP853's dense-output
/// stages and Radau5's finite-difference Jacobians, also on failed runs.
#[test]
fn rhs_calls_are_counted_exactly() {
    for &m in Method::ALL {
        let forced = CountingRhs(&Forced, Cell::new(0));
        let r = run(m, &forced, &[1.0], 10.0, &options(1e-7, 1e-7));
        assert_eq!(r.stats.rhs_calls, forced.1.get(), "{m:?}");
        let stiff = CountingRhs(&Robertson, Cell::new(0));
        let r = run(m, &stiff, &[1.0, 0.0, 0.0], 0.5, &options(1e-5, 1e-9));
        assert_eq!(r.stats.rhs_calls, stiff.1.get(), "{m:?}");
        let blow = CountingRhs(&BlowUp, Cell::new(0));
        let r = solve(
            m,
            &blow,
            0.0,
            &[1.0],
            2.0,
            &options(1e-6, 1e-6),
            &mut NoObserver,
        );
        assert!(matches!(r.status, Status::Failed(_)));
        assert_eq!(r.stats.rhs_calls, blow.1.get(), "{m:?}");
    }
}

/// Work of every method on fixed problems, pinned exactly: a change in the
/// step control or the cost accounting shows up here as a diff.
#[test]
fn work_counts_are_pinned() {
    let stats = |steps, rejected, rhs_calls, jacobians, factorizations| Stats {
        steps,
        rejected,
        rhs_calls,
        jacobians,
        factorizations,
    };
    for &m in Method::ALL {
        let want = match m {
            Method::Dp5 => stats(80, 0, 482, 0, 0),
            Method::Dop853 => stats(20, 0, 302, 0, 0),
            Method::Radau5 => stats(89, 0, 410, 1, 9),
        };
        let r = run(m, &Oscillator, &[1.0, 0.0], 20.0, &options(1e-6, 1e-6));
        assert_eq!(r.stats, want, "{m:?} on the oscillator");
    }
    let o = SolverOptions {
        rtol: 1e-6,
        atol: vec![1e-8, 1e-12, 1e-8],
        ..SolverOptions::default()
    };
    let r = run(Method::Radau5, &Robertson, &[1.0, 0.0, 0.0], 40.0, &o);
    assert_eq!(r.stats, stats(53, 2, 558, 44, 54), "Radau5 on Robertson");
}

// The original DP5 tests, kept as they were.

#[test]
fn dp5_error_shrinks_with_tolerance_on_the_oscillator() {
    let mut errors = Vec::new();
    for tol in [1e-4, 1e-6, 1e-8, 1e-10] {
        let report = solve(
            Method::Dp5,
            &Oscillator,
            0.0,
            &[1.0, 0.0],
            20.0,
            &options(tol, tol),
            &mut NoObserver,
        );
        assert_eq!(report.status, Status::Finished);
        assert_eq!(report.t, 20.0);
        let e = (report.y[0] - 20f64.cos())
            .abs()
            .max((report.y[1] + 20f64.sin()).abs());
        errors.push(e);
    }
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 10.0, "{errors:?}");
    }
    assert!(errors[3] < 1e-8, "{errors:?}");
}

/// Checks the dense output against the exact solution at 10 points per step.
struct Dp5DenseCheck {
    worst: f64,
}

impl StepObserver for Dp5DenseCheck {
    fn step(&mut self, step: &Step<'_>) -> Flow {
        let mut y = [0.0; 2];
        for i in 0..=10 {
            let t = step.t_prev + (step.t - step.t_prev) * f64::from(i) / 10.0;
            step.dense.eval(t, &mut y);
            self.worst = self.worst.max((y[0] - t.cos()).abs());
        }
        Flow::Continue
    }
}

#[test]
fn dp5_dense_output_is_accurate_between_steps() {
    let mut check = Dp5DenseCheck { worst: 0.0 };
    solve(
        Method::Dp5,
        &Oscillator,
        0.0,
        &[1.0, 0.0],
        10.0,
        &options(1e-9, 1e-9),
        &mut check,
    );
    assert!(check.worst < 1e-7, "{}", check.worst);
}

#[test]
fn observer_can_stop_a_run() {
    let report = solve(
        Method::Dp5,
        &Oscillator,
        0.0,
        &[1.0, 0.0],
        100.0,
        &options(1e-6, 1e-6),
        &mut StopAt(5.0),
    );
    assert_eq!(report.status, Status::Stopped);
    assert!(report.t > 5.0 && report.t < 10.0);
}

#[test]
fn malformed_problems_fail_cleanly() {
    let report = solve(
        Method::Dp5,
        &Oscillator,
        0.0,
        &[1.0],
        1.0,
        &options(1e-6, 1e-6),
        &mut NoObserver,
    );
    assert!(matches!(report.status, Status::Failed(_)));
    let mut bad = options(1e-6, 1e-6);
    bad.max_steps = 3;
    let report = solve(
        Method::Dp5,
        &Oscillator,
        0.0,
        &[1.0, 0.0],
        100.0,
        &bad,
        &mut NoObserver,
    );
    assert!(matches!(
        report.status,
        Status::Failed(autobal::integrate::Failure::TooManySteps { .. })
    ));
}

#[allow(dead_code)]
fn _dense_is_object_safe(d: &dyn DenseOutput) -> &dyn DenseOutput {
    d
}
