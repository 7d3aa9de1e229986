//! Radau5's structured Newton matrices (tridiagonal along the race plus low
//! rank through the rotor, used from 20 weights on) give the dense matrices'
//! answers: the same run, to the accuracy of finite differences.

use crate::auto_method::packed_chain_of;
use autobal::integrate::{CouplingStructure, HeadEquation, OdeSystem};
use autobal::metrics::RunMetrics;
use autobal::model::cargo::Cargo;
use autobal::model::effect::Effect;
use autobal::model::effect::contact::{Contact, ContactSpec};
use autobal::model::frame::RotatingSystem;
use autobal::model::rotor::{Rotor, TwoSupportRotor};
use autobal::model::speed::SpeedLaw;
use autobal::model::system::RotorSystem;
use autobal::scene_file::SceneFile;

/// `n` packed balls on Radau5 throughout, with dense or structured Newton
/// matrices.
fn packed_chain_on_radau5(n: usize, dense: bool) -> RunMetrics {
    run_on_radau5(&packed_chain_of(n, "radau5"), dense)
}

/// The scene `text` with dense or structured Newton matrices.
fn run_on_radau5(text: &str, dense: bool) -> RunMetrics {
    let file = SceneFile::parse(text, "scene.toml").expect("valid scene");
    let mut simulation = file.simulation("scene.toml").expect("simulation");
    simulation.solver.dense_newton = dense;
    simulation.run(false).expect("runs").metrics
}

/// Both runs end alike, to the accuracy of finite differences: the same
/// outcome and settling time, the residual within 1 %, and not the same bits
/// (different matrices were used).
fn assert_same_run(structured: &RunMetrics, dense: &RunMetrics) {
    eprintln!(
        "structured: {} RHS calls, {} steps, {:?}, residual {}; dense: {} RHS calls, {} steps, {:?}, residual {}",
        structured.rhs_calls,
        structured.steps,
        structured.settling_revs,
        structured.residual_rel,
        dense.rhs_calls,
        dense.steps,
        dense.settling_revs,
        dense.residual_rel,
    );
    assert_ne!(structured.rhs_calls, dense.rhs_calls);
    assert_eq!(structured.outcome, dense.outcome);
    assert_eq!(structured.settling_revs, dense.settling_revs);
    let rel = (structured.residual_rel / dense.residual_rel - 1.0).abs();
    assert!(
        rel <= 0.01,
        "residual {} vs {}",
        structured.residual_rel,
        dense.residual_rel
    );
}

#[test]
fn structured_newton_matrices_follow_a_packed_chain_of_24_balls_as_dense_ones_do() {
    let structured = packed_chain_on_radau5(24, false);
    let dense = packed_chain_on_radau5(24, true);
    assert_same_run(&structured, &dense);
    assert_fewer_rhs_calls(&structured, &dense);
}

/// The structured matrices, with the head rows from the head equation,
/// call the right-hand side at most 0.85 times as often as the dense ones.
/// Measured 0.63 (rotating frame) and 0.74 (inertial frame); with the rows
/// by directional differences 0.95 and 1.69.
fn assert_fewer_rhs_calls(structured: &RunMetrics, dense: &RunMetrics) {
    let ratio = structured.rhs_calls as f64 / dense.rhs_calls as f64;
    assert!(ratio <= 0.85, "structured/dense RHS calls {ratio:.2}");
}

#[test]
fn structured_newton_matrices_follow_packed_balls_in_the_inertial_frame_as_dense_ones_do() {
    // The full (inertial) equations, 100 revolutions.
    let text = packed_chain_of(24, "radau5")
        .replace("[solver]\n", "[solver]\nfidelity = \"full\"\n")
        .replace("t_end_revs = 2000", "t_end_revs = 100");
    let structured = run_on_radau5(&text, false);
    let dense = run_on_radau5(&text, true);
    assert_eq!(structured.fidelity, "full");
    assert_same_run(&structured, &dense);
    assert_fewer_rhs_calls(&structured, &dense);
}

/// The largest violation of the structure `system` declares at `y`, relative
/// to the row it occurs in: every acceleration of a ring coordinate, less
/// U·(the head accelerations), must depend only on its own coordinate, its
/// ring neighbours and the head coordinates (central differences).
fn structure_violation(system: &dyn OdeSystem, t: f64, y: &[f64]) -> f64 {
    let dim = y.len();
    let m = dim / 2;
    let mut st = CouplingStructure::default();
    assert!(system.coupling_structure(t, y, &mut st));
    let h = st.head;
    let jac = central_jacobian(system, t, y);
    let mut neighbours = vec![Vec::new(); m];
    let mut start = 0;
    for &end in &st.ring_ends {
        let ring = &st.order[start..end];
        for (p, &i) in ring.iter().enumerate() {
            let len = ring.len();
            neighbours[i] = vec![i, ring[(p + 1) % len], ring[(p + len - 1) % len]];
        }
        start = end;
    }
    let mut worst = 0.0f64;
    for i in h..m {
        let u = &st.coupling[(i - h) * h..(i - h + 1) * h];
        let local = |c: usize| {
            jac[(m + i) * dim + c] - (0..h).map(|r| u[r] * jac[(m + r) * dim + c]).sum::<f64>()
        };
        let scale = (0..dim)
            .map(|c| jac[(m + i) * dim + c].abs())
            .fold(1e-300, f64::max);
        for c in 0..dim {
            let coordinate = c % m;
            if coordinate < h || neighbours[i].contains(&coordinate) {
                continue;
            }
            worst = worst.max(local(c).abs() / scale);
        }
    }
    worst
}

