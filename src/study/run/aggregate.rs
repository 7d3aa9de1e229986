//! Per-design statistics of a study (`summary.parquet`), computed with polars.
//!
//! Settling statistics count every run: a run that did not settle is a
//! censored observation (Kaplan–Meier median and restricted mean, in
//! revolutions), never dropped; the best design is compared with every
//! other on paired runs ([`crate::decide::verdict`]). Residual vibration uses every
//! run that was simulated to the end (settled or not), i.e. the distribution
//! over the sampled unbalances; diverged and failed runs are counted.

use crate::decide::diagnosis::{
    DesignFacts, UnsettledRun, dead_band, diagnose, floor_reach, run_breakaways, settling_band,
};
use crate::decide::verdict::{
    BestVersusRest, LEVEL, SettlingClock, best_versus_rest, design_runs, measure_scale, pareto_set,
};
use crate::metrics::Outcome;
use crate::model::gap::GapGauge;
use crate::stats::interval::wilson_interval;
use crate::stats::quantile::{Interpolation, quantile_sorted};
use crate::stats::survival::Transform;
use crate::study::plan::config::StudyPlan;
use crate::study::plan::criterion::Criterion;
use crate::study::plan::design::Design;
use crate::study::results::measured_runs::{DesignRuns, Scale};
use crate::study::results::record::{RunRecord, to_dataframe};
use polars::prelude::*;

/// Non-null values of a column, sorted for [`quantile_sorted`].
///
/// The quantiles were polars's `QuantileMethod::Linear` (and its `median`),
/// which [`Interpolation::Linear`] reproduces bit for bit: same position,
/// same formula. Polars orders −0.0 with +0.0 and every NaN last, where
/// `f64::total_cmp` does not; neither value occurs here, as settling times
/// are (t − t₀)/T with t ≥ t₀ and residuals are RMS/A_ref of finite runs.
fn sorted_values(ca: &Float64Chunked) -> Vec<f64> {
    let mut v: Vec<f64> = ca.iter().flatten().collect();
    v.sort_by(f64::total_cmp);
    v
}

/// How runs that ended `diverged`, `solver_failed` or `budget_exceeded`
/// enter the statistics (stored beside them in `summary.parquet`).
pub const FAILED_RUNS_COUNTED: &str = "as not settled within the run (censored at the horizon τ) in every settling statistic; left out of the residual statistics";

/// One row per design, in design order.
pub fn summarize(plan: &StudyPlan, runs: &[RunRecord]) -> PolarsResult<DataFrame> {
    summarize_table(plan, &to_dataframe(runs)?)
}

/// One row per design from a runs table holding at least the columns in
/// [`crate::study::results::runs_file::SUMMARY_COLUMNS`].
pub fn summarize_table(plan: &StudyPlan, df: &DataFrame) -> PolarsResult<DataFrame> {
    let design_col = df.column("design_id")?.u32()?.clone();
    let study = StudyRuns::read(plan, df)?;
    let mut rows = SummaryColumns::default();
    for design in &plan.designs {
        let mine = df.filter(&design_col.equal(design.id))?;
        rows.push_design(&study, design, &mine)?;
    }
    let mut summary = rows.into_dataframe()?;
    crate::study::plan::plane_designs::append_columns(&mut summary, &plan.designs)?;
    crate::decide::plane_summary::append_columns(
        &mut summary,
        df,
        plan,
        study.scale.tau,
        study.clock,
    )?;
    append_peak_whirl(&mut summary, df)?;
    Ok(summary)
}

/// What every design's row is measured against: the designs' runs on the
/// study's clock, the verdicts and the Pareto set over all of them.
struct StudyRuns<'p> {
    plan: &'p StudyPlan,
    scale: Scale,
    clock: SettlingClock,
    by_design: Vec<DesignRuns>,
    /// A run-up also reports the clock from t = 0, beside the one it ranks on.
    from_start: Option<Vec<DesignRuns>>,
    criterion: Criterion,
    /// The analytic and linear rungs predict settling; they integrate nothing.
    estimated: bool,
    /// The planes every design's balancers fill (its own, or its spec in each).
    balancer_planes: u32,
    verdicts: Option<BestVersusRest>,
    pareto: Vec<u32>,
    /// The most runs any design has (every run is a row, failed ones too).
    most_runs: usize,
}

