//! The rigid rotor on two elastic supports (seed 003): reduction to the plane
//! model, conservation laws, and balancing inside vs outside the criterion's
//! speed ranges.

use autobal::design::criterion::{resonances, static_ranges};
use autobal::integrate::{
    Flow, Method, NoObserver, OdeSystem, SolverOptions, Status, Step, StepObserver, solve,
};
use autobal::metrics::{MetricOptions, Outcome, RunMetrics};
use autobal::model::cargo::Cargo;
use autobal::model::effect::Effects;
use autobal::model::invariants::{angular_momentum, energy};
use autobal::model::rotor::two_support::PointUnbalance;
use autobal::model::rotor::{DofVec, MAX_DOF, PlaneRotor, Rotor, RotorModel, TwoSupportRotor};
use autobal::model::scene::Scene;
use autobal::model::speed::SpeedLaw;
use autobal::model::start::StartMode;
use autobal::model::system::RotorSystem;
use autobal::scene_file::SceneFile;
use autobal::simulation::{Simulation, SolverSettings};

use crate::fixtures::long_rotor;

fn balls(n: usize, mass: f64, drag: f64, plane: usize) -> Vec<Cargo> {
    (0..n)
        .map(|_| Cargo {
            plane,
            ..Cargo::point(mass, 1.0, drag, 1.4)
        })
        .collect()
}

fn simulation(rotor: RotorModel, cargo: Vec<Cargo>, omega: f64, angles_deg: &[f64]) -> Simulation {
    Simulation {
        scene: Scene {
            rotor,
            balancer: None,
            balancers: Vec::new(),
            cargo,
            speed: SpeedLaw::Constant { omega },
            effects: Effects::default(),
        },
        start: StartMode::LockedSteady,
        initial_angles: angles_deg.iter().map(|d| d.to_radians()).collect(),
        solver: SolverSettings::default(),
        metrics: MetricOptions {
            t_end_revs: 800.0,
            ..MetricOptions::default()
        },
    }
}

#[test]
fn tilt_locked_rotor_with_a_balancer_at_the_centre_of_mass_is_the_plane_rotor() {
    // k1 l1 = k2 l2 and b1 l1 = b2 l2 decouple translation from tilt; with a
    // static unbalance and the balancer plane at the centre of mass nothing
    // excites the tilt, which stays locked at zero.
    let spatial = TwoSupportRotor {
        mass: 1.0,
        transverse_inertia: 0.5,
        polar_inertia: 0.3,
        k1: 1.2,
        l1: 0.5,
        k2: 0.8,
        l2: 0.75,
        b1: 0.12,
        b2: 0.08,
        k1y: None,
        k2y: None,
        b1y: None,
        b2y: None,
        planes: vec![0.0],
        static_unbalance: 0.01,
        static_angle: 0.3,
        moment_unbalance: 0.0,
        moment_angle: 0.0,
        unbalances: Vec::new(),
        weights_tilt_inertia: false,
    };
    let mut plane = PlaneRotor::isotropic(1.0, 0.01, 2.0, 0.2);
    plane.unbalance_angle = 0.3;
    let start = [60.0, 120.0, 180.0];
    let run = |rotor: RotorModel| {
        simulation(rotor, balls(3, 0.01, 0.01, 0), 4.0, &start)
            .run(true)
            .unwrap()
    };
    let (a, b) = (run(plane.into()), run(spatial.into()));
    assert_eq!(a.metrics.outcome, Outcome::Settled, "{}", a.metrics.reason);
    assert_eq!(b.metrics.outcome, a.metrics.outcome);
    assert!((a.metrics.a_ref - b.metrics.a_ref).abs() < 1e-12 * a.metrics.a_ref);
    let (ta, tb) = (
        a.metrics.settling_time.unwrap(),
        b.metrics.settling_time.unwrap(),
    );
    assert!(
        (ta - tb).abs() <= a.metrics.settling_time_err,
        "{ta} vs {tb}"
    );
    crate::fixtures::assert_same_trajectory(&a, &b, 1e-4, "two-support against plane");
}

/// Records the largest relative drift of energy and angular momentum.
struct Drift<'a> {
    reference: &'a RotorSystem,
    e0: f64,
    l0: f64,
    worst_e: f64,
    worst_l: f64,
}

impl StepObserver for Drift<'_> {
    fn step(&mut self, step: &Step<'_>) -> Flow {
        let e = energy(self.reference, step.t, step.y, 0.0);
        let l = angular_momentum(self.reference, step.t, step.y);
        self.worst_e = self.worst_e.max(((e - self.e0) / self.e0).abs());
        self.worst_l = self.worst_l.max(((l - self.l0) / self.l0).abs());
        Flow::Continue
    }
}

