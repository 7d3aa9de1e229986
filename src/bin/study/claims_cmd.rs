//! `study claims`: the virtual experiment on seed 000's design claims.

use crate::UserError;
use autobal::claims::{report::render, run_claims};
use autobal::output_file::{WhenExists, prepare};
use autobal::study::plan::config::load;
use autobal::study::run::NoProgress;
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study claims --help`.
pub const EXAMPLES: &str = "Examples:
  study claims studies/paper_claims.toml --report docs/paper-claims.md --overwrite";

/// Arguments of `study claims`.
#[derive(Args)]
pub struct ClaimsArgs {
    /// Claims study file (rotor, race, kinds, n range, drag, sampling).
    study: PathBuf,
    /// Write the markdown report here (default: print it).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Replace the --report file if it exists.
    #[arg(long, requires = "report")]
    overwrite: bool,
    /// The measure the verdicts rest on (default: the study's `[summary] rank_by`):
    /// median, mean, p90, settled_fraction, settled_by:<X>rev|s, residual_p95, p_residual_below:<X>m.
    #[arg(long, value_parser = crate::completion_values::CriterionParser, hide_possible_values = true, value_name = "CRITERION")]
    rank_by: Option<autobal::study::plan::criterion::Criterion>,
}

/// Run `study claims`.
pub fn run(args: &ClaimsArgs) -> Result<(), UserError> {
    let mut plan = load(&args.study)?;
    if let Some(path) = &args.report {
        prepare("--report", path, WhenExists::from_overwrite(args.overwrite))?;
    }
    if let Some(criterion) = args.rank_by {
        plan.file.summary.rank_by = criterion;
    }
    let out = run_claims(&plan, &NoProgress).map_err(|e| {
        let code = if e.is_user_error() { 2 } else { 1 };
        UserError(e.to_string(), code)
    })?;
    let command = format!(
        "study claims {}{}{}",
        args.study.display(),
        args.rank_by
            .map_or(String::new(), |c| format!(" --rank-by {c}")),
        args.report
            .as_ref()
            .map_or(String::new(), |r| format!(" --report {}", r.display()))
    );
    let text = render(&plan, &out, &command);
    match &args.report {
        Some(path) => {
            autobal::study::results::io::write_text(path, &text)
                .map_err(|e| UserError::internal(format!("--report {}: {e}", path.display())))?;
            eprintln!("wrote {}", path.display());
        }
        None => print!("{text}"),
    }
    Ok(())
}