impl<'p> StudyRuns<'p> {
    /// The runs table read per design, and the comparisons across designs.
    fn read(plan: &'p StudyPlan, df: &DataFrame) -> PolarsResult<Self> {
        let scale = measure_scale(plan);
        let clock = SettlingClock::of(plan);
        let by_design = design_runs(df, scale.tau, clock)?;
        let from_start = match clock {
            SettlingClock::FromStart => None,
            SettlingClock::FromOperatingSpeed(_) => {
                Some(design_runs(df, scale.tau, SettlingClock::FromStart)?)
            }
        };
        let criterion = plan.file.summary.rank_by;
        let verdicts = best_versus_rest(
            &by_design,
            criterion,
            &scale,
            plan.file.statistics.alpha,
            plan.file.sampling.common_random_numbers,
            plan.file.seed,
        );
        let pareto = pareto_set(&by_design, &plan.file.summary.pareto, &scale);
        let most_runs = by_design
            .iter()
            .map(|d| d.settling.len())
            .max()
            .unwrap_or(0);
        Ok(StudyRuns {
            plan,
            scale,
            clock,
            from_start,
            criterion,
            estimated: plan.file.solver.fidelity.is_estimate(),
            balancer_planes: plan.file.scene.rotor.as_rotor().planes() as u32,
            verdicts,
            pareto,
            most_runs,
            by_design,
        })
    }

    /// A design's runs as the statistics count them, if it has any.
    fn runs(&self, id: u32) -> Option<&DesignRuns> {
        self.by_design.iter().find(|d| d.design_id == id)
    }

    /// A raced design with fewer runs than the most any design has left the
    /// race after those samples.
    fn left_race_after(&self, id: u32) -> Option<u32> {
        let runs = self.runs(id)?.settling.len();
        (crate::study::run::racing::races(self.plan) && runs < self.most_runs)
            .then_some(runs as u32)
    }

    /// The design's place in the ranking (1 for every design with runs
    /// when there is no ranking).
    fn rank_of(&self, id: u32) -> Option<u32> {
        match &self.verdicts {
            Some(v) => v.order.iter().position(|&d| d == id).map(|r| r as u32 + 1),
            None => self.runs(id).is_some().then_some(1),
        }
    }
}

/// One design's runs as the row reads them: the outcomes, the settled
/// runs and those with a residual.
struct DesignTable<'d> {
    mine: &'d DataFrame,
    outcomes: Vec<Option<Outcome>>,
    residual: Float64Chunked,
    simulated: DataFrame,
    runs_n: u64,
    settled_n: u64,
}

impl<'d> DesignTable<'d> {
    fn read(mine: &'d DataFrame) -> PolarsResult<Self> {
        let outcome = mine.column("outcome")?.str()?.clone();
        let outcomes: Vec<Option<Outcome>> =
            outcome.iter().map(|o| o.and_then(Outcome::parse)).collect();
        let settled_mask = mine.column("settled")?.bool()?.clone();
        let settled = mine.filter(&settled_mask)?;
        let simulated = mine.filter(&BooleanChunked::from_iter_values(
            "simulated".into(),
            outcomes
                .iter()
                .map(|o| o.is_some_and(Outcome::has_residual)),
        ))?;
        let residual = simulated.column("residual_rel")?.f64()?.clone();
        Ok(DesignTable {
            mine,
            runs_n: mine.height() as u64,
            settled_n: settled.height() as u64,
            outcomes,
            residual,
            simulated,
        })
    }

    /// Runs that ended with this outcome.
    fn count(&self, which: Outcome) -> u64 {
        self.outcomes.iter().filter(|&&o| o == Some(which)).count() as u64
    }
}

impl SummaryColumns {
    /// One design's row, column group by column group in the table's order.
    fn push_design(
        &mut self,
        study: &StudyRuns,
        design: &Design,
        mine: &DataFrame,
    ) -> PolarsResult<()> {
        let table = DesignTable::read(mine)?;
        self.push_identity(study, design);
        self.push_settling(study, design, &table);
        self.push_diagnosis(study, design, &table)?;
        self.failed_counted.push(FAILED_RUNS_COUNTED.to_string());
        self.vs_best_alpha.push(study.plan.file.statistics.alpha);
        self.push_residuals(study, &table)?;
        self.estimated.push(study.estimated);
        // The revolution every `*_revs` column counts in: one turn at the
        // operating speed, whatever the speed law.
        self.seconds_per_rev.push(Some(
            std::f64::consts::TAU / study.plan.file.scene.speed.nominal_speed(),
        ));
        self.push_outcomes_and_contact(study, design, &table)?;
        self.push_speed(design, mine)
    }

    /// What the design is: its grid values and geometry.
    fn push_identity(&mut self, study: &StudyRuns, design: &Design) {
        let rows = self;
        rows.design_id.push(design.id);
        rows.rank.push(study.rank_of(design.id));
        rows.rank_by.push(study.criterion.to_string());
        rows.tie_break
            .push(study.plan.file.summary.tie_break.name().to_string());
        rows.settling_from.push(study.clock.describe().to_string());
        rows.kind.push(design.spec.kind.name().to_string());
        rows.n.push(design.spec.n);
        rows.rho.push(design.rho);
        rows.rho_rule.push(match &design.spec.rho {
            crate::model::scene::RhoChoice::Rule(rule) => Some(rule.clone()),
            crate::model::scene::RhoChoice::Value(_) => None,
        });
        rows.drag.push(design.spec.drag);
        rows.capacity.push(design.capacity);
        rows.race_radius.push(design.spec.race_radius);
        rows.weight_mass.push(design.weight_mass);
        rows.roller_height.push(design.roller_length());
        rows.balancer_planes.push(study.balancer_planes);
    }

