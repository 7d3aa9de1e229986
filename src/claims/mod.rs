//! The virtual experiment on seed 000's design claims (issue: "put the paper's
//! design claims to a virtual experiment"):
//! 1. capacity is maximal near half-race fill (Table-1 optima) — [`capacity`];
//! 2. three or more weights re-balance much faster than two after a 90° shift
//!    of the unbalance (Fig. 1 argument);
//! 3. the shortest transients come with 3 balls or 5 rollers (Fig. 7).
//!
//! Claims 2 and 3 are Monte Carlo studies run through the study runner under
//! each [`normalisation::Normalisation`]; the report states the numbers, the
//! normalisation and a plain verdict.

pub mod capacity;
pub mod normalisation;
pub mod report;

use crate::decide::verdict::{DesignRuns, SettlingClock, design_runs, settling_horizon};
use crate::model::balancer::Kind;
use crate::model::scene::{DesignSpec, RhoChoice};
use crate::model::start::StartMode;
use crate::study::plan::config::StudyPlan;
use crate::study::plan::distribution::{Distribution, InitialSpec, Scale, UnbalanceSpec};
use crate::study::results::runs_file::read_summary_columns;
use crate::study::run::study_folder::CLAIMS_MARK;
use crate::study::run::{Progress, RunError, RunOptions, run_study};
use normalisation::{Normalisation, design_capacity, rho_for};
use polars::prelude::*;
use serde::Serialize;

/// One design's statistics in one experiment.
#[derive(Debug, Clone, Serialize)]
pub struct DesignResult {
    /// "shift_90" or "fastest".
    pub experiment: String,
    /// The normalisation.
    pub normalisation: Normalisation,
    /// Balancer kind.
    pub kind: Kind,
    /// Number of weights.
    pub n: u32,
    /// Radius ratio used.
    pub rho: f64,
    /// Capacity (kg·m).
    pub capacity: f64,
    /// Total weight mass (kg).
    pub total_mass: f64,
    /// Runs.
    pub runs: u64,
    /// Fraction settled.
    pub settled_fraction: f64,
    /// Kaplan–Meier median settling time over every run (revolutions;
    /// `None`: beyond the run).
    pub median: Option<f64>,
    /// Its 95 % interval (`None` ends: not bounded within the run).
    pub median_ci: (Option<f64>, Option<f64>),
    /// Restricted mean settling time up to the horizon (revolutions).
    pub rmst: Option<f64>,
    /// 90th percentile over every run (revolutions; `None`: beyond the run).
    pub p90: Option<f64>,
    /// The runs themselves, for paired comparisons between designs.
    #[serde(skip)]
    pub runs_by_sample: DesignRuns,
    /// The runs' seed (for the bootstrap intervals of comparisons).
    pub seed: u64,
}

/// Everything the experiment produced.
#[derive(Debug, Clone)]
pub struct ClaimsOutput {
    /// Claim 1: analytic and simulated capacity over ρ.
    pub capacity: Vec<capacity::CapacityPoint>,
    /// Claim 2: settling after a 90° shift of the unbalance.
    pub shift: Vec<DesignResult>,
    /// Claim 3: settling from the locked steady state, n = 2..8.
    pub fastest: Vec<DesignResult>,
}

/// The same distribution multiplied by `factor`.
fn scaled(d: &Distribution, factor: f64) -> Distribution {
    match *d {
        Distribution::Fixed { value } => Distribution::Fixed {
            value: value * factor,
        },
        Distribution::Uniform { min, max } => Distribution::Uniform {
            min: min * factor,
            max: max * factor,
        },
        Distribution::LogUniform { min, max } => Distribution::LogUniform {
            min: min * factor,
            max: max * factor,
        },
        Distribution::NormalTruncated {
            mean,
            std,
            min,
            max,
        } => Distribution::NormalTruncated {
            mean: mean * factor,
            std: std * factor,
            min: min * factor,
            max: max * factor,
        },
    }
}

/// A study plan for one experiment and normalisation: one design per (kind, n).
fn variant(
    base: &StudyPlan,
    experiment: &str,
    norm: Normalisation,
    ns: &[u32],
    start: StartMode,
    initial: InitialSpec,
) -> Option<StudyPlan> {
    let mut file = base.file.clone();
    file.scene.start = start;
    file.sampling.initial = initial;
    file.sampling.common_random_numbers = true;
    let g = file.designs.clone();
    let drag = g.drag.values()[0];
    let mut designs = Vec::new();
    let mut reference = f64::INFINITY;
    for kind in g.kind.values() {
        for &n in ns {
            let Some(rho) = rho_for(norm, &g, kind, n, ns) else {
                continue;
            };
            let spec = DesignSpec {
                kind,
                n,
                rho: RhoChoice::Value(rho),
                race_radius: g.race_radius,
                density: g.density,
                roller_height: g.roller_height,
                drag,
                plane: 0,
            };
            if let Ok(d) = file.resolve_design(designs.len() as u32, spec) {
                reference =
                    reference.min(design_capacity(&g, kind, n, rho).unwrap_or(f64::INFINITY));
                designs.push(d);
            }
        }
    }
    if designs.is_empty() {
        return None;
    }
    let fractions = base.file.sampling.unbalance.distribution.clone();
    file.sampling.unbalance = match norm {
        Normalisation::Paper => UnbalanceSpec {
            distribution: fractions,
            relative_to: Some(Scale::Capacity),
        },
        _ => UnbalanceSpec {
            distribution: scaled(&fractions, reference),
            relative_to: Some(Scale::Absolute),
        },
    };
    let name = format!("{}/{experiment}_{}", base.name, norm.name());
    let text = format!(
        "{}\n# experiment {experiment}, normalisation {}\n",
        base.text,
        norm.name()
    );
    Some(StudyPlan {
        name,
        file,
        designs,
        text,
    })
}

