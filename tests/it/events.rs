//! Events of a hybrid system (`integrate::events`): the driver finds each
//! zero crossing on the dense output, lets the system act there, and
//! restarts the method; checked against closed-form event times with every
//! method.

use autobal::integrate::{
    EventFlow, Events, Method, NoObserver, OdeSystem, SolverOptions, Status, solve,
};
use std::cell::RefCell;

/// A ball dropped from height H under gravity g onto a floor, bouncing with
/// restitution e; the floor's events are recorded.
struct BouncingBall {
    g: f64,
    e: f64,
    bounces: RefCell<Vec<f64>>,
    stop_after: usize,
}

impl OdeSystem for BouncingBall {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -self.g;
    }
    fn events(&self) -> Option<&dyn Events> {
        Some(self)
    }
}

impl Events for BouncingBall {
    fn count(&self) -> usize {
        1
    }
    fn values(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = y[0];
    }
    fn handle(&self, t: f64, y: &mut [f64], _k: usize, falling: bool) -> EventFlow {
        assert!(falling, "the ball reaches the floor from above");
        // Lands exactly on the floor, its velocity reversed and reduced.
        y[0] = 0.0;
        y[1] *= -self.e;
        let mut b = self.bounces.borrow_mut();
        b.push(t);
        if b.len() >= self.stop_after {
            EventFlow::Stop
        } else {
            EventFlow::Continue
        }
    }
}

/// Bounce k (from 1) of a ball dropped from rest at height h: the first at
/// √(2h/g), then each flight 2·e^j·v₁/g with v₁ = √(2gh).
fn bounce_time(h: f64, g: f64, e: f64, k: usize) -> f64 {
    let v1 = (2.0 * g * h).sqrt();
    let mut t = v1 / g;
    for j in 1..k {
        t += 2.0 * e.powi(j as i32) * v1 / g;
    }
    t
}

#[test]
fn every_method_finds_the_bounces_of_a_ball_to_its_tolerance() {
    let (h, g, e) = (1.0, 9.81, 0.8);
    for &method in Method::ALL {
        let ball = BouncingBall {
            g,
            e,
            bounces: RefCell::new(Vec::new()),
            stop_after: 6,
        };
        let options = SolverOptions {
            rtol: 1e-10,
            atol: vec![1e-12],
            ..SolverOptions::default()
        };
        let report = solve(
            method,
            &ball,
            0.0,
            &[h, 0.0],
            100.0,
            &options,
            &mut NoObserver,
        );
        assert_eq!(report.status, Status::Stopped, "{method:?}: {report:?}");
        let bounces = ball.bounces.borrow();
        assert_eq!(bounces.len(), 6, "{method:?}");
        for (k, &t) in bounces.iter().enumerate() {
            let want = bounce_time(h, g, e, k + 1);
            // Free flight is a parabola: every method integrates it exactly,
            // so the error is the root search's and the interpolant's.
            assert!(
                (t - want).abs() < 1e-9,
                "{method:?} bounce {}: {t} vs {want}",
                k + 1
            );
        }
        // The run ends at the last bounce, on the floor, going up.
        assert_eq!(report.t, bounces[5]);
        assert!(report.y[0] == 0.0 && report.y[1] > 0.0, "{:?}", report.y);
    }
}

/// x'' = −x from x = 1: x crosses zero at π/2 + jπ, alternately falling
/// and rising; the run goes on through each crossing unchanged.
struct Oscillator {
    crossings: RefCell<Vec<(f64, bool)>>,
}

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -y[0];
    }
    fn events(&self) -> Option<&dyn Events> {
        Some(self)
    }
}

impl Events for Oscillator {
    fn count(&self) -> usize {
        1
    }
    fn values(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = y[0];
    }
    fn handle(&self, t: f64, _y: &mut [f64], _k: usize, falling: bool) -> EventFlow {
        self.crossings.borrow_mut().push((t, falling));
        EventFlow::Continue
    }
}

#[test]
fn an_event_that_changes_nothing_leaves_the_solution_on_its_course() {
    for &method in Method::ALL {
        let osc = Oscillator {
            crossings: RefCell::new(Vec::new()),
        };
        let options = SolverOptions {
            rtol: 1e-10,
            atol: vec![1e-12],
            ..SolverOptions::default()
        };
        let t_end = 20.0;
        let report = solve(
            method,
            &osc,
            0.0,
            &[1.0, 0.0],
            t_end,
            &options,
            &mut NoObserver,
        );
        assert_eq!(report.status, Status::Finished, "{method:?}");
        let crossings = osc.crossings.borrow();
        // π/2 + jπ < 20 for j = 0 … 5.
        assert_eq!(crossings.len(), 6, "{method:?}: {crossings:?}");
        for (j, &(t, falling)) in crossings.iter().enumerate() {
            let want = std::f64::consts::FRAC_PI_2 + j as f64 * std::f64::consts::PI;
            assert!((t - want).abs() < 1e-8, "{method:?} crossing {j}: {t}");
            assert_eq!(falling, j % 2 == 0, "{method:?} crossing {j}");
        }
        assert!(
            (report.y[0] - t_end.cos()).abs() < 1e-7,
            "{method:?}: {:?}",
            report.y
        );
    }
}