    /// How many runs settled and when: shares, Kaplan–Meier, restricted
    /// mean, the ranking's value, the verdict and the Pareto set.
    fn push_settling(&mut self, study: &StudyRuns, design: &Design, table: &DesignTable) {
        let rows = self;
        let (runs_n, settled_n) = (table.runs_n, table.settled_n);
        let (lo, hi) = wilson_interval(settled_n, runs_n);
        let runs = study.runs(design.id);
        let scale = &study.scale;
        let criterion = study.criterion;
        let verdicts = &study.verdicts;
        let pareto = &study.pareto;
        let from_start = &study.from_start;
        let left_race_after = |id| study.left_race_after(id);
        rows.runs.push(runs_n);
        rows.left_race_after.push(left_race_after(design.id));
        rows.settled.push(settled_n);
        rows.settled_fraction.push(if runs_n == 0 {
            0.0
        } else {
            settled_n as f64 / runs_n as f64
        });
        rows.settled_lo.push(lo);
        rows.settled_hi.push(hi);
        rows.ts_p90_all
            .push(runs.and_then(|r| Criterion::P90.value(r, scale)));
        let km = runs.and_then(DesignRuns::kaplan_meier);
        let median = km.as_ref().and_then(|k| k.median());
        let (median_lo, median_hi) = km.as_ref().map_or((None, None), |k| {
            k.median_interval(LEVEL, Transform::LogLog)
        });
        rows.ts_median_km.push(median);
        rows.ts_median_from_start.push(match &from_start {
            None => median,
            Some(all) => all
                .iter()
                .find(|d| d.design_id == design.id)
                .and_then(DesignRuns::kaplan_meier)
                .and_then(|k| k.median()),
        });
        rows.ts_median_km_lo.push(median_lo);
        rows.ts_median_km_hi.push(median_hi);
        let rmst = km.as_ref().map(|k| k.restricted_mean(scale.tau));
        rows.ts_rmst.push(rmst.map(|r| r.estimate));
        rows.ts_mean_settled
            .push(runs.and_then(DesignRuns::settled_mean));
        // Inside [0, τ] by construction: no clipping.
        let rmst_interval = rmst.map(|r| r.bounded_interval(LEVEL));
        rows.ts_rmst_lo.push(rmst_interval.map(|i| i.lower));
        rows.ts_rmst_hi.push(rmst_interval.map(|i| i.upper));
        rows.horizon.push(scale.tau);
        rows.rank_value
            .push(runs.and_then(|r| criterion.value(r, scale)));
        rows.push_verdict(verdicts.as_ref(), design.id);
        rows.pareto.push(pareto.contains(&design.id));
        rows.balances
            .push(runs.is_some_and(crate::decide::verdict::balances));
    }

    /// What the no-crown checks measure, and their verdict on the first.
    fn push_diagnosis(
        &mut self,
        study: &StudyRuns,
        design: &Design,
        table: &DesignTable,
    ) -> PolarsResult<()> {
        let rows = self;
        let plan = study.plan;
        let mine = table.mine;
        let outcomes = &table.outcomes;
        let runs = study.runs(design.id);
        let verdicts = &study.verdicts;
        // What the no-crown checks measure, and their verdict on the first.
        let a_ref = sorted_values(mine.column("a_ref")?.f64()?);
        let fraction = sorted_values(mine.column("unbalance_fraction")?.f64()?);
        let median_of = |v: &[f64]| quantile_sorted(v, 0.5, Interpolation::Linear);
        let plane_a_refs = crate::study::results::record::nullable_lists(mine, "plane_a_ref")?;
        // Each run's own μ_s where rolling resistance is uncertain.
        let breakaways = run_breakaways(plan, mine)?;
        let mut drawn: Vec<f64> = breakaways.iter().flatten().flatten().copied().collect();
        drawn.sort_by(f64::total_cmp);
        let facts = DesignFacts {
            breakaway_median: median_of(&drawn),
            plane_a_ref_medians: plane_medians(plane_a_refs.as_deref()),
            a_ref_median: median_of(&a_ref).unwrap_or(f64::NAN),
            unbalance_fraction_median: median_of(&fraction).unwrap_or(f64::NAN),
            over_capacity_share: if fraction.is_empty() {
                0.0
            } else {
                fraction.iter().filter(|&&f| f > 1.0).count() as f64 / fraction.len() as f64
            },
        };
        rows.a_ref_median.push(median_of(&a_ref));
        rows.settling_band
            .push(median_of(&a_ref).map(|a| settling_band(plan, a)));
        rows.dead_band.push(dead_band(plan, design));
        rows.over_capacity.push(facts.over_capacity_share);
        let diagnosis = match &verdicts {
            Some(v) if v.best == design.id && !v.works => Some(diagnose(plan, design, &facts)),
            None if runs.is_some_and(|r| !crate::decide::verdict::balances(r)) => {
                Some(diagnose(plan, design, &facts))
            }
            _ => None,
        };
        rows.unsettled_floor.push(
            unsettled_runs(
                mine,
                outcomes,
                plane_a_refs.as_deref(),
                breakaways.as_deref(),
            )?
            .and_then(|a| floor_reach(plan, design, &a))
            .map(|r| r.to_string()),
        );
        rows.diagnosis_cause
            .push(diagnosis.as_ref().map(|d| d.cause.key().to_string()));
        rows.diagnosis.push(diagnosis.map(|d| d.to_string()));
        Ok(())
    }

