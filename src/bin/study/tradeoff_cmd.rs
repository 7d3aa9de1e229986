//! `study tradeoff`: work-precision of every fidelity and tolerance.

use crate::UserError;
use crate::output::text_table;
use autobal::output_file::WhenExists;
use autobal::study::plan::config::load;
use autobal::study::run::study_folder::claim;
use autobal::tradeoff::{measure, recommend, spread_runs, summarize, write};
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study tradeoff --help`.
pub const EXAMPLES: &str = "Examples:
  study tradeoff studies/three_balls.toml --runs 12 --budget-revs 1
  study tradeoff studies/gravity_horizontal.toml --runs 4";

/// Arguments of `study tradeoff`.
#[derive(Args)]
pub struct TradeoffArgs {
    /// Study file.
    study: PathBuf,
    /// How many of the study's runs to measure (spread evenly over designs).
    #[arg(long, default_value_t = 12, value_parser = crate::limits::bench_runs)]
    runs: usize,
    /// Error budget: largest acceptable settling-time error (revolutions).
    #[arg(long, default_value_t = 1.0, value_parser = crate::limits::budget_revs)]
    budget_revs: f64,
    /// Error budget on the residual vibration (units of A_ref).
    #[arg(long, default_value_t = 0.01, value_parser = crate::limits::budget_residual)]
    budget_residual: f64,
    /// Replace the study folder's tradeoff.parquet if it exists.
    #[arg(long)]
    overwrite: bool,
}

/// Run `study tradeoff`.
pub fn run(args: &TradeoffArgs) -> Result<(), UserError> {
    let plan = load(&args.study)?;
    let _folder = claim(
        &plan,
        "tradeoff",
        &["tradeoff.parquet"],
        WhenExists::from_overwrite(args.overwrite),
    )?;
    let rows = measure(&plan, &spread_runs(&plan, args.runs as u64));
    let path = write(&plan, &rows).map_err(|e| UserError::internal(e.to_string()))?;
    let summary = summarize(&rows);
    let f = |v: Option<f64>| v.map_or("–".into(), |x| format!("{x:.3}"));
    let table: Vec<Vec<String>> = summary
        .iter()
        .map(|s| {
            vec![
                s.setting.label(),
                f(s.median_error_revs),
                f(s.max_error_revs),
                format!("{:.1e}", s.max_residual_error),
                format!("{:.0} %", 100.0 * s.outcome_agreement),
                format!("{:.0}", s.mean_rhs_calls),
                format!("{:.3}", 1e3 * s.mean_wall_time_s),
                s.same_best
                    .map_or("–".into(), |b| if b { "yes" } else { "NO" }.into()),
                s.kendall_tau.map_or("–".into(), |t| format!("{t:.2}")),
            ]
        })
        .collect();
    print!(
        "{}",
        text_table(
            &[
                "setting",
                "median\n|Δt_s| rev",
                "max\n|Δt_s| rev",
                "max |Δresidual|\n/A_ref",
                "outcome\nagrees",
                "RHS\ncalls",
                "ms/run",
                "same #1\ndesign",
                "rank corr.\n(Kendall)"
            ],
            &table
        )
    );
    let ranked = summary.first().map_or(0, |s| s.designs_ranked);
    if ranked >= 2 {
        crate::output::say(&format!(
            "(same #1 design, rank corr.: each setting's ranking of the {ranked} designs measured, by the restricted mean settling time of their measured runs, against the reference's on the same runs; Kendall's τ-b, 1 = the same order)"
        ));
    }
    match recommend(&summary, args.budget_revs, args.budget_residual) {
        Some(best) => crate::output::say(&format!(
            "recommended within {} rev and {} A_ref{}: {} ({:.3} ms/run, {:.0} RHS calls); set {}",
            args.budget_revs,
            args.budget_residual,
            if ranked >= 2 {
                ", ranking the same design first"
            } else {
                ""
            },
            best.setting.label(),
            1e3 * best.mean_wall_time_s,
            best.mean_rhs_calls,
            best.setting.keys()
        )),
        None => crate::output::say(&format!(
            "no setting stays within {} rev on every measured run",
            args.budget_revs
        )),
    }
    crate::output::say_err(&format!(
        "reference: {}; wrote {}",
        autobal::tradeoff::reference(&plan).label(),
        path.display()
    ));
    Ok(())
}