/// An unbalanced rotor with coupled supports (k14 ≠ 0), no damping.
fn free_rotor() -> TwoSupportRotor {
    TwoSupportRotor {
        mass: 1.0,
        transverse_inertia: 0.6,
        polar_inertia: 0.9,
        k1: 1.0,
        l1: 0.4,
        k2: 1.7,
        l2: 0.7,
        b1: 0.0,
        b2: 0.0,
        k1y: None,
        k2y: None,
        b1y: None,
        b2y: None,
        planes: vec![-0.5, 0.6],
        static_unbalance: 0.03,
        static_angle: 0.2,
        moment_unbalance: 0.02,
        moment_angle: 1.9,
        unbalances: vec![PointUnbalance {
            s: 0.01,
            z: 0.3,
            angle: -0.7,
        }],
        weights_tilt_inertia: false,
    }
}

fn free_cargo() -> Vec<Cargo> {
    vec![
        Cargo {
            plane: 0,
            ..Cargo::point(0.02, 0.5, 0.0, 1.2)
        },
        Cargo {
            plane: 1,
            ..Cargo::point(0.03, 0.4, 0.0, 1.05)
        },
        Cargo {
            plane: 1,
            rolling_coupling: 0.002,
            rolling_inertia: 0.003,
            ..Cargo::point(0.01, 0.6, 0.0, 1.4)
        },
    ]
}

fn perturbed_state(system: &RotorSystem) -> Vec<f64> {
    let lay = system.layout();
    let nq = lay.nq();
    let mut y = vec![0.0; system.dim()];
    y[..4].copy_from_slice(&[0.02, -0.01, 0.03, -0.02]);
    y[nq..nq + 4].copy_from_slice(&[0.03, 0.05, -0.04, 0.06]);
    y[nq + lay.phi()] = 3.0;
    for j in 0..lay.cargoes {
        y[lay.psi(j)] = 1.1 * j as f64;
        y[nq + lay.psi(j)] = 0.2 - 0.15 * j as f64;
    }
    y
}

fn drift(reference: &RotorSystem, integrated: &RotorSystem, t_end: f64) -> (f64, f64) {
    let y0 = perturbed_state(reference);
    let mut d = Drift {
        reference,
        e0: energy(reference, 0.0, &y0, 0.0),
        l0: angular_momentum(reference, 0.0, &y0),
        worst_e: 0.0,
        worst_l: 0.0,
    };
    let options = SolverOptions {
        rtol: 1e-10,
        atol: vec![1e-13],
        ..SolverOptions::default()
    };
    let report = solve(Method::Dp5, integrated, 0.0, &y0, t_end, &options, &mut d);
    assert_eq!(report.status, Status::Finished);
    (d.worst_e, d.worst_l)
}

#[test]
fn energy_and_angular_momentum_are_conserved_without_dissipation() {
    let system = RotorSystem::new(
        Box::new(free_rotor()),
        free_cargo(),
        SpeedLaw::Free { omega_start: 3.0 },
        vec![],
    );
    let (de, dl) = drift(&system, &system, 150.0);
    assert!(
        de < 1e-7 && dl < 1e-7,
        "energy drift {de:e}, momentum drift {dl:e}"
    );
}

/// The spatial rotor with the gyroscopic φ̈ coupling left out: a wrong model.
#[derive(Debug)]
struct NoGyroCoupling(TwoSupportRotor);

impl Rotor for NoGyroCoupling {
    fn name(&self) -> &'static str {
        "broken"
    }
    fn dof(&self) -> usize {
        self.0.dof()
    }
    fn planes(&self) -> usize {
        self.0.planes()
    }
    fn plane_map(&self, plane: usize) -> [DofVec; 2] {
        self.0.plane_map(plane)
    }
    fn mass_matrix(&self) -> [DofVec; MAX_DOF] {
        self.0.mass_matrix()
    }
    fn spin_inertia(&self) -> f64 {
        self.0.spin_inertia()
    }
    fn forces(&self, q: &[f64], qd: &[f64], spin_rate: f64, f: &mut DofVec) {
        self.0.forces(q, qd, spin_rate, f)
    }
    fn spin_coupling(&self, phi: f64, _q: &[f64]) -> DofVec {
        self.0.spin_coupling(phi, &[0.0; MAX_DOF])
    }
    fn unbalance_forces(&self, phi: f64, spin_rate: f64, f: &mut DofVec) {
        self.0.unbalance_forces(phi, spin_rate, f)
    }
    fn static_unbalance(&self) -> (f64, f64) {
        self.0.static_unbalance()
    }
    fn own_unbalance(&self) -> f64 {
        self.0.own_unbalance()
    }
    fn unbalance_size(&self, f: &DofVec) -> f64 {
        self.0.unbalance_size(f)
    }
}

