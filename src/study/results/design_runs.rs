//! Each design's runs read from a runs table as the statistics see them:
//! settling observations (censored where a run did not settle) and
//! residuals, counted with the plan's clock and horizon τ.

use crate::metrics::Outcome;
use crate::stats::survival::Observation;
use crate::study::plan::config::StudyPlan;
pub use crate::study::results::measured_runs::DesignRuns;
use crate::study::results::measured_runs::Scale;
use polars::prelude::*;

/// The latest settling time a run of the plan can show (revolutions) on
/// the plan's clock ([`SettlingClock::of`]): the end of the run less the
/// hold window, and on a ramp less the ramp too, since a run-up's times
/// count from the moment the speed is reached. Runs that never settled
/// are censored here, and the restricted mean, the capped times of the
/// paired mean test and the p90 all run up to it: one τ for
/// `summary.parquet`, `study compare`, `study claims` and `study optimize`.
///
/// A motor's run-up has no time known before the run (its speed only
/// approaches the synchronous one): each run is censored at what it
/// showed after reaching speed, and τ stays t_end − hold.
pub fn settling_horizon(plan: &StudyPlan) -> f64 {
    let metrics = &plan.file.metrics;
    let whole = metrics.t_end_revs - metrics.hold_revs;
    match SettlingClock::of(plan) {
        SettlingClock::FromStart => whole,
        SettlingClock::FromOperatingSpeed(rev_seconds) => {
            let ramp = plan.file.scene.speed.operating_time().unwrap_or(0.0) / rev_seconds;
            // Before 2026-12-07 τ counted the ramp's revolutions too: a run
            // that never settled counted 550 rev where 317 were observable.
            (whole - ramp).max(0.0)
        }
    }
}

/// τ and the length of a revolution of `plan`.
pub fn measure_scale(plan: &StudyPlan) -> Scale {
    Scale {
        tau: settling_horizon(plan),
        rev_seconds: 2.0 * std::f64::consts::PI / plan.file.scene.speed.nominal_speed(),
    }
}

/// Where settling times are counted from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SettlingClock {
    /// From t = 0 (a constant speed: the rotor runs at speed from the start).
    FromStart,
    /// From the moment the rotor reached its operating speed (a run-up):
    /// what the balancer takes, not the motor. One revolution lasts this
    /// many seconds.
    FromOperatingSpeed(f64),
}

impl SettlingClock {
    /// The clock a plan's statistics use: from the operating speed whenever
    /// the speed law is not constant.
    pub fn of(plan: &StudyPlan) -> Self {
        match plan.file.scene.speed {
            crate::model::speed::SpeedLaw::Constant { .. } => SettlingClock::FromStart,
            ref law => {
                SettlingClock::FromOperatingSpeed(2.0 * std::f64::consts::PI / law.nominal_speed())
            }
        }
    }

    /// What tables say about it.
    pub fn describe(self) -> &'static str {
        match self {
            SettlingClock::FromStart => "from t = 0",
            SettlingClock::FromOperatingSpeed(_) => {
                "from the moment the operating speed was reached"
            }
        }
    }
}

/// What a run recorded of its timing (columns of runs.parquet).
#[derive(Debug, Clone, Copy)]
pub struct RunTimes {
    /// `settled`.
    pub settled: Option<bool>,
    /// `settling_revs`.
    pub settling_revs: Option<f64>,
    /// `censoring_revs`.
    pub censoring_revs: Option<f64>,
    /// `operating_time_s`.
    pub operating_time_s: Option<f64>,
}

/// One run's settling as the statistics count it: settled at its time, or
/// censored (at `censoring_revs`, else the horizon), on `clock`.
pub fn settling_observation(run: RunTimes, horizon: f64, clock: SettlingClock) -> Observation {
    let offset = match clock {
        SettlingClock::FromStart => 0.0,
        SettlingClock::FromOperatingSpeed(rev) => run.operating_time_s.map_or(0.0, |t| t / rev),
    };
    match (run.settled, run.settling_revs) {
        (Some(true), Some(t)) => Observation {
            time: (t - offset).max(0.0),
            settled: true,
        },
        // A run without a censoring time (it failed, or stopped early) is
        // counted as not settled up to the horizon, which is already on
        // the plan's clock.
        _ => Observation {
            time: run
                .censoring_revs
                .map_or(horizon, |c| (c - offset).min(horizon))
                .max(0.0),
            settled: false,
        },
    }
}

/// Every design's runs from a runs table holding the columns of
/// [`crate::study::results::runs_file::SUMMARY_COLUMNS`], in design order (designs without
/// runs are left out).
///
/// With [`SettlingClock::FromOperatingSpeed`], every time is counted from
/// the run's `operating_time_s` (a run that never reached the operating
/// speed keeps its censoring time: it is known not to have settled by then).
pub fn design_runs(
    df: &DataFrame,
    horizon: f64,
    clock: SettlingClock,
) -> PolarsResult<Vec<DesignRuns>> {
    let design = df.column("design_id")?.u32()?;
    let sample = df.column("sample_id")?.u32()?;
    let outcome = df.column("outcome")?.str()?;
    let settled = df.column("settled")?.bool()?;
    let revs = df.column("settling_revs")?.f64()?;
    let censoring = df.column("censoring_revs")?.f64()?;
    let residual = df.column("residual_rel")?.f64()?;
    let residual_abs = df.column("residual_abs")?.f64()?;
    let operating = df.column("operating_time_s")?.f64()?;
    let mut out: Vec<DesignRuns> = Vec::new();
    let mut rows: Vec<usize> = (0..df.height()).collect();
    rows.sort_by_key(|&i| (design.get(i), sample.get(i)));
    for i in rows {
        let id = design.get(i).unwrap_or_default();
        if out.last().is_none_or(|d| d.design_id != id) {
            out.push(DesignRuns {
                design_id: id,
                sample_ids: Vec::new(),
                settling: Vec::new(),
                residual: Vec::new(),
                residual_abs: Vec::new(),
            });
        }
        let d = out.last_mut().expect("pushed above");
        let observation = settling_observation(
            RunTimes {
                settled: settled.get(i),
                settling_revs: revs.get(i),
                censoring_revs: censoring.get(i),
                operating_time_s: operating.get(i),
            },
            horizon,
            clock,
        );
        let simulated = outcome
            .get(i)
            .and_then(Outcome::parse)
            .is_some_and(Outcome::has_residual);
        d.sample_ids.push(sample.get(i).unwrap_or_default());
        d.settling.push(observation);
        d.residual
            .push(residual.get(i).filter(|r| simulated && r.is_finite()));
        d.residual_abs
            .push(residual_abs.get(i).filter(|r| simulated && r.is_finite()));
    }
    Ok(out)
}
