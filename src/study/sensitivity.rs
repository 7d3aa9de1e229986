//! Which input matters: variance-based (Sobol) sensitivity of a study's
//! measures to everything it samples, by pick-freeze.
//!
//! The inputs are the study's own random streams, each one input (or group):
//! the unbalance (its size and direction together), the start angles, each
//! tolerance of the weights, the couple part, and each uncertain scene key
//! (`[uncertain]`). For N rows, each design runs the matrices A (the study's
//! own draws: row j is sample j of `study run`), B (an independent second
//! set of draws) and, for each input i, AB_i (A with input i taken from B):
//! N·(k + 2) runs per design. Saltelli's (2010) first-order and Jansen's
//! (1999) total-effect estimators with bootstrap intervals
//! ([`crate::stats::sobol_indices`]) then say how much of each measure's
//! variance each input explains, alone and with its interactions.
//!
//! The measures are those a decision rests on: the settling time capped at
//! the horizon τ (the restricted mean's integrand, censored runs at τ), the
//! residual vibration (µm) and the settled indicator (settled by τ or not).

use crate::stats::sobol_indices::{PickFreeze, SobolIndex, indices};
use crate::study::plan::config::StudyPlan;
use crate::study::plan::distribution::{DirectionSpec, Distribution, InitialSpec};
use crate::study::plan::stream::{Input, Matrix, Purpose, Sequence, key_hash, stream};
use crate::study::results::design_runs::{
    RunTimes, SettlingClock, settling_horizon, settling_observation,
};
use crate::study::results::record::RunRecord;
use crate::study::run::run_design_sample_in;
use polars::prelude::*;
use rayon::prelude::*;

/// Bootstrap resamples of each index's interval.
pub const RESAMPLES: usize = 1000;

/// One input of the analysis: what it is called in tables and which stream
/// (or uncertain key) it draws from.
#[derive(Debug, Clone, PartialEq)]
pub struct SensitivityInput {
    /// Its name in tables and in sensitivity.parquet.
    pub name: String,
    /// The stream it draws from.
    pub input: Input,
    /// What kind of input it is to the engineer.
    pub kind: InputKind,
}

/// What an input is to the engineer who reads its index. Only a machine
/// unknown is something to measure or specify before building: the
/// unbalance and the start are what the balancer meets in service, and a
/// tolerance is the spread of the balancer's own parts, so a headline on
/// "which input matters" names the largest machine unknown and reports the
/// others apart (before 2026-12 it named "unbalance (size, direction)").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// An `[uncertain]` scene key: the machine's physics, known only to a
    /// distribution.
    MachineUnknown,
    /// A sampled operating condition: the unbalance (size and direction),
    /// the start angles, the couple part.
    OperatingCondition,
    /// A manufacturing tolerance of the balancer's parts.
    Tolerance,
}

impl InputKind {
    /// Its name in sensitivity.parquet's `input_kind` column.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::MachineUnknown => "machine_unknown",
            InputKind::OperatingCondition => "operating_condition",
            InputKind::Tolerance => "tolerance",
        }
    }
}