#[test]
fn dropping_the_gyroscopic_spin_coupling_breaks_conservation() {
    let speed = SpeedLaw::Free { omega_start: 3.0 };
    let ok = RotorSystem::new(Box::new(free_rotor()), free_cargo(), speed.clone(), vec![]);
    let broken = RotorSystem::new(
        Box::new(NoGyroCoupling(free_rotor())),
        free_cargo(),
        speed,
        vec![],
    );
    let (de, dl) = drift(&ok, &broken, 50.0);
    assert!(
        de > 1e-6 || dl > 1e-6,
        "a wrong model must show drift: {de:e}, {dl:e}"
    );
}

/// A single plane at z with the rotor's unbalance in that plane: the setting
/// of the criterion's elementary unbalances.
fn single_plane_run(z: f64, omega: f64) -> RunMetrics {
    let mut rotor = long_rotor(vec![z]);
    rotor.unbalances = vec![PointUnbalance {
        s: 0.01,
        z,
        angle: 0.0,
    }];
    let sim = simulation(
        rotor.into(),
        balls(2, 0.01, 0.01, 0),
        omega,
        &[100.0, 260.0],
    );
    sim.run(false).unwrap().metrics
}

#[test]
fn static_balancing_occurs_inside_the_criterions_ranges_and_not_outside() {
    let z = 1.0;
    let p = long_rotor(vec![z]).criterion_params();
    let r = resonances(&p).unwrap();
    let ranges = static_ranges(&p, z).unwrap();
    let (w1, wt, w2) = (ranges.0[0].0, ranges.0[0].1, r.omega2.unwrap());
    assert!((w1 - 2f64.sqrt()).abs() < 1e-12 && (w2 - 10f64.sqrt()).abs() < 1e-12);
    assert!((wt - (10.0f64 / 1.8).sqrt()).abs() < 1e-12);
    // Speeds well inside each interval (ω1 ≈ 1.41, ω̃ ≈ 2.36, ω2 ≈ 3.16).
    for omega in [0.5 * (w1 + wt), 2.0 * w2] {
        assert!(ranges.contains(omega));
        let m = single_plane_run(z, omega);
        assert_eq!(m.outcome, Outcome::Settled, "ω = {omega}: {}", m.reason);
        assert!(
            m.balancing_error < 0.05,
            "ω = {omega}: ε = {}",
            m.balancing_error
        );
    }
    for omega in [0.6 * w1, 0.5 * (wt + w2)] {
        assert!(!ranges.contains(omega));
        let m = single_plane_run(z, omega);
        assert_eq!(m.outcome, Outcome::Censored, "ω = {omega}: {}", m.reason);
        assert!(
            m.balancing_error > 1.0,
            "ω = {omega}: ε = {}",
            m.balancing_error
        );
    }
}

#[test]
fn two_planes_balance_dynamically_above_omega2_only() {
    // Static and moment unbalance, a two-ball balancer in each of two planes.
    let mut rotor = long_rotor(vec![-1.0, 1.0]);
    rotor.unbalances = vec![
        PointUnbalance {
            s: 0.012,
            z: -1.0,
            angle: 0.0,
        },
        PointUnbalance {
            s: 0.008,
            z: 1.0,
            angle: 2.0,
        },
    ];
    let w2 = 10f64.sqrt();
    let mut cargo = balls(2, 0.01, 0.01, 0);
    cargo.extend(balls(2, 0.01, 0.01, 1));
    let start = [100.0, 260.0, 80.0, 200.0];
    let fast = simulation(rotor.clone().into(), cargo.clone(), 2.0 * w2, &start)
        .run(false)
        .unwrap()
        .metrics;
    assert_eq!(fast.outcome, Outcome::Settled, "{}", fast.reason);
    assert!(fast.balancing_error < 0.05, "ε = {}", fast.balancing_error);
    // Between ω1 and ω2 two planes cannot balance (eq 31).
    let slow = simulation(rotor.into(), cargo, 2.0, &start)
        .run(false)
        .unwrap()
        .metrics;
    assert_eq!(slow.outcome, Outcome::Censored, "{}", slow.reason);
}