/// A variant's folder may be (re)written only when it is new, empty, or
/// marked as a claims variant: results of anything else are never replaced.
fn owned_variant_folder(plan: &StudyPlan) -> Result<(), RunError> {
    let dir = crate::study::run::output_dir(plan, None);
    let foreign = std::fs::read_dir(&dir).is_ok_and(|mut entries| entries.next().is_some())
        && !dir.join(CLAIMS_MARK).exists();
    if foreign {
        return Err(RunError::NotOwned {
            path: dir.display().to_string(),
            owner: "study claims",
        });
    }
    Ok(())
}

/// Run a variant through the study runner and read its summary back.
fn run_variant(
    plan: &StudyPlan,
    experiment: &str,
    norm: Normalisation,
    progress: &dyn Progress,
) -> Result<Vec<DesignResult>, RunError> {
    // Each variant's folder belongs to the claims verb, which recomputes it.
    let options = RunOptions {
        overwrite: true,
        ..RunOptions::default()
    };
    // A claim is judged on every design's every sample, as the paper's
    // statement is about each design: no race.
    let mut every_sample = plan.clone();
    every_sample.file.sampling.racing = false;
    let out = run_study(&every_sample, &options, progress)?;
    std::fs::write(out.dir.join(CLAIMS_MARK), "written by study claims\n")?;
    let summary = out.summary.expect("unsharded runs have a summary");
    let f = |c: &str| -> PolarsResult<Vec<Option<f64>>> {
        Ok(summary.column(c)?.f64()?.iter().collect())
    };
    let (median, lo, hi, rmst, p90, frac) = (
        f("settling_revs_median_km")?,
        f("settling_revs_median_km_lo")?,
        f("settling_revs_median_km_hi")?,
        f("settling_revs_rmst")?,
        f("settling_revs_p90_all_runs")?,
        f("settled_fraction")?,
    );
    let by_design = design_runs(
        &read_summary_columns(&out.dir.join("runs.parquet"))?,
        settling_horizon(plan),
        SettlingClock::of(plan),
    )?;
    let runs: Vec<u64> = summary
        .column("runs")?
        .u64()?
        .iter()
        .map(|v| v.unwrap_or(0))
        .collect();
    Ok(plan
        .designs
        .iter()
        .enumerate()
        .map(|(i, d)| DesignResult {
            experiment: experiment.to_string(),
            normalisation: norm,
            kind: d.spec.kind,
            n: d.spec.n,
            rho: d.rho,
            capacity: d.capacity,
            total_mass: f64::from(d.spec.n) * d.weight_mass,
            runs: runs[i],
            settled_fraction: frac[i].unwrap_or(0.0),
            median: median[i],
            median_ci: (lo[i], hi[i]),
            rmst: rmst[i],
            p90: p90[i],
            runs_by_sample: by_design
                .iter()
                .find(|r| r.design_id == d.id)
                .cloned()
                .unwrap_or_else(|| DesignRuns {
                    design_id: d.id,
                    sample_ids: Vec::new(),
                    settling: Vec::new(),
                    residual: Vec::new(),
                    residual_abs: Vec::new(),
                }),
            seed: plan.file.seed,
        })
        .collect())
}

/// Run all three experiments of the claims study `base` (its `[designs]` give
/// the kinds, the n range, race, density and drag; `[sampling]` the unbalance
/// fractions and sample size; `[scene]` the rotor).
pub fn run_claims(base: &StudyPlan, progress: &dyn Progress) -> Result<ClaimsOutput, RunError> {
    let ns: Vec<u32> = base
        .file
        .designs
        .n
        .values()
        .into_iter()
        .filter(|&n| n >= 2)
        .collect();
    let capacity = capacity::capacity_experiment(base, &ns);
    let mut shift = Vec::new();
    let mut fastest = Vec::new();
    let shift_ns: Vec<u32> = ns.iter().copied().filter(|&n| n <= 5).collect();
    let mut variants = Vec::new();
    for norm in Normalisation::ALL {
        // The shift starts from the locked steady state of the new unbalance with
        // the weights still at the old balanced position: a quiet rotor (the
        // `step` start) would add the support's own start-up transient, which
        // measures the support damping, not the balancer.
        if let Some(p) = variant(
            base,
            "shift_90",
            norm,
            &shift_ns,
            StartMode::LockedSteady,
            InitialSpec::BalancedForShift(90.0),
        ) {
            variants.push((p, "shift_90", norm));
        }
        if let Some(p) = variant(
            base,
            "fastest",
            norm,
            &ns,
            StartMode::LockedSteady,
            InitialSpec::Clustered,
        ) {
            variants.push((p, "fastest", norm));
        }
    }
    // Every variant's folder is checked before the first one runs.
    for (p, _, _) in &variants {
        owned_variant_folder(p)?;
    }
    for (p, experiment, norm) in &variants {
        let rows = run_variant(p, experiment, *norm, progress)?;
        if *experiment == "shift_90" {
            shift.extend(rows);
        } else {
            fastest.extend(rows);
        }
    }
    Ok(ClaimsOutput {
        capacity,
        shift,
        fastest,
    })
}