/// ∂f/∂y at (t, y) by central differences, row-major.
fn central_jacobian(system: &dyn OdeSystem, t: f64, y: &[f64]) -> Vec<f64> {
    let dim = y.len();
    let mut jac = vec![0.0; dim * dim];
    let (mut yp, mut fp, mut fm) = (y.to_vec(), vec![0.0; dim], vec![0.0; dim]);
    for c in 0..dim {
        let d = 1e-6 * (1.0 + y[c].abs());
        yp[c] = y[c] + d;
        system.rhs(t, &yp, &mut fp);
        yp[c] = y[c] - d;
        system.rhs(t, &yp, &mut fm);
        yp[c] = y[c];
        for r in 0..dim {
            jac[r * dim + c] = (fp[r] - fm[r]) / (2.0 * d);
        }
    }
    jac
}

/// The largest violation of the head equation `system` gives at `y`, each
/// relative to the largest term of its row: differentiating
/// M_h·z + Σ e_i·a_i = F_h along a ring coordinate c gives
/// M_h·∂z/∂y_c + Σ e_i·∂a_i/∂y_c = own_c, which central differences check.
/// None when the system gives no head equation.
fn head_equation_violation(system: &dyn OdeSystem, t: f64, y: &[f64]) -> Option<f64> {
    let dim = y.len();
    let m = dim / 2;
    let mut st = CouplingStructure::default();
    assert!(system.coupling_structure(t, y, &mut st));
    let h = st.head;
    let mut f = vec![0.0; dim];
    system.rhs(t, y, &mut f);
    let mut eq = HeadEquation::default();
    if !system.head_equation(t, y, &f, &mut eq) {
        return None;
    }
    let jac = central_jacobian(system, t, y);
    let mut worst = 0.0f64;
    for c in (h..m).chain(m + h..dim) {
        let (half, i) = (c / m, c % m);
        for r in 0..h {
            let mut terms: Vec<f64> = (0..h)
                .map(|s| eq.mass[r * h + s] * jac[(m + s) * dim + c])
                .collect();
            terms.extend((h..m).map(|k| eq.reaction[(k - h) * h + r] * jac[(m + k) * dim + c]));
            let own = eq.own[(i - h) * 2 * h + half * h + r];
            let scale = terms.iter().fold(own.abs(), |a, t| a.max(t.abs()));
            worst = worst.max((terms.iter().sum::<f64>() - own).abs() / scale);
        }
    }
    Some(worst)
}

/// The rotor systems the structure tests check, each with a state of 24
/// pressed weights dealt out of race order: 24 packed balls in the rotating
/// and the inertial frame and on a motor (the spin a head coordinate), and
/// two planes of twelve on a rigid rotor, without and with tilt inertia.
struct Fixtures {
    scene_text: String,
    rotating: RotatingSystem,
    inertial: RotorSystem,
    motor: RotorSystem,
    two_planes: RotorSystem,
    two_planes_tilting: RotorSystem,
    /// States of the plane rotor, the motor and the two-plane rotor.
    y: Vec<f64>,
    y_motor: Vec<f64>,
    y_planes: Vec<f64>,
}

/// A scene from its text.
fn parse_scene(text: &str) -> autobal::model::scene::Scene {
    SceneFile::parse(text, "scene.toml")
        .expect("valid scene")
        .simulation("scene.toml")
        .expect("simulation")
        .scene
}

