//! Radau5's structured Newton matrices (tridiagonal along the race plus low
//! rank through the rotor, used from 20 weights on) give the dense matrices'
//! answers: the same run, to the accuracy of finite differences.

use crate::auto_method::packed_chain_of;
use autobal::metrics::RunMetrics;
use autobal::scene_file::SceneFile;

/// `n` packed balls on Radau5 throughout, with dense or structured Newton
/// matrices.
fn packed_chain_on_radau5(n: usize, dense: bool) -> RunMetrics {
    let file = SceneFile::parse(&packed_chain_of(n, "radau5"), "scene.toml").expect("valid scene");
    let mut simulation = file.simulation("scene.toml").expect("simulation");
    simulation.solver.dense_newton = dense;
    simulation.run(false).expect("runs").metrics
}

#[test]
fn structured_newton_matrices_follow_a_packed_chain_of_24_balls_as_dense_ones_do() {
    let structured = packed_chain_on_radau5(24, false);
    let dense = packed_chain_on_radau5(24, true);
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
    // Different matrices, so not the same bits.
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
