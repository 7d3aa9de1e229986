//! The flexible (Stodola–Green) shaft of seed 002: beam theory, the paper's
//! dimensionless parameters, conservation, and its stability map against
//! nonlinear simulations.

use autobal::integrate::{
    Flow, Method, OdeSystem, SolverOptions, Status, Step, StepObserver, solve,
};
use autobal::metrics::Outcome;
use autobal::model::cargo::Cargo;
use autobal::model::invariants::{angular_momentum, energy};
use autobal::model::rotor::{FlexibleShaft, Rotor, RotorModel};
use autobal::model::speed::SpeedLaw;
use autobal::model::system::RotorSystem;
use autobal::model::zero_approx::criterion_margin;
use autobal::scene_file::SceneFile;
use autobal::study::stability_map::stability_map;
use autobal::study::sweep::speed_grid;

fn paper_scene() -> SceneFile {
    SceneFile::read(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/flexible_meraz.toml"
    )))
    .unwrap()
}

#[test]
fn scene_file_holds_the_papers_dimensionless_values() {
    let paper = FlexibleShaft::dimensionless(2.0, 0.01, 0.01, 0.01);
    assert!((paper.omega0() - 1.0).abs() < 1e-12);
    assert!((paper.zeta_t() - 0.01).abs() < 1e-12 && (paper.zeta_r() - 0.01).abs() < 1e-12);
    let RotorModel::Flexible(file) = paper_scene().rotor else {
        panic!("the scene is not a flexible rotor");
    };
    for (a, b) in [
        (file.mass, paper.mass),
        (file.transverse_inertia, paper.transverse_inertia),
        (file.polar_inertia, paper.polar_inertia),
        (file.ei, paper.ei),
        (file.length, paper.length),
        (file.c_t, paper.c_t),
        (file.c_r, paper.c_r),
        (file.eccentricity, paper.eccentricity),
    ] {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    let cargo = &paper_scene().cargo;
    // m/M = 0.01 and D/(m R² ω0) = 0.01 with the drag torque β l² ψ̇.
    assert!(
        cargo
            .iter()
            .all(|c| c.mass == 0.01 && c.drag * c.track_radius.powi(2) == 1e-4)
    );
}

#[test]
fn clamped_shaft_stiffness_is_the_cantilevers() {
    // A tip force F alone: deflection F L³/(3EI), slope F L²/(2EI).
    let s = FlexibleShaft::dimensionless(2.0, 0.0, 0.0, 0.0);
    let (k11, k14, k33) = s.stiffness();
    let f = 0.3;
    // Solve [k11 k14; k14 k33] (x, β) = (F, 0).
    let det = k11 * k33 - k14 * k14;
    let (x, beta) = (k33 * f / det, -k14 * f / det);
    assert!((x - f * s.length.powi(3) / (3.0 * s.ei)).abs() < 1e-12);
    assert!((beta - f * s.length.powi(2) / (2.0 * s.ei)).abs() < 1e-12);
    // The rotor's forces use exactly these coefficients (y, α by symmetry).
    let mut force = [0.0; 4];
    s.forces(&[0.0, x, -beta, 0.0], &[0.0; 4], 0.0, &mut force);
    assert!((force[1] + f).abs() < 1e-12 && force[2].abs() < 1e-12);
}

struct Drift<'a> {
    system: &'a RotorSystem,
    e0: f64,
    l0: f64,
    worst: f64,
}

impl StepObserver for Drift<'_> {
    fn step(&mut self, step: &Step<'_>) -> Flow {
        let e = energy(self.system, step.t, step.y, 0.0);
        let l = angular_momentum(self.system, step.t, step.y);
        self.worst = self
            .worst
            .max(((e - self.e0) / self.e0).abs())
            .max(((l - self.l0) / self.l0).abs());
        Flow::Continue
    }
}