fn fixtures(seed: u64) -> Fixtures {
    let mut seed = seed;
    let n = 24;
    let scene_text = packed_chain_of(n, "radau5");
    let scene = parse_scene(&scene_text);
    let angles = pressed(n, 180.0 / n as f64, &mut seed);
    let mut motor_scene = scene.clone();
    motor_scene.speed = SpeedLaw::Motor {
        stall_torque: 20.0,
        omega_sync: 300.0,
        omega_start: 250.0,
    };
    let mut y_motor = state(3, 3 + n, &angles);
    y_motor[2] = 0.7;
    y_motor[3 + n + 2] = 240.0;
    let two_planes = |tilt: bool| {
        let rotor = TwoSupportRotor {
            weights_tilt_inertia: tilt,
            ..crate::fixtures::long_rotor(vec![-1.0, 1.0])
        };
        let cargo: Vec<Cargo> = (0..n)
            .map(|j| Cargo {
                plane: j % 2,
                radius: (7.5f64).to_radians().sin(),
                ..Cargo::point(0.01, 1.0, 0.02, 1.4)
            })
            .collect();
        let effects: Vec<Box<dyn Effect>> = vec![Box::new(
            Contact::new(&ContactSpec::default(), &cargo, 3.0).expect("sized weights"),
        )];
        RotorSystem::new(
            Box::new(rotor),
            cargo,
            SpeedLaw::Constant { omega: 3.0 },
            effects,
        )
    };
    // Plane by plane 15° apart (the planes interleave in cargo order).
    let mut plane_angles = vec![0.0; n];
    for (k, a) in pressed(n / 2, 15.0, &mut seed).into_iter().enumerate() {
        plane_angles[2 * k] = a;
        plane_angles[2 * k + 1] = a + 0.01;
    }
    let head = crate::fixtures::long_rotor(vec![-1.0, 1.0]).dof();
    Fixtures {
        rotating: RotatingSystem::new(&scene).expect("rotating frame"),
        inertial: scene.build().expect("system"),
        motor: motor_scene.build().expect("system"),
        two_planes: two_planes(false),
        two_planes_tilting: two_planes(true),
        y: state(2, 2 + n, &angles),
        y_motor,
        y_planes: state(head, head + n, &plane_angles),
        scene_text,
    }
}

#[test]
fn rotor_systems_give_their_head_equations_truly_or_not_at_all() {
    let f = fixtures(5);
    let violations = [
        ("rotating", head_equation_violation(&f.rotating, 0.3, &f.y)),
        ("inertial", head_equation_violation(&f.inertial, 0.3, &f.y)),
        (
            "two planes",
            head_equation_violation(&f.two_planes, 0.3, &f.y_planes),
        ),
    ];
    eprintln!("largest violations of the head equations: {violations:?}");
    for (system, violation) in violations {
        let violation = violation.expect("a head equation");
        // Measured 2.2e-6 (rotating), rounding in the differences (it grows
        // as 1/step below this step); the weight's acceleration term left
        // out of `own` gives 7.6e-3 (rotating) and 9.8e-3 (inertial), a
        // coefficient 5 % off 1.7e-2 and more.
        assert!(violation < 1e-4, "{system}: {violation:e}");
    }
    // Head terms the systems leave to directional differences: an
    // off-centre race (rotor forces from the weights' angles), a free
    // spin, the weights' tilt inertia.
    let off_centre = format!(
        "{}\n[effects.race_eccentricity]\noffset = 1e-4\nangle_deg = 30\n",
        f.scene_text
    );
    let rotating = RotatingSystem::new(&parse_scene(&off_centre)).expect("rotating frame");
    assert_eq!(head_equation_violation(&rotating, 0.3, &f.y), None);
    assert_eq!(head_equation_violation(&f.motor, 0.3, &f.y_motor), None);
    assert_eq!(
        head_equation_violation(&f.two_planes_tilting, 0.3, &f.y_planes),
        None
    );
}

/// Packed angles (rad) a little less than `spacing_deg` apart, so that
/// contacts press, dealt to the weights out of race order (weight j sits
/// at place 7j mod n), so that a ring in weight order would be wrong.
fn pressed(n: usize, spacing_deg: f64, seed: &mut u64) -> Vec<f64> {
    (0..n)
        .map(|j| {
            let place = (7 * j % n) as f64;
            *seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let noise = (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            (40.0 + spacing_deg * (0.98 * place + 0.01 * noise)).to_radians()
        })
        .collect()
}

/// A state with the head coordinates at `head` ≥ 1e-4, the given ring angles
/// and every rate about 1.
fn state(head: usize, nq: usize, angles: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; 2 * nq];
    for r in 0..head {
        y[r] = 1e-4 * (1.0 + r as f64);
        y[nq + r] = 0.3 - 0.1 * r as f64;
    }
    for (j, a) in angles.iter().enumerate() {
        y[nq - angles.len() + j] = *a;
        y[2 * nq - angles.len() + j] = 0.5 + 0.05 * j as f64;
    }
    y
}

#[test]
fn every_rotor_system_couples_its_weights_as_it_declares() {
    let f = fixtures(17);
    let violations = [
        ("rotating", structure_violation(&f.rotating, 0.3, &f.y)),
        ("inertial", structure_violation(&f.inertial, 0.3, &f.y)),
        ("motor", structure_violation(&f.motor, 0.3, &f.y_motor)),
        (
            "two planes with tilt inertia",
            structure_violation(&f.two_planes_tilting, 0.3, &f.y_planes),
        ),
    ];
    eprintln!("largest violations: {violations:?}");
    for (system, v) in violations {
        assert!(v < 1e-6, "{system}: {v:e}");
    }
}
