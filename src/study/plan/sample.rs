//! The draws of one run: unbalance, direction, start angles and, where the
//! study samples them, the couple part and the weights as built.
//!
//! Every run draws from its own streams ([`crate::study::plan::stream`]): results do not
//! depend on thread count, scheduling or sharding. With common random
//! numbers (the default) the design index is left out of the unbalance and
//! direction draws, so every design meets the same unbalances and
//! differences between designs are not sampling noise.

use crate::design::geometry::{half_angle, pressed_angles};
use crate::model::scene::Scene;
use crate::model::start::balanced_fan;
use crate::study::plan::config::StudyPlan;
use crate::study::plan::design::Design;
pub use crate::study::plan::distribution::draw_value;
use crate::study::plan::distribution::{DirectionSpec, InitialSpec, Scale};
use crate::study::plan::stream::{Draws, Matrix, RunStreams, key_hash};
pub use crate::study::plan::stream::{Purpose, splitmix64, stream};
use crate::study::plan::tolerance::SampledWeights;
use crate::uncertain::UncertainValue;
use rand::RngExt;
use rand_distr::{Distribution as _, Exp1};
use std::f64::consts::PI;

/// What was drawn for one run.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Unbalance magnitude U = M e (kg·m).
    pub unbalance: f64,
    /// U as a fraction of the design's capacity.
    pub fraction: f64,
    /// Unbalance direction relative to the rotor (rad).
    pub direction: f64,
    /// Initial cargo angles relative to the rotor (rad).
    pub initial_angles: Vec<f64>,
    /// The weights as built, when the study samples tolerances (filled by
    /// [`crate::study::run::sample_simulation`], which builds the scene).
    pub weights: Option<SampledWeights>,
    /// The couple part, when the study samples one (`[sampling.couple]`).
    pub couple: Option<crate::study::plan::couple::SampledCouple>,
    /// The uncertain scene keys' values (`[uncertain]`, key order), empty
    /// when the study has none.
    pub uncertain: Vec<UncertainValue>,
    /// Why the uncertain keys' draw could not be written into the scene
    /// (the run is then recorded as failed with this reason).
    pub uncertain_refused: Option<String>,
}

/// Draw the sample of run (design, sample index).
pub fn draw_sample(plan: &StudyPlan, design: &Design, sample: u64) -> Sample {
    draw_sample_in(plan, design, sample, Matrix::A)
}

/// Draw the sample of run (design, sample index) from the set of draws
/// `matrix` names for each input (a sensitivity analysis's A, B and AB_i;
/// a study's own runs are [`Matrix::A`]).
pub fn draw_sample_in(plan: &StudyPlan, design: &Design, sample: u64, matrix: Matrix) -> Sample {
    let s = &plan.file.sampling;
    let streams = run_streams(plan, design, matrix);
    let mut rng = streams.draws(sample, Purpose::Unbalance);
    let value = draw_value(&s.unbalance.distribution, &mut rng);
    let (unbalance, fraction) = match s.unbalance.scale() {
        Scale::Capacity => (value * design.capacity, value),
        Scale::Absolute => (value, value / design.capacity),
    };
    let direction = match s.direction {
        DirectionSpec::Uniform => 2.0 * PI * rng.random::<f64>(),
        DirectionSpec::Fixed(deg) => deg.to_radians(),
    };
    // Planes with designs of their own start as plane 0 does (the same
    // draws: clustered around the same direction), each with its weights.
    let initial_angles = std::iter::once(design)
        .chain(&design.plane_designs)
        .flat_map(|d| {
            let mut rng = streams.draws(sample, Purpose::Initial);
            initial_angles(&s.initial, d, &mut rng, unbalance, direction)
        })
        .collect();
    Sample {
        unbalance,
        fraction,
        direction,
        initial_angles,
        weights: None,
        couple: s.couple.as_ref().map(|spec| {
            crate::study::plan::couple::draw(spec, &streams, design, sample, (unbalance, direction))
        }),
        uncertain: crate::uncertain::draw(&plan.file.uncertain, |key| {
            streams.key_draws(key_hash(key), sample).random()
        }),
        uncertain_refused: None,
    }
}