#[test]
fn scene_files_choose_the_rotor_model_and_place_balancers_in_planes() {
    let text = r#"
[rotor]
model = "two_support"
mass = 1.0
transverse_inertia = 1.0
polar_inertia = 0.2
k1 = 1.0
l1 = 2.0
k2 = 1.0
l2 = 2.0
b1 = 0.05
b2 = 0.05
planes = [-1.0, 1.0]
[[rotor.unbalances]]
s = 0.01
z = -1.0
[[rotor.unbalances]]
s = 0.01
z = 1.0
angle_deg = 114.59155902616465

[balancer]
kind = "ball"
n = 2
rho = 0.1
race_radius = 1.0
density = 10.0
drag = 0.01

[[balancers]]
kind = "ball"
n = 3
rho = 0.1
race_radius = 1.0
density = 10.0
drag = 0.01
plane = 1

[speed]
mode = "constant"
omega = 6.0

[metrics]
t_end_revs = 5
hold_revs = 2
"#;
    let file = SceneFile::parse(text, "two.toml").unwrap();
    assert_eq!(file.rotor.name(), "two_support");
    let sim = file.simulation("two.toml").unwrap();
    let cargo = sim.scene.cargoes().unwrap();
    let planes: Vec<usize> = cargo.iter().map(|c| c.plane).collect();
    assert_eq!(planes, vec![0, 0, 1, 1, 1]);
    let system = sim.scene.build().unwrap();
    assert_eq!(system.layout().rotor_dof, 4);
    let result = sim.run(false).unwrap();
    assert!(result.metrics.a_ref.is_finite() && result.metrics.a_ref > 0.0);
    // A plane index beyond the rotor's planes is named.
    let bad = text.replace("plane = 1", "plane = 2");
    let err = SceneFile::parse(&bad, "two.toml")
        .unwrap()
        .simulation("two.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("balancers[0].plane") && err.contains("2 balancer planes"),
        "{err}"
    );
    // Unknown keys are still named through the model tag.
    let typo = text.replace("polar_inertia", "polar_inertiaa");
    let err = SceneFile::parse(&typo, "two.toml").unwrap_err().to_string();
    assert!(err.contains("polar_inertiaa"), "{err}");
    // A plane file without `model` still reads as the plane rotor.
    let plane = "[rotor]\nmass = 1.0\nkx = 1.0\nky = 1.0\nbx = 0.1\nby = 0.1\n[speed]\nmode = \"constant\"\nomega = 4.0\n[[cargo]]\nmass = 0.01\ntrack_radius = 1.0\ndrag = 0.01\nkappa = 1.4\n";
    assert_eq!(
        SceneFile::parse(plane, "p.toml").unwrap().rotor.name(),
        "plane"
    );
    // Serialising writes the tag and reads back the same rotor.
    let again: SceneFile = toml::from_str(&toml::to_string(&file).unwrap()).unwrap();
    assert_eq!(again.rotor, file.rotor);
}

#[test]
fn locked_start_is_the_steady_forced_response() {
    // From the locked steady state with negligible cargo mass, the rotor
    // stays on its forced orbit: after a while the state is where it started
    // one revolution later.
    let mut rotor = free_rotor();
    rotor.b1 = 0.1;
    rotor.b2 = 0.1;
    let omega = 2.3;
    let cargo: Vec<Cargo> = free_cargo()
        .into_iter()
        .map(|c| Cargo {
            mass: 1e-12,
            drag: 1e-12,
            ..c
        })
        .collect();
    let system = RotorSystem::new(Box::new(rotor), cargo, SpeedLaw::Constant { omega }, vec![]);
    let y0 =
        autobal::model::start::initial_state(&system, StartMode::LockedSteady, &[0.0, 1.0, 2.0]);
    let period = 2.0 * std::f64::consts::PI / omega;
    let options = SolverOptions {
        rtol: 1e-11,
        atol: vec![1e-14],
        ..SolverOptions::default()
    };
    let report = solve(
        Method::Dp5,
        &system,
        0.0,
        &y0,
        3.0 * period,
        &options,
        &mut NoObserver,
    );
    let nq = system.layout().nq();
    let scale = y0[..4].iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(scale > 1e-3);
    for i in (0..4).chain(nq..nq + 4) {
        assert!(
            (report.y[i] - y0[i]).abs() < 1e-7 * scale * omega,
            "coordinate {i}: {} vs {}",
            report.y[i],
            y0[i]
        );
    }
}

#[test]
fn study_run_accepts_a_two_support_rotor() {
    let tmp = tempfile::tempdir().unwrap();
    let text = format!(
        r#"name = "two"
output = "{}"
[scene.rotor]
model = "two_support"
mass = 1.0
transverse_inertia = 1.0
polar_inertia = 0.2
k1 = 1.0
l1 = 2.0
k2 = 1.0
l2 = 2.0
b1 = 0.05
b2 = 0.05
planes = [-1.0, 1.0]
[scene.speed]
mode = "constant"
omega = 6.3
[designs]
kind = "ball"
n = 2
rho = 0.1
race_radius = 1.0
density = 10.0
drag = 0.01
[sampling]
samples = 2
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.6, relative_to = "capacity" }}
[metrics]
t_end_revs = 20
hold_revs = 10
"#,
        tmp.path().join("results").display()
    );
    let path = tmp.path().join("two.toml");
    std::fs::write(&path, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(tmp.path().join("results/two/runs.parquet").exists());
}