    /// Runs whose weights circulate instead of balancing
    /// ([`crate::metrics::circulates`]) and how much worse than no balancer
    /// they end (the range of their residual/A_ref).
    fn push_circulating(&mut self, table: &DesignTable) -> PolarsResult<()> {
        let mine = table.mine;
        let slip: Vec<Option<f64>> = match mine.column("pack_slip_rate") {
            Ok(c) => c.f64()?.iter().collect(),
            // Runs written before the column: nothing to tell.
            Err(_) => vec![None; mine.height()],
        };
        let spin = mine.column("final_spin_rate")?.f64()?;
        let settled = mine.column("settled")?.bool()?;
        let residual = mine.column("residual_rel")?.f64()?;
        let worse: Vec<f64> = (0..mine.height())
            .filter(|&i| {
                crate::metrics::circulating(settled.get(i).unwrap_or(false), slip[i], spin.get(i))
            })
            .map(|i| residual.get(i).unwrap_or(f64::NAN))
            .collect();
        self.circulating.push(worse.len() as u64);
        let finite = || worse.iter().copied().filter(|r| r.is_finite());
        self.circulating_residual_min
            .push(finite().reduce(f64::min));
        self.circulating_residual_max
            .push(finite().reduce(f64::max));
        Ok(())
    }

    /// The residual statistics (none for an estimate rung).
    fn push_residuals(&mut self, study: &StudyRuns, table: &DesignTable) -> PolarsResult<()> {
        let rows = self;
        let estimated = study.estimated;
        let residual = &table.residual;
        let runs_n = table.runs_n;
        let simulated = &table.simulated;
        // An estimate rung measures no residual: its zeros are not data, so
        // no residual statistic is written (before 2026-11-27 the analytic
        // rung printed "residual p95 0.00 µm" as if measured).
        let measured = |v: Option<f64>| v.filter(|_| !estimated);
        rows.res_mean.push(measured(residual.mean()));
        let res_sorted = sorted_values(residual);
        let res_q = |q| measured(quantile_sorted(&res_sorted, q, Interpolation::Linear));
        rows.res_median.push(res_q(0.5));
        rows.res_p95.push(res_q(0.95));
        // Over every run: a failed run has no residual and is not counted worse.
        let worse = residual.iter().flatten().filter(|&r| r > 1.0).count();
        rows.worse_than_none
            .push(measured((runs_n > 0).then(|| worse as f64 / runs_n as f64)));
        let (worse_lo, worse_hi) = wilson_interval(worse as u64, runs_n);
        let bounds = (runs_n > 0 && !estimated).then_some((worse_lo, worse_hi));
        rows.worse_than_none_lo.push(bounds.map(|b| b.0));
        rows.worse_than_none_hi.push(bounds.map(|b| b.1));
        rows.push_circulating(table)?;
        let abs_sorted = sorted_values(simulated.column("residual_abs")?.f64()?);
        rows.res_abs_p95.push(measured(quantile_sorted(
            &abs_sorted,
            0.95,
            Interpolation::Linear,
        )));
        Ok(())
    }

