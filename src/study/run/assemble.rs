//! One run assembled from a plan: its draws, its scene and simulation, and
//! the record it leaves (also for designs outside the grid, as the
//! optimiser's candidates are).

use super::*;
use crate::study::plan::stream::Matrix;

/// Execute one run of the plan. Never panics: a failed run is a row with a reason.
pub fn run_one(plan: &StudyPlan, run_id: u64) -> RunRecord {
    let samples = u64::from(plan.file.sampling.samples);
    let design = &plan.designs[(run_id / samples) as usize];
    run_design_sample(plan, design, run_id % samples, run_id)
}

/// Sample `sample_id` of `design` and the simulation a study runs for it
/// (the plan's start, solver and metric settings); the one place a run's
/// inputs are assembled.
pub fn sample_simulation(
    plan: &StudyPlan,
    design: &Design,
    sample_id: u64,
) -> (Sample, Simulation) {
    sample_simulation_in(plan, design, sample_id, Matrix::A)
}

/// As [`sample_simulation`], each input drawn from the set `matrix` names
/// (a sensitivity analysis's pick-freeze runs).
pub fn sample_simulation_in(
    plan: &StudyPlan,
    design: &Design,
    sample_id: u64,
    matrix: Matrix,
) -> (Sample, Simulation) {
    let mut sample = draw_sample_in(plan, design, sample_id, matrix);
    let mut scene = plan.scene(design, sample.unbalance, sample.direction);
    // Without designs of their own, the design sits in every balancer plane,
    // and so do its start angles (the sampled unbalance is placed in every
    // plane at one direction too).
    let planes = plan.file.scene.rotor.as_rotor().planes().max(1);
    if planes > 1 && design.plane_designs.is_empty() {
        sample.initial_angles = sample.initial_angles.repeat(planes);
    }
    if let Some(couple) = &sample.couple {
        let planes = crate::study::plan::couple::plane_unbalances(
            (sample.unbalance, sample.direction),
            couple,
        );
        let at = plan
            .file
            .sampling
            .couple
            .as_ref()
            .and_then(|c| c.at.map(|p| p.0));
        crate::study::plan::couple::apply(&mut scene.rotor, at, &planes);
    }
    sample.weights = draw_weights(plan, design, sample_id, matrix, &mut scene);
    if !sample.uncertain.is_empty() {
        // Validated up front at both ends of every key's support; a draw
        // that still does not read back fails its run with the reason.
        match crate::uncertain::apply(&scene, &sample.uncertain) {
            Ok(varied) => scene = varied,
            Err(reason) => sample.uncertain_refused = Some(reason),
        }
    }
    let simulation = Simulation {
        scene,
        start: plan.file.scene.start,
        initial_angles: sample.initial_angles.clone(),
        solver: plan.file.solver.clone(),
        metrics: plan.file.metrics.clone(),
    };
    (sample, simulation)
}

/// Execute sample `sample_id` of any design (also one outside the plan's grid,
/// as the optimiser's candidates are), recorded under `run_id`.
pub fn run_design_sample(
    plan: &StudyPlan,
    design: &Design,
    sample_id: u64,
    run_id: u64,
) -> RunRecord {
    run_design_sample_in(plan, design, sample_id, run_id, Matrix::A)
}

/// As [`run_design_sample`], each input drawn from the set `matrix` names.
pub fn run_design_sample_in(
    plan: &StudyPlan,
    design: &Design,
    sample_id: u64,
    run_id: u64,
    matrix: Matrix,
) -> RunRecord {
    let (sample, simulation) = sample_simulation_in(plan, design, sample_id, matrix);
    let contact = simulation
        .scene
        .effects
        .contact
        .as_ref()
        .is_some_and(|c| c.enabled);
    let clock = Instant::now();
    let metrics = guarded_metrics(&simulation, sample.uncertain_refused.as_deref());
    RunRecord {
        run_id,
        design_id: design.id,
        sample_id: sample_id as u32,
        kind: design.spec.kind.name().to_string(),
        n: design.spec.n,
        rho: design.rho,
        race_radius: design.spec.race_radius,
        weight_mass: design.weight_mass,
        capacity: design.capacity,
        drag: design.spec.drag,
        unbalance: sample.unbalance,
        unbalance_fraction: sample.fraction,
        direction_deg: sample.direction.to_degrees(),
        initial_angles_deg: sample
            .initial_angles
            .iter()
            .map(|a| a.to_degrees())
            .collect(),
        method: if metrics.method.is_empty() {
            plan.file.solver.method.name().to_string()
        } else {
            metrics.method.clone()
        },
        metrics,
        contact,
        stall_torque: design.stall_torque,
        wall_time_s: clock.elapsed().as_secs_f64(),
        weights: sample.weights,
        couple: sample.couple,
        uncertain: sample.uncertain,
    }
}

/// The metrics of `simulation`, never a panic: a scene the draws made
/// invalid (`refused`, or one the run refuses) or a panic inside the run
/// is a failed run with its reason.
pub(super) fn guarded_metrics(simulation: &Simulation, refused: Option<&str>) -> RunMetrics {
    let result = match refused {
        Some(reason) => Ok(Err(reason.to_string())),
        None => std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            simulation.run(false).map_err(|e| e.to_string())
        })),
    };
    match result {
        Ok(Ok(r)) => r.metrics,
        Ok(Err(e)) => failed(format!("invalid scene: {e}")),
        Err(panic) => {
            let why = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            failed(format!("internal error: {why}"))
        }
    }
}

/// Metrics of a run that could not be simulated at all.
fn failed(reason: String) -> RunMetrics {
    RunMetrics::not_integrated(0.0, Outcome::SolverFailed, reason, "")
}