/// The inputs a study samples, in a fixed order: the unbalance, the start
/// angles, the tolerances, the couple part, then the uncertain keys.
pub fn inputs(plan: &StudyPlan) -> Vec<SensitivityInput> {
    let s = &plan.file.sampling;
    let stream = |name: &str, purpose| SensitivityInput {
        name: name.to_string(),
        input: Input::Stream(purpose),
        kind: match purpose {
            Purpose::MassTolerance | Purpose::RadiusTolerance | Purpose::EccentricityTolerance => {
                InputKind::Tolerance
            }
            _ => InputKind::OperatingCondition,
        },
    };
    let mut out = Vec::new();
    let fixed_size = matches!(s.unbalance.distribution, Distribution::Fixed { .. });
    if !(fixed_size && matches!(s.direction, DirectionSpec::Fixed(_))) {
        out.push(stream("unbalance (size, direction)", Purpose::Unbalance));
    }
    if !matches!(s.initial, InitialSpec::BalancedForShift(_)) {
        out.push(stream("start angles", Purpose::Initial));
    }
    if let Some(t) = &s.tolerances {
        for (present, name, purpose) in [
            (
                t.mass.is_some(),
                "weights' mass tolerance",
                Purpose::MassTolerance,
            ),
            (
                t.radius.is_some(),
                "weights' radius tolerance",
                Purpose::RadiusTolerance,
            ),
            (
                t.eccentricity.is_some(),
                "race eccentricity tolerance",
                Purpose::EccentricityTolerance,
            ),
        ] {
            if present {
                out.push(stream(name, purpose));
            }
        }
    }
    if s.couple.is_some() {
        out.push(stream("couple part", Purpose::Couple));
    }
    out.extend(plan.file.uncertain.keys().map(|key| SensitivityInput {
        name: key.clone(),
        input: Input::Key(key_hash(key)),
        kind: InputKind::MachineUnknown,
    }));
    out
}

/// The measures whose variance is apportioned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// Settling time capped at τ (rev): censored runs count τ.
    RestrictedSettling,
    /// Residual vibration (µm) of runs simulated to their end.
    Residual,
    /// 1 when the run settled by τ, else 0.
    Settled,
}

impl Measure {
    /// Every measure, in table order.
    pub const ALL: [Measure; 3] = [
        Measure::RestrictedSettling,
        Measure::Residual,
        Measure::Settled,
    ];

    /// Its name in sensitivity.parquet.
    pub fn name(self) -> &'static str {
        match self {
            Measure::RestrictedSettling => "restricted_settling_revs",
            Measure::Residual => "residual_um",
            Measure::Settled => "settled",
        }
    }

    /// One run's value; `None` where the run has none (a failed run's residual).
    fn of(self, run: &RunRecord, tau: f64, clock: SettlingClock) -> Option<f64> {
        let m = &run.metrics;
        let observed = || {
            let times = RunTimes {
                settled: Some(m.settled),
                settling_revs: m.settling_revs,
                censoring_revs: m.censoring_revs,
                operating_time_s: m.operating_time,
            };
            settling_observation(times, tau, clock)
        };
        match self {
            Measure::RestrictedSettling => Some(observed().time.min(tau)),
            Measure::Settled => {
                let o = observed();
                Some(if o.settled && o.time <= tau { 1.0 } else { 0.0 })
            }
            Measure::Residual => (m.outcome.has_residual() && m.residual_abs.is_finite())
                .then_some(m.residual_abs * 1e6),
        }
    }
}

/// How the analysis samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensitivitySettings {
    /// N: rows of each matrix (a power of two with the Sobol sequence).
    pub rows: u32,
    /// Where the draws come from (Sobol: Owen-scrambled, A and B scrambled apart).
    pub sequence: Sequence,
    /// Worker threads (`None`: rayon's default); the results do not depend on it.
    pub threads: Option<usize>,
}

/// Runs the analysis makes: N·(k + 2) per design.
pub fn runs_needed(plan: &StudyPlan, settings: &SensitivitySettings) -> u64 {
    let k = inputs(plan).len() as u64;
    plan.designs.len() as u64 * u64::from(settings.rows) * (k + 2)
}

/// One index of one input for one design and measure.
#[derive(Debug, Clone, PartialEq)]
pub struct SensitivityRow {
    /// The design.
    pub design_id: u32,
    /// The measure.
    pub measure: Measure,
    /// The input's name.
    pub input: String,
    /// What kind of input it is.
    pub kind: InputKind,
    /// First-order and total indices with their intervals; `None` with a
    /// note when the measure did not vary (or had too few rows).
    pub index: Option<SobolIndex>,
    /// Rows of the design the estimate used (rows where a run had no value
    /// for the measure are left out whole).
    pub rows: u32,
    /// Why there is no index, if there is none.
    pub note: Option<String>,
}

