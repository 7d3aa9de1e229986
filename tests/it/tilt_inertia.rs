//! The weights' tilt inertia (the m R² terms, issue 19 item 6): four weights
//! spread evenly round a plane at the centre of mass and held by heavy drag
//! must act as a rigid ring, i.e. add n m to the mass, n m l²/2 to the
//! transverse and n m l² to the polar moment of inertia (src/model/tilt_inertia.rs).
//! Compared eigenvalue by eigenvalue in the linear analysis at ω = 0.5,
//! 1.3 and 3: with the terms the worst relative miss is 7·10⁻⁹ – 3·10⁻⁷,
//! without them 2 – 31 % (the tilt modes).

use autobal::model::cargo::Cargo;
use autobal::model::effect::Effects;
use autobal::model::linear::analyse;
use autobal::model::rotor::{RotorModel, TwoSupportRotor};
use autobal::model::scene::Scene;
use autobal::model::speed::SpeedLaw;

const N: usize = 4;
const MASS: f64 = 0.02;
const L: f64 = 1.0;

fn rotor(extra_mass: f64, extra_a: f64, extra_c: f64, tilt_terms: bool) -> RotorModel {
    TwoSupportRotor {
        mass: 1.0 + extra_mass,
        transverse_inertia: 1.0 + extra_a,
        polar_inertia: 0.6 + extra_c,
        k1: 1.0,
        l1: 1.0,
        k2: 1.5,
        l2: 0.8,
        b1: 0.05,
        b2: 0.05,
        k1y: None,
        k2y: None,
        b1y: None,
        b2y: None,
        planes: vec![0.0],
        static_unbalance: 0.0,
        static_angle: 0.0,
        moment_unbalance: 0.0,
        moment_angle: 0.0,
        unbalances: Vec::new(),
        weights_tilt_inertia: tilt_terms,
    }
    .into()
}

fn eigenvalues(rotor: RotorModel, cargo: Vec<Cargo>, omega: f64) -> Vec<(f64, f64)> {
    let n = cargo.len();
    let scene = Scene {
        rotor,
        balancer: None,
        balancers: Vec::new(),
        cargo,
        speed: SpeedLaw::Constant { omega },
        effects: Effects::default(),
    };
    let evenly: Vec<f64> = (0..n)
        .map(|j| 2.0 * std::f64::consts::PI * j as f64 / n as f64)
        .collect();
    let report = analyse(
        &scene.build().expect("valid"),
        (n > 0).then_some(&evenly[..]),
    )
    .expect("a balanced state");
    report.eigenvalues
}

/// Largest relative distance from each rigid-ring eigenvalue to the nearest
/// eigenvalue of the rotor with its weights.
fn worst_miss(rigid: &[(f64, f64)], with_weights: &[(f64, f64)]) -> f64 {
    rigid
        .iter()
        .map(|&(re, im)| {
            let size = re.hypot(im);
            with_weights
                .iter()
                .map(|&(a, b)| (a - re).hypot(b - im) / size)
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

#[test]
fn evenly_spread_weights_held_by_drag_act_as_a_rigid_ring() {
    let ring = N as f64 * MASS;
    // Heavy drag: the weights' own modes decay at β/(κ m) ≈ 5·10⁶ 1/s and
    // their relative motion in the rotor modes is of order 1/β.
    let weights = || vec![Cargo::point(MASS, L, 1e5, 1.0); N];
    for omega in [0.5, 1.3, 3.0] {
        // A scene needs a weight: a 10⁻¹² one, whose own modes are set aside.
        let rigid: Vec<_> = eigenvalues(
            rotor(ring, ring * L * L / 2.0, ring * L * L, false),
            vec![Cargo::point(1e-12, L, 1e-7, 1.0)],
            omega,
        )
        .into_iter()
        .filter(|(re, im)| (1e-3..1e3).contains(&re.hypot(*im)))
        .collect();
        assert_eq!(rigid.len(), 8, "{rigid:?}");
        let with_terms = eigenvalues(rotor(0.0, 0.0, 0.0, true), weights(), omega);
        let without = eigenvalues(rotor(0.0, 0.0, 0.0, false), weights(), omega);
        let (hit, miss) = (
            worst_miss(&rigid, &with_terms),
            worst_miss(&rigid, &without),
        );
        assert!(
            hit < 1e-4,
            "ω = {omega}: with the terms the rotor modes miss by {hit:.2e}"
        );
        assert!(miss > 3e-3, "ω = {omega}: without them only by {miss:.2e}");
    }
}

#[test]
fn a_motor_driven_rotor_refuses_the_terms_naming_the_key() {
    let scene = Scene {
        rotor: rotor(0.0, 0.0, 0.0, true),
        balancer: None,
        balancers: Vec::new(),
        cargo: vec![Cargo::point(MASS, L, 1.0, 1.0); 3],
        speed: SpeedLaw::Motor {
            stall_torque: 1.0,
            omega_sync: 2.0,
            omega_start: 0.0,
        },
        effects: Effects::default(),
    };
    let message = scene.validate().expect_err("refused").to_string();
    assert!(message.contains("rotor.weights_tilt_inertia"), "{message}");
}
