//! Steppers against problems with exact solutions.

use autobal::integrate::{
    DenseOutput, Flow, Method, NoObserver, OdeSystem, SolverOptions, Status, Step, StepObserver,
    solve,
};

/// y'' = −y as a first-order system; exact solution (cos t, −sin t).
struct Oscillator;

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -y[0];
    }
}

fn options(rtol: f64, atol: f64) -> SolverOptions {
    SolverOptions {
        rtol,
        atol: vec![atol],
        ..SolverOptions::default()
    }
}

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
struct DenseCheck {
    worst: f64,
}

impl StepObserver for DenseCheck {
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
    let mut check = DenseCheck { worst: 0.0 };
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
