//! Energy and angular momentum are conserved when nothing dissipates or drives.

use autobal::integrate::{
    Flow, Method, OdeSystem, SolverOptions, Status, Step, StepObserver, solve,
};
use autobal::model::balancer::{Geometry, Kind, cargoes};
use autobal::model::cargo::Cargo;
use autobal::model::invariants::{angular_momentum, energy};
use autobal::model::rotor::PlaneRotor;
use autobal::model::speed::SpeedLaw;
use autobal::model::system::RotorSystem;

/// Records the largest relative drift of energy and angular momentum.
struct Drift<'a> {
    system: &'a RotorSystem,
    e0: f64,
    l0: f64,
    worst_e: f64,
    worst_l: f64,
}

impl StepObserver for Drift<'_> {
    fn step(&mut self, step: &Step<'_>) -> Flow {
        let e = energy(self.system, step.t, step.y, 0.0);
        let l = angular_momentum(self.system, step.t, step.y);
        self.worst_e = self.worst_e.max(((e - self.e0) / self.e0).abs());
        self.worst_l = self.worst_l.max(((l - self.l0) / self.l0).abs());
        Flow::Continue
    }
}

fn check_conservation(system: &RotorSystem, y0: &[f64], rtol: f64) -> (f64, f64) {
    let e0 = energy(system, 0.0, y0, 0.0);
    let l0 = angular_momentum(system, 0.0, y0);
    let mut drift = Drift {
        system,
        e0,
        l0,
        worst_e: 0.0,
        worst_l: 0.0,
    };
    let options = SolverOptions {
        rtol,
        atol: vec![rtol * 1e-3],
        ..SolverOptions::default()
    };
    let report = solve(Method::Dp5, system, 0.0, y0, 200.0, &options, &mut drift);
    assert_eq!(report.status, Status::Finished);
    (drift.worst_e, drift.worst_l)
}

fn free_rotor() -> PlaneRotor {
    let mut rotor = PlaneRotor::isotropic(1.0, 0.05, 1.0, 0.0);
    rotor.inertia = 0.3;
    rotor.unbalance_angle = 0.4;
    rotor
}

fn perturbed_state(system: &RotorSystem) -> Vec<f64> {
    let lay = system.layout();
    let nq = lay.nq();
    let mut y = vec![0.0; system.dim()];
    y[0] = 0.02;
    y[1] = -0.01;
    y[nq] = 0.03;
    y[nq + 1] = 0.05;
    y[nq + lay.phi()] = 3.0;
    for j in 0..lay.cargoes {
        y[lay.psi(j)] = 1.1 * j as f64;
        y[nq + lay.psi(j)] = 0.2 - 0.15 * j as f64;
    }
    y
}

#[test]
fn pendulum_like_cargoes_conserve_energy_and_momentum() {
    let cargo = vec![
        Cargo::point(0.02, 0.5, 0.0, 1.2),
        Cargo::point(0.03, 0.4, 0.0, 1.05),
        Cargo::point(0.01, 0.6, 0.0, 1.4),
    ];
    let system = RotorSystem::new(
        Box::new(free_rotor()),
        cargo,
        SpeedLaw::Free { omega_start: 3.0 },
        vec![],
    );
    let y0 = perturbed_state(&system);
    let (de, dl) = check_conservation(&system, &y0, 1e-10);
    assert!(
        de < 1e-7 && dl < 1e-7,
        "energy drift {de:e}, momentum drift {dl:e}"
    );
}

#[test]
fn rolling_balls_conserve_energy_and_momentum() {
    let geometry = Geometry {
        race_radius: 0.5,
        rho: 0.2,
        density: 100.0,
        roller_height: 0.0,
        drag: 0.0,
    };
    for kind in [Kind::Ball, Kind::Roller] {
        let mut g = geometry;
        g.roller_height = 0.1;
        let cargo = cargoes(kind, 3, &g).unwrap();
        let system = RotorSystem::new(
            Box::new(free_rotor()),
            cargo,
            SpeedLaw::Free { omega_start: 3.0 },
            vec![],
        );
        let y0 = perturbed_state(&system);
        let (de, dl) = check_conservation(&system, &y0, 1e-10);
        assert!(
            de < 1e-7 && dl < 1e-7,
            "{kind}: energy drift {de:e}, momentum drift {dl:e}"
        );
    }
}

#[test]
fn dropping_the_rolling_coupling_breaks_conservation() {
    // The conservation check must be able to fail: remove the rolling terms
    // from the equations but not from the invariants and the drift shows.
    let g = Geometry {
        race_radius: 0.5,
        rho: 0.2,
        density: 100.0,
        roller_height: 0.0,
        drag: 0.0,
    };
    let mut cargo = cargoes(Kind::Ball, 3, &g).unwrap();
    let system_ok = RotorSystem::new(
        Box::new(free_rotor()),
        cargo.clone(),
        SpeedLaw::Free { omega_start: 3.0 },
        vec![],
    );
    let y0 = perturbed_state(&system_ok);
    for c in &mut cargo {
        c.rolling_coupling *= 0.5;
    }
    let broken = RotorSystem::new(
        Box::new(free_rotor()),
        cargo,
        SpeedLaw::Free { omega_start: 3.0 },
        vec![],
    );
    let e0 = energy(&system_ok, 0.0, &y0, 0.0);
    let options = SolverOptions {
        rtol: 1e-10,
        atol: vec![1e-13],
        ..SolverOptions::default()
    };
    let report = solve(
        Method::Dp5,
        &broken,
        0.0,
        &y0,
        50.0,
        &options,
        &mut autobal::integrate::NoObserver,
    );
    let e1 = energy(&system_ok, report.t, &report.y, 0.0);
    assert!(
        ((e1 - e0) / e0).abs() > 1e-6,
        "a wrong model must show drift: {}",
        (e1 - e0) / e0
    );
}
