//! The reference problem every benchmark solves: the isotropic rotor of
//! `scenes/three_balls.toml` with n identical point cargoes, started
//! `locked_steady`, with absolute tolerances on the problem's own scales.
//!
//! This file uses the library only, so that `tests/alloc.rs` can compile it
//! into its own test binary (it cannot reach a module of this binary).

use autobal::integrate::{Method, NoObserver, SolveReport, SolverOptions, Status};
use autobal::metrics::reference::a_ref;
use autobal::model::cargo::Cargo;
use autobal::model::effect::Effects;
use autobal::model::rotor::PlaneRotor;
use autobal::model::scene::Scene;
use autobal::model::speed::SpeedLaw;
use autobal::model::start::{StartMode, initial_state};
use autobal::model::system::RotorSystem;
use autobal::simulation::scaled_atol;
use std::f64::consts::PI;

/// Cargo counts of the right-hand-side scaling series (here, because `tests/alloc.rs` checks each).
pub const CARGO_COUNTS: &[usize] = &[1, 2, 4, 8, 16, 32, 64];

/// Spin speed ω of the reference scene (four times the natural frequency).
pub const OMEGA: f64 = 4.0;

/// Absolute tolerance as a fraction of the relative one, on the problem's
/// scales (the pair 1e-6/1e-8 is the simulation default).
pub const ATOL_PER_RTOL: f64 = 1e-2;

/// The reference scene with `n` identical point cargoes (`scenes/three_balls.toml` for n = 3).
pub fn reference_scene(n: usize) -> Scene {
    Scene {
        rotor: PlaneRotor::isotropic(1.0, 0.01, 1.0, 0.1).into(),
        balancers: Vec::new(),
        balancer: None,
        cargo: vec![Cargo::point(0.01, 1.0, 0.01, 1.4); n],
        speed: SpeedLaw::Constant { omega: OMEGA },
        effects: Effects::default(),
    }
}

/// Initial cargo angles 90°, 100°, 110°, … (rad) of the reference scene.
pub fn reference_angles(n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| (90.0 + 10.0 * j as f64).to_radians())
        .collect()
}

/// One benchmark problem: the assembled system, its start and its tolerances.
#[derive(Debug)]
pub struct BenchProblem {
    /// The equations.
    pub system: RotorSystem,
    /// Initial state (`locked_steady` at [`reference_angles`]).
    pub y0: Vec<f64>,
    /// Solver options with per-component absolute tolerances.
    pub options: SolverOptions,
    /// Horizon in time units.
    pub t_end: f64,
}

impl BenchProblem {
    /// The reference problem with `n` cargoes at `rtol`, over `revolutions`.
    pub fn new(n: usize, rtol: f64, revolutions: f64) -> Self {
        let system = reference_scene(n)
            .build()
            .expect("the reference scene is valid");
        let y0 = initial_state(&system, StartMode::LockedSteady, &reference_angles(n));
        let atol = scaled_atol(&system, rtol * ATOL_PER_RTOL, a_ref(&system, OMEGA), OMEGA);
        let options = SolverOptions {
            rtol,
            atol,
            max_steps: u64::MAX,
            ..SolverOptions::default()
        };
        BenchProblem {
            system,
            y0,
            options,
            t_end: revolutions * 2.0 * PI / OMEGA,
        }
    }

    /// Solve with `method` and no observer.
    pub fn solve(&self, method: Method) -> SolveReport {
        autobal::integrate::solve(
            method,
            &self.system,
            0.0,
            &self.y0,
            self.t_end,
            &self.options,
            &mut NoObserver,
        )
    }

    /// Largest difference to `reference` in units of the problem's scales
    /// (A_ref for displacements, A_ref·ω for velocities, rad, rad·ω).
    pub fn scaled_error(&self, y: &[f64], reference: &[f64]) -> f64 {
        let scale = scaled_atol(&self.system, 1.0, a_ref(&self.system, OMEGA), OMEGA);
        y.iter()
            .zip(reference)
            .zip(&scale)
            .map(|((a, b), s)| (a - b).abs() / s)
            .fold(0.0, f64::max)
    }
}

/// The status of a solve as the reports print it.
pub fn status_name(status: &Status) -> String {
    match status {
        Status::Finished => "finished".into(),
        Status::Stopped => "stopped".into(),
        Status::Failed(f) => format!("failed: {f}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use autobal::scene_file::SceneFile;

    #[test]
    fn reference_scene_is_the_three_balls_scene_file() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/three_balls.toml");
        let file = SceneFile::read(std::path::Path::new(path)).unwrap();
        assert_eq!(file.scene(), reference_scene(3));
        assert_eq!(file.start.mode, StartMode::LockedSteady);
        let angles: Vec<f64> = file
            .start
            .angles_deg
            .unwrap()
            .iter()
            .map(|d| d.to_radians())
            .collect();
        assert_eq!(angles, reference_angles(3));
    }
}
