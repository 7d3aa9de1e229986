//! `causes.parquet`: one row per counterfactual re-run, a sample of the
//! leading design that did not settle run again with one effect removed
//! ([`crate::simulation::counterfactual`]). Bit-identical for a seed: no
//! wall time is kept, and the rows are in (sample, counterfactual) order.

use crate::metrics::Outcome;
use crate::simulation::counterfactual::Counterfactual;
use polars::prelude::*;

/// The file name `study run` gives the table.
pub const CAUSES_FILE: &str = "causes.parquet";

/// One re-run of a sample with one effect removed.
#[derive(Debug, Clone, PartialEq)]
pub struct CauseRun {
    /// The design re-run.
    pub design_id: u32,
    /// Its sample (the run's draws, as in runs.parquet).
    pub sample_id: u32,
    /// The effect removed.
    pub counterfactual: Counterfactual,
    /// How the re-run ended.
    pub outcome: Outcome,
    /// Whether it settled into its band and held.
    pub settled: bool,
    /// Its settling time (rev), when it settled.
    pub settling_revs: Option<f64>,
    /// Its residual over A_ref, when it was simulated to the end.
    pub residual_rel: Option<f64>,
    /// Why it ended as it did (a failed re-run's reason).
    pub reason: String,
}

/// The rows as a table.
pub fn to_dataframe(rows: &[CauseRun]) -> PolarsResult<DataFrame> {
    DataFrame::new(
        rows.len(),
        vec![
            Column::new(
                "design_id".into(),
                rows.iter().map(|r| r.design_id).collect::<Vec<_>>(),
            ),
            Column::new(
                "sample_id".into(),
                rows.iter().map(|r| r.sample_id).collect::<Vec<_>>(),
            ),
            Column::new(
                "counterfactual".into(),
                rows.iter()
                    .map(|r| r.counterfactual.key())
                    .collect::<Vec<_>>(),
            ),
            Column::new(
                "outcome".into(),
                rows.iter().map(|r| r.outcome.name()).collect::<Vec<_>>(),
            ),
            Column::new(
                "settled".into(),
                rows.iter().map(|r| r.settled).collect::<Vec<_>>(),
            ),
            Column::new(
                "settling_revs".into(),
                rows.iter().map(|r| r.settling_revs).collect::<Vec<_>>(),
            ),
            Column::new(
                "residual_rel".into(),
                rows.iter().map(|r| r.residual_rel).collect::<Vec<_>>(),
            ),
            Column::new(
                "reason".into(),
                rows.iter().map(|r| r.reason.as_str()).collect::<Vec<_>>(),
            ),
        ],
    )
}

/// The rows of a table written by [`to_dataframe`]; a row whose
/// counterfactual or outcome this build does not know is refused.
pub fn from_dataframe(df: &DataFrame) -> PolarsResult<Vec<CauseRun>> {
    let unknown = |what: &str, v: &str| {
        PolarsError::ComputeError(format!("causes.parquet: unknown {what} '{v}'").into())
    };
    let design = df.column("design_id")?.u32()?;
    let sample = df.column("sample_id")?.u32()?;
    let cf = df.column("counterfactual")?.str()?;
    let outcome = df.column("outcome")?.str()?;
    let settled = df.column("settled")?.bool()?;
    let revs = df.column("settling_revs")?.f64()?;
    let residual = df.column("residual_rel")?.f64()?;
    let reason = df.column("reason")?.str()?;
    (0..df.height())
        .map(|i| {
            let key = cf.get(i).unwrap_or_default();
            let ended = outcome.get(i).unwrap_or_default();
            Ok(CauseRun {
                design_id: design.get(i).unwrap_or_default(),
                sample_id: sample.get(i).unwrap_or_default(),
                counterfactual: Counterfactual::parse(key)
                    .ok_or_else(|| unknown("counterfactual", key))?,
                outcome: Outcome::parse(ended).ok_or_else(|| unknown("outcome", ended))?,
                settled: settled.get(i).unwrap_or(false),
                settling_revs: revs.get(i),
                residual_rel: residual.get(i),
                reason: reason.get(i).unwrap_or_default().to_string(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows survive the table both ways, a failed re-run's reason included.
    #[test]
    fn rows_read_back_as_written() {
        let rows = vec![
            CauseRun {
                design_id: 3,
                sample_id: 7,
                counterfactual: Counterfactual::RaceEccentricity,
                outcome: Outcome::Settled,
                settled: true,
                settling_revs: Some(12.5),
                residual_rel: Some(0.01),
                reason: String::new(),
            },
            CauseRun {
                design_id: 3,
                sample_id: 7,
                counterfactual: Counterfactual::Gravity,
                outcome: Outcome::SolverFailed,
                settled: false,
                settling_revs: None,
                residual_rel: None,
                reason: "step size underflow".into(),
            },
        ];
        let df = to_dataframe(&rows).unwrap();
        assert_eq!(from_dataframe(&df).unwrap(), rows);
    }
}
