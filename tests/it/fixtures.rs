//! Shared pieces of the test fixtures.

/// The rotor of the shipped SI studies: 10 kg on supports of 1e5 N/m with 5 %
/// of critical damping (ω_n = 100 rad/s), spinning at 300 rad/s.
pub const SI_SCENE: &str = r#"[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
mode = "constant"
omega = 300.0
"#;

/// The dimensionless plane rotor of `scenes/three_balls.toml` (M = 1, k = 1:
/// natural frequency 1) with `n` equal point weights, as scene-file text up
/// to (not including) its `[speed]` table.
/// The soft rotor of issues 29 and 30: 8 kg on 14 kN/m supports at 1200
/// rpm, steel balls in a 25 mm race, starting locked (a study's [scene]
/// and the fixed keys of its [designs]; the drag and what follows are the
/// caller's).
pub const SOFT_ROTOR: &str = r#"[scene]
start = "locked_steady"
[scene.rotor]
mass = 8.0
kx = 14000.0
ky = 14000.0
bx = 33.5
by = 33.5
[scene.speed]
mode = "constant"
omega = 125.66
[designs]
kind = "ball"
n = 3
rho = "optimal"
race_radius = 0.025
density = 7850.0
"#;

pub fn point_weights_scene(n: usize) -> String {
    let mut text = String::from(
        "[rotor]\nmass = 1.0\neccentricity = 0.01\nkx = 1.0\nky = 1.0\nbx = 0.1\nby = 0.1\n",
    );
    for _ in 0..n {
        text += "[[cargo]]\nmass = 0.01\ntrack_radius = 1.0\ndrag = 0.01\nkappa = 1.4\n";
    }
    text
}

/// Run `study simulate` on a scene file holding `text`.
pub fn simulate_text(text: &str) -> std::process::Output {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("simulate")
        .arg(&path)
        .output()
        .unwrap()
}

/// The metrics of one run of the scene file `text` (in the library, no CLI).
pub fn scene_metrics(text: &str) -> autobal::metrics::RunMetrics {
    let file = autobal::scene_file::SceneFile::parse(text, "scene.toml").expect("valid scene");
    file.simulation("scene.toml")
        .expect("simulation")
        .run(false)
        .expect("runs")
        .metrics
}

/// Two runs are the same run, bit for bit: an effect that adds nothing must
/// leave the right-hand side exactly as it was.
pub fn assert_same_run(a: &autobal::metrics::RunMetrics, b: &autobal::metrics::RunMetrics) {
    assert_eq!(a.residual_abs.to_bits(), b.residual_abs.to_bits());
    assert_eq!(a.rhs_calls, b.rhs_calls);
    assert_eq!(a.final_rel_angles_deg, b.final_rel_angles_deg);
}

/// Every study shipped in `studies/`, sorted.
pub fn shipped_studies() -> Vec<std::path::PathBuf> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("studies");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// A shipped study at `samples` per design, its solver settings edited.
pub fn shipped_plan(
    path: &std::path::Path,
    samples: u32,
    edit: impl FnOnce(&mut autobal::simulation::SolverSettings),
) -> autobal::study::plan::config::StudyPlan {
    shipped_plan_edited(path, samples, |file| edit(&mut file.solver))
}

/// A shipped study at `samples` per design, any part of its file edited.
pub fn shipped_plan_edited(
    path: &std::path::Path,
    samples: u32,
    edit: impl FnOnce(&mut autobal::study::plan::config::StudyFile),
) -> autobal::study::plan::config::StudyPlan {
    let text = std::fs::read_to_string(path).unwrap();
    let shown = path.display().to_string();
    let mut file = autobal::study::plan::config::StudyFile::parse(&text, &shown).unwrap();
    file.sampling.samples = samples;
    edit(&mut file);
    file.plan(&text, &shown).unwrap()
}

/// A long rigid rotor (A > C) on symmetric supports with tilt stiffness well
/// above the translational one (ω1 = √2, ω2 = √10, well-separated ranges),
/// balancer planes at `planes`, no unbalance and no tilt inertia of weights.
pub fn long_rotor(planes: Vec<f64>) -> autobal::model::rotor::TwoSupportRotor {
    autobal::model::rotor::TwoSupportRotor {
        mass: 1.0,
        transverse_inertia: 1.0,
        polar_inertia: 0.2,
        k1: 1.0,
        l1: 2.0,
        k2: 1.0,
        l2: 2.0,
        b1: 0.05,
        b2: 0.05,
        k1y: None,
        k2y: None,
        b1y: None,
        b2y: None,
        planes,
        static_unbalance: 0.0,
        static_angle: 0.0,
        moment_unbalance: 0.0,
        moment_angle: 0.0,
        unbalances: Vec::new(),
        weights_tilt_inertia: false,
    }
}

/// Two recorded runs follow one trajectory: over more than 1 000 common
/// samples the whirl r agrees within `tol`·A_ref (of `a`) and every
/// weight's final angle within `tol` rad. `what` names the case in failures.
pub fn assert_same_trajectory(
    a: &autobal::simulation::RunResult,
    b: &autobal::simulation::RunResult,
    tol: f64,
    what: &str,
) {
    let (sa, sb) = (
        a.series.as_ref().expect("recorded"),
        b.series.as_ref().expect("recorded"),
    );
    let n = sa.r.len().min(sb.r.len());
    assert!(n > 1000, "{what}: {n} samples");
    let worst = (0..n)
        .map(|i| (sa.r[i] - sb.r[i]).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < tol * a.metrics.a_ref,
        "{what}: r differs by {worst:e} (A_ref {:e})",
        a.metrics.a_ref
    );
    for j in 0..sa.psi.len() {
        let d = (sa.psi[j][n - 1] - sb.psi[j][n - 1]).abs();
        assert!(d < tol, "{what}: weight {j} differs by {d} rad");
    }
}