/// Every run of the analysis, in (design, matrix, row) order: matrix 0 is A,
/// 1 is B, 2 + i is AB_i.
pub fn run_pick_freeze(
    plan: &StudyPlan,
    settings: &SensitivitySettings,
    done: &(dyn Fn(u64) + Sync),
) -> Vec<RunRecord> {
    let plan = with_sequence(plan, settings.sequence);
    let inputs = inputs(&plan);
    let matrices: Vec<Matrix> = [Matrix::A, Matrix::B]
        .into_iter()
        .chain(inputs.iter().map(|i| Matrix::AWithFromB(i.input)))
        .collect();
    let rows = u64::from(settings.rows);
    let per_design = rows * matrices.len() as u64;
    let total = plan.designs.len() as u64 * per_design;
    let counter = std::sync::atomic::AtomicU64::new(0);
    let all = || -> Vec<RunRecord> {
        (0..total)
            .into_par_iter()
            .map(|run_id| {
                let design = &plan.designs[(run_id / per_design) as usize];
                let within = run_id % per_design;
                let matrix = matrices[(within / rows) as usize];
                let record = run_design_sample_in(&plan, design, within % rows, run_id, matrix);
                done(counter.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
                record
            })
            .collect()
    };
    match settings
        .threads
        .and_then(|t| rayon::ThreadPoolBuilder::new().num_threads(t).build().ok())
    {
        Some(pool) => pool.install(all),
        None => all(),
    }
}

/// The plan with the analysis's sequence (the study's own otherwise unchanged).
fn with_sequence(plan: &StudyPlan, sequence: Sequence) -> StudyPlan {
    let mut plan = plan.clone();
    plan.file.sampling.sequence = sequence;
    plan
}

/// The indices of every design, measure and input from the runs of
/// [`run_pick_freeze`]; each design's bootstrap draws from a stream of its own.
pub fn estimate(
    plan: &StudyPlan,
    settings: &SensitivitySettings,
    runs: &[RunRecord],
) -> Vec<SensitivityRow> {
    let inputs = inputs(plan);
    let (tau, clock) = (settling_horizon(plan), SettlingClock::of(plan));
    let rows = settings.rows as usize;
    let per_design = rows * (inputs.len() + 2);
    let mut out = Vec::new();
    for (design, block) in plan.designs.iter().zip(runs.chunks(per_design)) {
        for measure in Measure::ALL {
            let values: Vec<Option<f64>> =
                block.iter().map(|r| measure.of(r, tau, clock)).collect();
            let columns: Vec<&[Option<f64>]> = values.chunks(rows).collect();
            // A row counts only where every matrix has a value.
            let kept: Vec<usize> = (0..rows)
                .filter(|&j| columns.iter().all(|c| c[j].is_some()))
                .collect();
            let take = |c: &[Option<f64>]| -> Vec<f64> {
                kept.iter().map(|&j| c[j].unwrap_or_default()).collect()
            };
            let (a, b) = (take(columns[0]), take(columns[1]));
            let ab: Vec<Vec<f64>> = columns[2..].iter().map(|c| take(c)).collect();
            let mut rng = stream(plan.file.seed, Some(design.id), 0, Purpose::Sensitivity);
            let found = indices(
                &PickFreeze {
                    a: &a,
                    b: &b,
                    ab: &ab,
                },
                RESAMPLES,
                &mut rng,
            );
            for (i, input) in inputs.iter().enumerate() {
                let (index, note) = match &found {
                    Ok(all) => (Some(all[i].clone()), None),
                    Err(e) => (None, Some(e.to_string())),
                };
                out.push(SensitivityRow {
                    design_id: design.id,
                    measure,
                    input: input.name.clone(),
                    kind: input.kind,
                    index,
                    rows: kept.len() as u32,
                    note,
                });
            }
        }
    }
    out
}

/// Write sensitivity.parquet into the study's folder (with its provenance);
/// the caller claimed the folder.
pub fn write(plan: &StudyPlan, rows: &[SensitivityRow]) -> PolarsResult<std::path::PathBuf> {
    let dir = crate::study::run::output_dir(plan, None);
    std::fs::create_dir_all(&dir)?;
    let path = dir.join(FILE);
    let provenance =
        crate::study::results::io::Provenance::new(&plan.text, plan.file.seed, "sensitivity");
    crate::study::results::io::write_parquet(&path, &mut to_dataframe(rows)?, &provenance)?;
    Ok(path)
}

/// One input's total index as sensitivity.parquet records it.
#[derive(Debug, Clone, PartialEq)]
pub struct InputTotal {
    /// The input's name.
    pub input: String,
    /// What kind of input it is (from the study's inputs, by name).
    pub kind: InputKind,
    /// Its total index (raw estimate).
    pub total: f64,
    /// The index's 95 % bootstrap interval.
    pub interval: (f64, f64),
}

/// Each input's total index on `measure` for `design`, largest first, from
/// the sensitivity.parquet in `dir` when `study sensitivity` wrote one for
/// this very study file (its recorded hash matches); `None` otherwise.
pub fn read_totals(
    plan: &StudyPlan,
    dir: &std::path::Path,
    design: u32,
    measure: Measure,
) -> Option<Vec<InputTotal>> {
    let path = dir.join(FILE);
    let recorded = crate::study::results::io::read_metadata(&path).ok()?;
    let hash = recorded.iter().find(|(k, _)| k == "study_sha256")?;
    if !crate::study::results::io::same_study(&hash.1, &plan.text) {
        return None;
    }
    let df = crate::study::results::io::read_parquet(&path).ok()?;
    let col = |name: &str| df.column(name).ok().cloned();
    let (d, m, input) = (col("design_id")?, col("measure")?, col("input")?);
    let (t, lo, hi) = (
        col("total_order")?,
        col("total_order_lo")?,
        col("total_order_hi")?,
    );
    let (d, m, input) = (d.u32().ok()?, m.str().ok()?, input.str().ok()?);
    let (t, lo, hi) = (t.f64().ok()?, lo.f64().ok()?, hi.f64().ok()?);
    let kinds = inputs(plan);
    let mut out: Vec<InputTotal> = (0..df.height())
        .filter(|&i| d.get(i) == Some(design) && m.get(i) == Some(measure.name()))
        .filter_map(|i| {
            let name = input.get(i)?;
            Some(InputTotal {
                input: name.to_string(),
                kind: kinds.iter().find(|k| k.name == name)?.kind,
                total: t.get(i)?,
                interval: (lo.get(i)?, hi.get(i)?),
            })
        })
        .collect();
    out.sort_by(|a, b| b.total.total_cmp(&a.total));
    (!out.is_empty()).then_some(out)
}

/// The file the analysis writes into the study's folder.
pub const FILE: &str = "sensitivity.parquet";

/// The rows as sensitivity.parquet holds them (one row per design, measure
/// and input; indices null with a note where they are undefined).
pub fn to_dataframe(rows: &[SensitivityRow]) -> PolarsResult<DataFrame> {
    let pick = |f: fn(&SobolIndex) -> f64| -> Vec<Option<f64>> {
        rows.iter().map(|r| r.index.as_ref().map(f)).collect()
    };
    df!(
        "design_id" => rows.iter().map(|r| r.design_id).collect::<Vec<_>>(),
        "measure" => rows.iter().map(|r| r.measure.name()).collect::<Vec<_>>(),
        "input" => rows.iter().map(|r| r.input.clone()).collect::<Vec<_>>(),
        "input_kind" => rows.iter().map(|r| r.kind.name()).collect::<Vec<_>>(),
        "first_order" => pick(|i| i.first),
        "first_order_lo" => pick(|i| i.first_ci.0),
        "first_order_hi" => pick(|i| i.first_ci.1),
        "total_order" => pick(|i| i.total),
        "total_order_lo" => pick(|i| i.total_ci.0),
        "total_order_hi" => pick(|i| i.total_ci.1),
        "rows" => rows.iter().map(|r| r.rows).collect::<Vec<_>>(),
        "note" => rows.iter().map(|r| r.note.clone()).collect::<Vec<_>>(),
    )
}