    /// How runs ended, and whether and how the weights were solid.
    fn push_outcomes_and_contact(
        &mut self,
        study: &StudyRuns,
        design: &Design,
        table: &DesignTable,
    ) -> PolarsResult<()> {
        let rows = self;
        let plan = study.plan;
        let mine = table.mine;
        let count = |which| table.count(which);
        rows.censored.push(count(Outcome::Censored));
        rows.not_settled.push(count(Outcome::NotSettled));
        rows.diverged.push(count(Outcome::Diverged));
        rows.solver_failed.push(count(Outcome::SolverFailed));
        rows.budget_exceeded.push(count(Outcome::BudgetExceeded));
        rows.merged.push(count(Outcome::Merged));
        // Whether the weights were solid, and how close they came in the
        // worst run (negative: they overlapped).
        let contact = mine.column("contact")?.bool()?.clone();
        rows.contact.push(contact.all());
        // How it was modelled, as the runs record it: "rigid", "penalty",
        // both joined when runs differ, null where no run modelled contact.
        let models: std::collections::BTreeSet<String> = mine
            .column("contact_model")
            .ok()
            .and_then(|c| c.str().ok().cloned())
            .map(|c| c.iter().flatten().map(str::to_string).collect())
            .unwrap_or_default();
        rows.contact_model
            .push((!models.is_empty()).then(|| models.into_iter().collect::<Vec<_>>().join("/")));
        let min_gap = mine.column("min_gap_rad")?.f64()?.min();
        rows.min_gap.push(min_gap);
        // The deepest overlap as a share of the touching angle 2α: what the
        // penalty contact lets through (docs/model.md: below 2 % by default).
        let touching = plan
            .scene(design, 0.0, 0.0)
            .cargoes()
            .ok()
            .and_then(|c| GapGauge::new(&c))
            .map(|g| g.contact_angle());
        rows.max_overlap.push(
            min_gap
                .zip(touching)
                .map(|(gap, angle)| (-gap).max(0.0) / angle),
        );
        Ok(())
    }

    /// Variable speed: how many runs passed through to the operating speed,
    /// and where the others were held (the Sommerfeld effect).
    fn push_speed(&mut self, design: &Design, mine: &DataFrame) -> PolarsResult<()> {
        let rows = self;
        rows.stall_torque.push(design.stall_torque);
        let t_op = mine.column("operating_time_s")?.f64()?;
        rows.reached_operating
            .push(t_op.is_not_null().sum().unwrap_or(0) as u64);
        rows.operating_median.push(quantile_sorted(
            &sorted_values(t_op),
            0.5,
            Interpolation::Linear,
        ));
        let spin = sorted_values(mine.column("final_spin_rate")?.f64()?);
        rows.spin_median
            .push(quantile_sorted(&spin, 0.5, Interpolation::Linear));
        Ok(())
    }
}

/// Column buffers of the summary table.
#[derive(Default)]
struct SummaryColumns {
    design_id: Vec<u32>,
    rank: Vec<Option<u32>>,
    rank_by: Vec<String>,
    tie_break: Vec<String>,
    rank_value: Vec<Option<f64>>,
    settling_from: Vec<String>,
    pareto: Vec<bool>,
    balances: Vec<bool>,
    left_race_after: Vec<Option<u32>>,
    /// Per reported measure (Criterion::REPORTED order): this − best, its
    /// interval and the Holm-adjusted p.
    vs_best_measure: [MeasureColumns; 4],
    a_ref_median: Vec<Option<f64>>,
    settling_band: Vec<Option<f64>>,
    dead_band: Vec<Option<f64>>,
    over_capacity: Vec<f64>,
    diagnosis: Vec<Option<String>>,
    diagnosis_cause: Vec<Option<String>>,
    unsettled_floor: Vec<Option<String>>,
    failed_counted: Vec<String>,
    kind: Vec<String>,
    n: Vec<u32>,
    rho: Vec<f64>,
    /// The rule that chose ρ ("optimal", "half_race"), null for a given ρ.
    rho_rule: Vec<Option<String>>,
    drag: Vec<f64>,
    capacity: Vec<f64>,
    race_radius: Vec<f64>,
    weight_mass: Vec<f64>,
    roller_height: Vec<Option<f64>>,
    balancer_planes: Vec<u32>,
    runs: Vec<u64>,
    settled: Vec<u64>,
    settled_fraction: Vec<f64>,
    settled_lo: Vec<f64>,
    settled_hi: Vec<f64>,
    ts_median_km: Vec<Option<f64>>,
    ts_median_from_start: Vec<Option<f64>>,
    ts_median_km_lo: Vec<Option<f64>>,
    ts_median_km_hi: Vec<Option<f64>>,
    ts_mean_settled: Vec<Option<f64>>,
    ts_rmst: Vec<Option<f64>>,
    ts_rmst_lo: Vec<Option<f64>>,
    ts_rmst_hi: Vec<Option<f64>>,
    horizon: Vec<f64>,
    ts_p90_all: Vec<Option<f64>>,
    vs_best_verdict: Vec<String>,
    vs_best_test: Vec<Option<String>>,
    vs_best_share: Vec<Option<f64>>,
    vs_best_share_lo: Vec<Option<f64>>,
    vs_best_share_hi: Vec<Option<f64>>,
    vs_best_diff: Vec<Option<f64>>,
    vs_best_diff_lo: Vec<Option<f64>>,
    vs_best_diff_hi: Vec<Option<f64>>,
    vs_best_p_holm: Vec<Option<f64>>,
    vs_best_alpha: Vec<f64>,
    res_mean: Vec<Option<f64>>,
    res_median: Vec<Option<f64>>,
    res_p95: Vec<Option<f64>>,
    worse_than_none: Vec<Option<f64>>,
    worse_than_none_lo: Vec<Option<f64>>,
    worse_than_none_hi: Vec<Option<f64>>,
    /// Runs whose weights circulate, and their residual/A_ref range.
    circulating: Vec<u64>,
    circulating_residual_min: Vec<Option<f64>>,
    circulating_residual_max: Vec<Option<f64>>,
    estimated: Vec<bool>,
    /// 95th percentile of the residual whirl in metres.
    res_abs_p95: Vec<Option<f64>>,
    /// Seconds per revolution of the operating speed (the unit of every `*_revs` column).
    seconds_per_rev: Vec<Option<f64>>,
    censored: Vec<u64>,
    not_settled: Vec<u64>,
    diverged: Vec<u64>,
    solver_failed: Vec<u64>,
    budget_exceeded: Vec<u64>,
    merged: Vec<u64>,
    contact: Vec<bool>,
    contact_model: Vec<Option<String>>,
    min_gap: Vec<Option<f64>>,
    max_overlap: Vec<Option<f64>>,
    stall_torque: Vec<Option<f64>>,
    reached_operating: Vec<u64>,
    operating_median: Vec<Option<f64>>,
    spin_median: Vec<Option<f64>>,
}