/// The streams of a design's runs: the study's seed and sequence, and the
/// design index only when designs do not share their draws (common random
/// numbers, the default).
pub fn run_streams(plan: &StudyPlan, design: &Design, matrix: Matrix) -> RunStreams {
    RunStreams {
        seed: plan.file.seed,
        shared: if plan.file.sampling.common_random_numbers {
            None
        } else {
            Some(design.id)
        },
        sequence: plan.file.sampling.sequence,
        matrix,
    }
}

/// Draw the weights of run (design, sample index) into `scene`, when the
/// study samples tolerances (`[sampling.tolerances]`); `None`, and the scene
/// left alone, when it does not.
pub fn draw_weights(
    plan: &StudyPlan,
    design: &Design,
    sample: u64,
    matrix: Matrix,
    scene: &mut Scene,
) -> Option<SampledWeights> {
    let t = plan.file.sampling.tolerances.as_ref()?;
    Some(crate::study::plan::tolerance::apply(
        t,
        &run_streams(plan, design, matrix),
        design,
        sample,
        scene,
    ))
}

/// The start angles of one balancer's weights (`design`'s plane), from the
/// run's stream of initial positions.
fn initial_angles(
    initial: &InitialSpec,
    design: &Design,
    rng: &mut Draws,
    unbalance: f64,
    direction: f64,
) -> Vec<f64> {
    let n = design.spec.n as usize;
    match *initial {
        InitialSpec::Clustered => {
            let centre = 2.0 * PI * rng.random::<f64>();
            cluster(design, centre)
        }
        InitialSpec::Even => {
            let start = 2.0 * PI * rng.random::<f64>();
            (0..n)
                .map(|j| start + 2.0 * PI * j as f64 / n as f64)
                .collect()
        }
        InitialSpec::Uniform => uniform_without_overlap(design, rng),
        InitialSpec::BalancedForShift(shift) => {
            let old = direction - shift.to_radians();
            balanced_fan(n, design.weight_mass * design.track_radius, unbalance, old)
                // Solid weights cannot take a fan step below their touching
                // angle 2α: such an unbalance exceeds what they can cancel.
                .filter(|fan| n < 2 || fan_step(fan) >= 2.0 * half_angle(design.rho).unwrap_or(0.0))
                // Beyond what the cargoes can cancel: press them together opposite.
                .unwrap_or_else(|| cluster(design, old + PI))
        }
    }
}

/// The equal angular step between neighbours of a balanced fan.
fn fan_step(fan: &[f64]) -> f64 {
    (fan[1] - fan[0]).abs()
}

/// The weights pressed together, centred on `centre`. A design whose radius
/// leaves no touching angle (never a valid one) gets an even spread rather
/// than coincident weights: the symmetric state is an equilibrium of the
/// model and coincident weights would never separate.
fn cluster(design: &Design, centre: f64) -> Vec<f64> {
    let n = design.spec.n as usize;
    match pressed_angles(design.spec.n, design.rho) {
        Ok(angles) => angles.into_iter().map(|a| a + centre).collect(),
        Err(_) => (0..n)
            .map(|j| centre + 2.0 * PI * j as f64 / n as f64)
            .collect(),
    }
}

/// Uniformly random positions of n weights that may not overlap: the free
/// arc 2π − 2nα is cut into n gaps with uniform spacings (normalised
/// exponentials), which is exactly uniform over non-overlapping configurations.
fn uniform_without_overlap(design: &Design, rng: &mut Draws) -> Vec<f64> {
    let n = design.spec.n as usize;
    let start = 2.0 * PI * rng.random::<f64>();
    if n == 1 {
        return vec![start];
    }
    let width = 2.0 * half_angle(design.rho.min(0.5)).unwrap_or(0.0);
    let free = (2.0 * PI - n as f64 * width).max(0.0);
    let gaps: Vec<f64> = (0..n).map(|_| Exp1.sample(rng)).collect();
    let total: f64 = gaps.iter().sum();
    let mut angle = start;
    let mut out = Vec::with_capacity(n);
    for g in gaps {
        out.push(angle);
        angle += width + free * g / total;
    }
    out
}
