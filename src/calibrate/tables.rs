//! A calibration's results as tables (written as Parquet by `study
//! calibrate --out`; every column in docs/results-files.md): the unknowns'
//! estimates, the points' outcomes, every weighted draw.

use super::calibration::{Calibration, Coverage};
use super::problem::RigProblem;
use polars::prelude::*;

/// One row per unknown: prior support, fit, posterior quantiles.
pub fn estimates_frame(c: &Calibration) -> PolarsResult<DataFrame> {
    let e = &c.estimates;
    let col = |f: fn(&super::calibration::Estimate) -> f64| e.iter().map(f).collect::<Vec<f64>>();
    df!(
        "key" => e.iter().map(|e| e.key.clone()).collect::<Vec<_>>(),
        "prior_min" => col(|e| e.prior.0),
        "prior_max" => col(|e| e.prior.1),
        "fit" => col(|e| e.fit),
        "p025" => col(|e| e.interval[0]),
        "median" => col(|e| e.interval[1]),
        "p975" => col(|e| e.interval[2]),
    )
}

/// One row per measured point: what was measured, the model at the fit,
/// z, the model's band and the predictive band.
pub fn points_frame(problem: &RigProblem, c: &Calibration) -> PolarsResult<DataFrame> {
    let pts = &problem.rig.points;
    let o = &c.points;
    let band = |k: usize| o.iter().map(|p| p.band.map(|b| b[k])).collect::<Vec<_>>();
    let pred = |k: usize| {
        o.iter()
            .map(|p| p.predictive.map(|b| b[k]))
            .collect::<Vec<_>>()
    };
    df!(
        "point" => (0..pts.len() as u32).collect::<Vec<_>>(),
        "case" => pts.iter().map(|p| p.case.clone()).collect::<Vec<_>>(),
        "quantity" => pts.iter().map(|p| p.quantity.name()).collect::<Vec<_>>(),
        "use" => pts.iter().map(|p| p.role.name()).collect::<Vec<_>>(),
        "rpm_lo" => pts.iter().map(|p| p.rpm.map(|r| r[0])).collect::<Vec<_>>(),
        "rpm_hi" => pts.iter().map(|p| p.rpm.map(|r| r[1])).collect::<Vec<_>>(),
        "measured" => o.iter().map(|p| p.measured).collect::<Vec<_>>(),
        "sd" => pts.iter().map(|p| p.sd).collect::<Vec<_>>(),
        "at_fit" => o.iter().map(|p| p.at_fit.as_ref().ok().copied()).collect::<Vec<_>>(),
        "z" => o.iter().map(|p| p.z).collect::<Vec<_>>(),
        "model_p025" => band(0),
        "model_median" => band(1),
        "model_p975" => band(2),
        "predictive_p025" => pred(0),
        "predictive_p975" => pred(1),
        "inside" => o.iter().map(|p| p.inside()).collect::<Vec<_>>(),
        "failure" => o.iter().map(|p| p.at_fit.as_ref().err().cloned()).collect::<Vec<_>>(),
    )
}

/// One row per draw: its stage, weight, loss, the unknowns
/// (`scene.<key>`) and each point's prediction (`point_<i>`).
pub fn draws_frame(problem: &RigProblem, c: &Calibration) -> PolarsResult<DataFrame> {
    let d = &c.draws;
    let mut columns = vec![
        Column::new(
            "stage".into(),
            d.iter()
                .map(|d| if d.from_prior { "prior" } else { "proposal" })
                .collect::<Vec<_>>(),
        ),
        Column::new("weight".into(), c.weights.clone()),
        Column::new(
            "loss".into(),
            d.iter()
                .map(|d| (d.loss < super::misfit::FAILED).then_some(d.loss))
                .collect::<Vec<_>>(),
        ),
    ];
    for (j, key) in problem.keys().iter().enumerate() {
        columns.push(Column::new(
            format!("{}{key}", crate::uncertain::COLUMN_PREFIX).into(),
            d.iter().map(|d| d.values[j]).collect::<Vec<_>>(),
        ));
    }
    for i in 0..problem.rig.points.len() {
        columns.push(Column::new(
            format!("point_{i}").into(),
            d.iter()
                .map(|d| d.predictions[i].as_ref().ok().copied())
                .collect::<Vec<_>>(),
        ));
    }
    DataFrame::new(d.len(), columns)
}

/// One row per repetition of a synthetic check: per key, the fit and
/// whether the interval covered the truth.
pub fn coverage_frame(problem: &RigProblem, c: &Coverage) -> PolarsResult<DataFrame> {
    let mut columns = vec![
        Column::new(
            "repetition".into(),
            (0..c.fits.len() as u32).collect::<Vec<_>>(),
        ),
        Column::new("effective_size".into(), c.effective_sizes.clone()),
    ];
    for (j, key) in problem.keys().iter().enumerate() {
        columns.push(Column::new(
            format!("truth.{key}").into(),
            vec![c.truth[j]; c.fits.len()],
        ));
        columns.push(Column::new(
            format!("fit.{key}").into(),
            c.fits.iter().map(|f| f[j]).collect::<Vec<_>>(),
        ));
        columns.push(Column::new(
            format!("covered.{key}").into(),
            c.covered.iter().map(|v| v[j]).collect::<Vec<_>>(),
        ));
    }
    DataFrame::new(c.fits.len(), columns)
}