/// One measure's comparison with the best design, per design.
#[derive(Default)]
struct MeasureColumns {
    diff: Vec<Option<f64>>,
    lo: Vec<Option<f64>>,
    hi: Vec<Option<f64>>,
    p_holm: Vec<Option<f64>>,
}

/// A finite value, or `None` (an infinite paired median difference means
/// that in half the pairs or more one design did not settle).
fn finite(x: f64) -> Option<f64> {
    // + 0.0 turns a −0.0 (the negation of an exact 0) into 0.0.
    x.is_finite().then_some(x + 0.0)
}

impl SummaryColumns {
    /// The comparison of design `id` with the best design (nothing for the
    /// best itself, or when there is only one design).
    fn push_verdict(&mut self, verdicts: Option<&BestVersusRest>, id: u32) {
        let other = verdicts.and_then(|v| v.others.iter().find(|(c, _, _)| c.b == id));
        self.vs_best_verdict.push(match (verdicts, other) {
            (Some(v), _) if v.best == id && v.works => "best".to_string(),
            (Some(v), _) if v.best == id => "no_design_balances".to_string(),
            (_, Some((_, _, verdict))) => verdict.name().to_string(),
            _ => "only_design".to_string(),
        });
        let paired = other.and_then(|(c, _, _)| c.paired.as_ref());
        let on_criterion = other.and_then(|(c, _, _)| c.measures.first());
        self.vs_best_test
            .push(on_criterion.and_then(|m| m.difference.map(|d| d.test.to_string())));
        self.vs_best_share.push(paired.map(|p| p.a_sooner_share));
        self.vs_best_share_lo
            .push(paired.map(|p| p.a_sooner_share_interval.0));
        self.vs_best_share_hi
            .push(paired.map(|p| p.a_sooner_share_interval.1));
        self.vs_best_diff
            .push(paired.and_then(|p| finite(p.median_difference)));
        self.vs_best_diff_lo
            .push(paired.and_then(|p| finite(p.median_difference_interval.0)));
        self.vs_best_diff_hi
            .push(paired.and_then(|p| finite(p.median_difference_interval.1)));
        self.vs_best_p_holm.push(other.map(|(_, p, _)| *p));
        for (k, measure) in Criterion::REPORTED.iter().enumerate() {
            let m = other.and_then(|(c, _, _)| c.on(*measure));
            let d = m.and_then(|m| m.difference);
            let columns = &mut self.vs_best_measure[k];
            // Stored as this design minus the best.
            columns.diff.push(d.and_then(|d| finite(-d.difference)));
            columns.lo.push(d.and_then(|d| finite(-d.interval.1)));
            columns.hi.push(d.and_then(|d| finite(-d.interval.0)));
            columns.p_holm.push(m.map(|m| m.p_holm));
        }
    }

