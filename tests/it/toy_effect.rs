//! The recipe for a new effect, followed from outside the crate: a toy effect
//! written against the public [`Effect`] trait and added to built systems with
//! `with_effect`, checked against its closed-form solution.
//!
//! The toy is a constant external torque τ on every weight. Three equal
//! weights at 120° keep the total unbalance at zero while they move together,
//! so the rotor (with no unbalance of its own) stays at rest and each weight
//! at constant speed obeys I ψ̈ + β l² ψ̇ = τ, I = κ m l². From rest:
//!
//!   ψ̇(t) = (τ/c)(1 − e^{−ct/I}),  ψ(t) = ψ₀ + (τ/c)[t − (I/c)(1 − e^{−ct/I})],  c = β l².

use autobal::integrate::{Method, NoObserver, OdeSystem, SolverOptions, Status, solve};
use autobal::model::cargo::Cargo;
use autobal::model::effect::{Effect, EffectContext, Forces};
use autobal::model::frame::RotatingSystem;
use autobal::model::rotor::PlaneRotor;
use autobal::model::scene::Scene;
use autobal::model::speed::SpeedLaw;
use std::f64::consts::PI;

/// The toy: the same tangential torque on every weight.
#[derive(Debug)]
struct ConstantTorque(f64);

impl Effect for ConstantTorque {
    fn name(&self) -> &'static str {
        "constant_torque"
    }

    fn apply(&self, _ctx: &EffectContext<'_>, forces: &mut Forces<'_>) {
        for f in forces.cargo.iter_mut() {
            *f += self.0;
        }
    }
}

const TAU: f64 = 1e-4;
const MASS: f64 = 0.01;
const TRACK: f64 = 0.1;
const DRAG: f64 = 0.1;
const KAPPA: f64 = 1.4;

fn scene() -> Scene {
    Scene {
        rotor: PlaneRotor::isotropic(1.0, 0.0, 400.0, 2.0).into(),
        balancer: None,
        balancers: Vec::new(),
        cargo: vec![Cargo::point(MASS, TRACK, DRAG, KAPPA); 3],
        speed: SpeedLaw::Constant { omega: 10.0 },
        effects: Default::default(),
    }
}

/// Rotor at rest, weights at 0°, 120°, 240° and at rest relative to it.
fn start() -> Vec<f64> {
    let mut y = vec![0.0; 10];
    for j in 0..3 {
        y[2 + j] = 2.0 * PI * j as f64 / 3.0;
    }
    y
}

/// Relative angle and rate of a weight started at ψ₀ from rest, at time t.
fn exact(psi0: f64, t: f64) -> (f64, f64) {
    let inertia = KAPPA * MASS * TRACK * TRACK;
    let c = DRAG * TRACK * TRACK;
    let decay = (-c * t / inertia).exp();
    let rate = TAU / c * (1.0 - decay);
    let angle = psi0 + TAU / c * (t - inertia / c * (1.0 - decay));
    (angle, rate)
}

fn check_against_closed_form(system: &dyn OdeSystem, frame: &str) {
    let inertia = KAPPA * MASS * TRACK * TRACK;
    let y0 = start();
    // At the start only the torque acts on the weights: ψ̈ = τ/I.
    let mut dydt = vec![0.0; y0.len()];
    system.rhs(0.0, &y0, &mut dydt);
    for j in 0..3 {
        let accel = dydt[7 + j];
        assert!(
            (accel - TAU / inertia).abs() < 1e-12 * TAU / inertia,
            "{frame}: ψ̈_{j}(0) = {accel}, expected τ/I = {}",
            TAU / inertia
        );
    }
    let options = SolverOptions {
        rtol: 1e-11,
        atol: vec![1e-13],
        ..SolverOptions::default()
    };
    // About seven time constants I/(β l²) = 0.14 s: close to the terminal drift.
    let t_end = 1.0;
    let report = solve(
        Method::Dop853,
        system,
        0.0,
        &y0,
        t_end,
        &options,
        &mut NoObserver,
    );
    assert_eq!(report.status, Status::Finished, "{frame}");
    for j in 0..3 {
        let (angle, rate) = exact(y0[2 + j], t_end);
        let (got_angle, got_rate) = (report.y[2 + j], report.y[7 + j]);
        assert!(
            (got_rate - rate).abs() < 1e-9 * rate,
            "{frame}: ψ̇_{j} = {got_rate}, closed form {rate}"
        );
        assert!(
            (got_angle - angle).abs() < 1e-9,
            "{frame}: ψ_{j} = {got_angle}, closed form {angle}"
        );
    }
    // The rotor never moved: the weights kept their symmetric fan.
    for i in [0, 1, 5, 6] {
        assert!(
            report.y[i].abs() < 1e-12,
            "{frame}: rotor state {i} = {}",
            report.y[i]
        );
    }
}

#[test]
fn a_constant_torque_drives_each_weight_to_the_drag_limited_rate_in_both_frames() {
    let inertial = scene()
        .build()
        .unwrap()
        .with_effect(Box::new(ConstantTorque(TAU)));
    assert_eq!(inertial.effect_names(), ["drag", "constant_torque"]);
    check_against_closed_form(&inertial, "inertial");

    let rotating = RotatingSystem::new(&scene())
        .unwrap()
        .with_effect(Box::new(ConstantTorque(TAU)));
    check_against_closed_form(&rotating, "rotating");
}