#[test]
fn energy_and_angular_momentum_are_conserved_without_dissipation() {
    let mut shaft = FlexibleShaft::dimensionless(2.0, 0.0, 0.0, 0.01);
    shaft.unbalance_angle = 0.6;
    let cargo = vec![
        Cargo::point(0.01, 1.0, 0.0, 1.0),
        Cargo::point(0.02, 0.8, 0.0, 1.3),
    ];
    let system = RotorSystem::new(
        Box::new(shaft),
        cargo,
        SpeedLaw::Free { omega_start: 2.0 },
        vec![],
    );
    let lay = system.layout();
    let nq = lay.nq();
    let mut y = vec![0.0; system.dim()];
    y[..4].copy_from_slice(&[0.01, -0.02, 0.015, 0.005]);
    y[nq..nq + 4].copy_from_slice(&[0.02, 0.01, -0.03, 0.02]);
    y[nq + lay.phi()] = 2.0;
    y[lay.psi(1)] = 2.0;
    y[nq + lay.psi(0)] = 0.1;
    let mut d = Drift {
        system: &system,
        e0: energy(&system, 0.0, &y, 0.0),
        l0: angular_momentum(&system, 0.0, &y),
        worst: 0.0,
    };
    let options = SolverOptions {
        rtol: 1e-10,
        atol: vec![1e-13],
        ..SolverOptions::default()
    };
    let report = solve(Method::Dp5, &system, 0.0, &y, 100.0, &options, &mut d);
    assert_eq!(report.status, Status::Finished);
    assert!(d.worst < 1e-7, "drift {:e}", d.worst);
}

#[test]
fn stability_map_at_the_papers_values_and_nonlinear_runs_agree() {
    let file = paper_scene();
    let scene = file.scene();
    // ω/ω0 from 0.1 to 3, ε/R from 0.001 to 0.019 (2m/M = 0.02 is the capacity).
    let omegas = speed_grid(0.1, 3.0, 30);
    let map = stability_map(&scene, &omegas, &[0.001, 0.01, 0.019]).unwrap();
    assert!(map.iter().all(|p| p.balanced));
    // Unstable below about 0.4 ω0 (just above the first critical speed ≈ 0.27 ω0),
    // stable above about 0.5 ω0, for every ε/R.
    for p in &map {
        if p.omega < 0.3 {
            assert_eq!(p.stable, Some(false), "{p:?}");
        }
        if p.omega > 0.5 {
            assert_eq!(p.stable, Some(true), "{p:?}");
        }
    }
    // The stable region lies inside the criterion's prediction (ω > ω1).
    for p in map.iter().filter(|p| p.stable == Some(true)) {
        let mut s = scene.clone();
        s.speed = SpeedLaw::Constant { omega: p.omega };
        assert!(
            criterion_margin(&s.build().unwrap(), p.omega) < 0.0,
            "{p:?}"
        );
    }
    // Nonlinear runs inside and outside the stable region.
    for (omega, stable) in [(2.0, true), (0.35, false)] {
        let mut f = paper_scene();
        f.speed = SpeedLaw::Constant { omega };
        let point = stability_map(&f.scene(), &[omega], &[0.01]).unwrap()[0].clone();
        assert_eq!(point.stable, Some(stable));
        let run = f
            .simulation("flexible_meraz.toml")
            .unwrap()
            .run(false)
            .unwrap()
            .metrics;
        let expected = if stable {
            Outcome::Settled
        } else {
            Outcome::Censored
        };
        assert_eq!(run.outcome, expected, "ω = {omega}: {}", run.reason);
        if !stable {
            assert!(run.balancing_error > 0.5, "ε = {}", run.balancing_error);
        }
    }
}

#[test]
fn study_map_writes_the_grid_and_draws_it() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("map.parquet");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args([
            "map",
            concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/flexible_meraz.toml"),
            "--omega",
            "0.2..2",
            "--unbalance",
            "0.005..0.025",
            "--points",
            "4x3",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = String::from_utf8_lossy(&run.stdout);
    let picture: Vec<&str> = text.lines().skip(3).collect();
    // Top row: ε/R = 0.025 beyond the capacity; then stable except at the lowest speed.
    assert_eq!(picture, vec!["    ", ".###", ".###"], "{text}");
    let df = autobal::study::results::io::read_parquet(&out).unwrap();
    assert_eq!(df.height(), 12);
}