    fn into_dataframe(self) -> PolarsResult<DataFrame> {
        let height = self.design_id.len();
        let mut measures = Vec::new();
        for (measure, columns) in Criterion::REPORTED.iter().zip(self.vs_best_measure) {
            let name = measure.to_string();
            measures.push(Column::new(
                format!("vs_best_{name}_diff").into(),
                columns.diff,
            ));
            measures.push(Column::new(
                format!("vs_best_{name}_diff_lo").into(),
                columns.lo,
            ));
            measures.push(Column::new(
                format!("vs_best_{name}_diff_hi").into(),
                columns.hi,
            ));
            measures.push(Column::new(
                format!("vs_best_{name}_p_holm").into(),
                columns.p_holm,
            ));
        }
        let mut columns = vec![
            Column::new("design_id".into(), self.design_id),
            Column::new("rank".into(), self.rank),
            Column::new("rank_by".into(), self.rank_by),
            Column::new("tie_break".into(), self.tie_break),
            Column::new("rank_value".into(), self.rank_value),
            Column::new("settling_from".into(), self.settling_from),
            Column::new("pareto".into(), self.pareto),
            Column::new("balances".into(), self.balances),
            Column::new("kind".into(), self.kind),
            Column::new("n".into(), self.n),
            Column::new("rho".into(), self.rho),
            Column::new("rho_rule".into(), self.rho_rule),
            Column::new("drag".into(), self.drag),
            Column::new("capacity".into(), self.capacity),
            Column::new("race_radius".into(), self.race_radius),
            Column::new("weight_mass".into(), self.weight_mass),
            Column::new("roller_height".into(), self.roller_height),
            Column::new("balancer_planes".into(), self.balancer_planes),
            Column::new("runs".into(), self.runs),
            Column::new("left_race_after".into(), self.left_race_after),
            Column::new("settled".into(), self.settled),
            Column::new("settled_fraction".into(), self.settled_fraction),
            Column::new("settled_fraction_lo".into(), self.settled_lo),
            Column::new("settled_fraction_hi".into(), self.settled_hi),
            Column::new("settling_revs_median_km".into(), self.ts_median_km),
            Column::new("settling_revs_median_km_lo".into(), self.ts_median_km_lo),
            Column::new(
                "settling_revs_median_km_from_start".into(),
                self.ts_median_from_start,
            ),
            Column::new("settling_revs_median_km_hi".into(), self.ts_median_km_hi),
            Column::new("settling_revs_rmst".into(), self.ts_rmst),
            Column::new("settling_revs_rmst_lo".into(), self.ts_rmst_lo),
            Column::new("settling_revs_rmst_hi".into(), self.ts_rmst_hi),
            Column::new("settling_revs_mean_settled".into(), self.ts_mean_settled),
            Column::new("settling_horizon_revs".into(), self.horizon),
            Column::new("settling_revs_p90_all_runs".into(), self.ts_p90_all),
            Column::new("vs_best_verdict".into(), self.vs_best_verdict),
            Column::new("vs_best_test".into(), self.vs_best_test),
            Column::new("vs_best_sooner_share".into(), self.vs_best_share),
            Column::new("vs_best_sooner_share_lo".into(), self.vs_best_share_lo),
            Column::new("vs_best_sooner_share_hi".into(), self.vs_best_share_hi),
            Column::new("vs_best_median_diff_revs".into(), self.vs_best_diff),
            Column::new("vs_best_median_diff_revs_lo".into(), self.vs_best_diff_lo),
            Column::new("vs_best_median_diff_revs_hi".into(), self.vs_best_diff_hi),
            Column::new("vs_best_p_holm".into(), self.vs_best_p_holm),
            Column::new("vs_best_alpha".into(), self.vs_best_alpha),
            Column::new("residual_rel_mean".into(), self.res_mean),
            Column::new("residual_rel_median".into(), self.res_median),
            Column::new("residual_rel_p95".into(), self.res_p95),
            Column::new("worse_than_none_fraction".into(), self.worse_than_none),
            Column::new("worse_than_none_lo".into(), self.worse_than_none_lo),
            Column::new("worse_than_none_hi".into(), self.worse_than_none_hi),
            Column::new("circulating_runs".into(), self.circulating),
            Column::new(
                "circulating_residual_rel_min".into(),
                self.circulating_residual_min,
            ),
            Column::new(
                "circulating_residual_rel_max".into(),
                self.circulating_residual_max,
            ),
            Column::new("estimated".into(), self.estimated),
            Column::new("residual_abs_p95".into(), self.res_abs_p95),
            Column::new("seconds_per_rev".into(), self.seconds_per_rev),
            Column::new("censored".into(), self.censored),
            Column::new("not_settled".into(), self.not_settled),
            Column::new("diverged".into(), self.diverged),
            Column::new("solver_failed".into(), self.solver_failed),
            Column::new("budget_exceeded".into(), self.budget_exceeded),
            Column::new("merged".into(), self.merged),
            Column::new("contact".into(), self.contact),
            Column::new("contact_model".into(), self.contact_model),
            Column::new("min_gap_rad".into(), self.min_gap),
            Column::new("max_overlap_fraction".into(), self.max_overlap),
            Column::new("stall_torque".into(), self.stall_torque),
            Column::new("reached_operating_speed".into(), self.reached_operating),
            Column::new("operating_time_s_median".into(), self.operating_median),
            Column::new("final_spin_rate_median".into(), self.spin_median),
            Column::new("a_ref_median".into(), self.a_ref_median),
            Column::new("settling_band_m".into(), self.settling_band),
            Column::new("dead_band_m".into(), self.dead_band),
            Column::new("over_capacity_share".into(), self.over_capacity),
            Column::new("diagnosis".into(), self.diagnosis),
            Column::new("diagnosis_cause".into(), self.diagnosis_cause),
            Column::new("unsettled_floor".into(), self.unsettled_floor),
            Column::new("failed_runs_counted".into(), self.failed_counted),
        ];
        columns.extend(measures);
        DataFrame::new(height, columns)
    }
}

/// Each watched plane's median A_ref over a design's runs (empty when the
/// runs carry one plane or none).
fn plane_medians(lists: Option<&[Vec<Option<f64>>]>) -> Vec<f64> {
    let Some(lists) = lists else {
        return Vec::new();
    };
    let planes = lists.iter().map(Vec::len).max().unwrap_or(0);
    if planes < 2 {
        return Vec::new();
    }
    (0..planes)
        .map(|p| {
            let mut v: Vec<f64> = lists
                .iter()
                .filter_map(|l| l.get(p).copied().flatten())
                .collect();
            v.sort_by(f64::total_cmp);
            quantile_sorted(&v, 0.5, Interpolation::Linear).unwrap_or(f64::NAN)
        })
        .collect()
}

/// The start-up whirl columns, in the summary's design order: the median
/// and 95th percentile of each design's runs' `peak_r / a_ref`
/// ([`crate::metrics::peak_whirl`]); null where no run has one, or the runs
/// table has no `peak_r`.
fn append_peak_whirl(summary: &mut DataFrame, runs: &DataFrame) -> PolarsResult<()> {
    let ids: Vec<Option<u32>> = summary.column("design_id")?.u32()?.iter().collect();
    let mut stats = vec![None; ids.len()];
    if let Ok(peak) = runs.column("peak_r") {
        let peak = peak.f64()?;
        let design = runs.column("design_id")?.u32()?;
        let a_ref = runs.column("a_ref")?.f64()?;
        let outcome = runs.column("outcome")?.str()?;
        let mut ratios = vec![Vec::new(); ids.len()];
        for i in 0..runs.height() {
            let row = design
                .get(i)
                .and_then(|d| ids.iter().position(|&id| id == Some(d)));
            let ratio = match (
                outcome.get(i).and_then(Outcome::parse),
                peak.get(i),
                a_ref.get(i),
            ) {
                (Some(o), Some(p), Some(a)) => crate::metrics::peak_whirl::peak_over_a_ref(o, p, a),
                _ => None,
            };
            if let (Some(row), Some(ratio)) = (row, ratio) {
                ratios[row].push(ratio);
            }
        }
        stats = ratios
            .into_iter()
            .map(crate::metrics::peak_whirl::median_and_p95)
            .collect();
    }
    summary.with_column(Column::new(
        "peak_whirl_over_a_ref_median".into(),
        stats.iter().map(|s| s.map(|s| s.0)).collect::<Vec<_>>(),
    ))?;
    summary.with_column(Column::new(
        "peak_whirl_over_a_ref_p95".into(),
        stats.iter().map(|s| s.map(|s| s.1)).collect::<Vec<_>>(),
    ))?;
    Ok(())
}

/// A_ref per watched plane (or the rotor's alone) and the drawn μ_s
/// (`breakaways`, where uncertain) of each run of `mine` that ended
/// censored or not settled; `None` when every run settled or failed.
fn unsettled_runs(
    mine: &DataFrame,
    outcomes: &[Option<Outcome>],
    plane_a_refs: Option<&[Vec<Option<f64>>]>,
    breakaways: Option<&[Option<f64>]>,
) -> PolarsResult<Option<Vec<UnsettledRun>>> {
    let a_ref = mine.column("a_ref")?.f64()?;
    let rows: Vec<UnsettledRun> = outcomes
        .iter()
        .enumerate()
        .filter(|(_, o)| matches!(o, Some(Outcome::Censored | Outcome::NotSettled)))
        .filter_map(|(i, _)| {
            let a_refs = match plane_a_refs.and_then(|l| l.get(i)) {
                Some(l) if l.len() > 1 => l.iter().copied().collect::<Option<Vec<f64>>>(),
                _ => a_ref.get(i).map(|a| vec![a]),
            }?;
            Some(UnsettledRun {
                a_refs,
                breakaway: breakaways.and_then(|b| b[i]),
            })
        })
        .collect();
    Ok((!rows.is_empty()).then_some(rows))
}
