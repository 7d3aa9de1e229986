//! `study report`: one self-contained HTML page of a finished study, to
//! share: its question, ranking and verdicts, figures, the Kaplan–Meier
//! curves of the leading designs, and how to reproduce it.

use crate::UserError;
use crate::plot_cmd::plot_error;
use crate::robustness_notes::robustness_findings;
use autobal::decide::decision::StudyDecision;
use autobal::output_file::{WhenExists, prepare};
use autobal::report::{Report, question, study_figures};
use autobal::study::results::io::{read_metadata, write_text};
use autobal::study::results::results_table::{TableKind, read_table};
use autobal::text::ranking::ranking;
use clap::Args;
use std::path::{Path, PathBuf};

/// Examples shown under `study report --help`.
pub const EXAMPLES: &str = "Examples:
  study report results/three_balls --out three_balls.html
  scripts/check-report.sh three_balls.html     opens it in a headless browser";

/// Arguments of `study report`.
#[derive(Args)]
pub struct ReportArgs {
    /// The output folder of `study run` (or `study merge`).
    dir: PathBuf,
    /// The HTML file to write.
    #[arg(long)]
    out: PathBuf,
    /// Replace the --out file if it exists.
    #[arg(long)]
    overwrite: bool,
    /// How many leading designs get a Kaplan–Meier curve.
    #[arg(long, default_value_t = DEFAULT_LEADING, value_parser = clap::value_parser!(u32).range(0..=8))]
    leading: u32,
}

/// Leading designs drawn when `--leading` is not given.
const DEFAULT_LEADING: u32 = 3;

/// Refuse a folder whose runs and summary come from different studies:
/// the page would put one study's verdict beside another's runs.
fn same_study_files(runs: &Path, summary: &Path) -> Result<(), UserError> {
    let hash = |path: &Path| -> Result<Option<String>, UserError> {
        if !path.is_file() {
            let what = if path.exists() {
                "not a file"
            } else {
                "not found"
            };
            return Err(UserError(
                format!(
                    "{}: {what} (give the output folder of a finished `study run` or `study merge`)",
                    path.display()
                ),
                2,
            ));
        }
        let meta = read_metadata(path).map_err(|e| UserError(e.to_string(), 2))?;
        Ok(meta
            .into_iter()
            .find(|(k, _)| k == "study_sha256")
            .map(|(_, v)| v))
    };
    let (of_runs, of_summary) = (hash(runs)?, hash(summary)?);
    if of_runs != of_summary {
        let short = |h: &Option<String>| {
            h.as_deref().map_or("none recorded".to_string(), |h| {
                h[..h.len().min(12)].to_string()
            })
        };
        return Err(UserError(
            format!(
                "{} and {} come from different studies: their study hashes differ ({} and {}); rerun the study, or give a folder whose files belong together",
                summary.display(),
                runs.display(),
                short(&of_summary),
                short(&of_runs)
            ),
            2,
        ));
    }
    Ok(())
}

/// Run `study report`.
pub fn run(args: &ReportArgs) -> Result<(), UserError> {
    prepare(
        "--out",
        &args.out,
        WhenExists::from_overwrite(args.overwrite),
    )?;
    let summary_path = args.dir.join("summary.parquet");
    if !summary_path.is_file() {
        return Err(UserError(
            format!(
                "{}: no summary.parquet (give the output folder of a finished `study run` or `study merge`)",
                args.dir.display()
            ),
            2,
        ));
    }
    let summary =
        read_table(&summary_path, TableKind::Summary).map_err(|e| UserError(e.to_string(), 2))?;
    let runs_path = args.dir.join("runs.parquet");
    same_study_files(&runs_path, &summary_path)?;
    // A column the ranking needs beyond those checked above: still the file's fault.
    let in_summary =
        |message: String| UserError(format!("{}: {message}", summary_path.display()), 2);
    let parts =
        ranking(&summary, crate::output::layout()).map_err(|e| in_summary(e.to_string()))?;
    let study_text = autobal::input_file::read_text(&args.dir.join("study.toml"))
        .map_err(|e| UserError(format!("{}/study.toml: {e}", args.dir.display()), 2))?;
    // The leading designs' ids, in rank order, from the typed decision.
    let decision = StudyDecision::from_summary(&summary).map_err(|e| in_summary(e.to_string()))?;
    let leading = decision.leading(args.leading as usize);
    let figures = study_figures(&args.dir, &leading).map_err(plot_error)?;
    let meta = read_metadata(&runs_path).unwrap_or_default();
    let value = |key: &str| {
        meta.iter()
            .find(|(k, _)| k == key)
            .map_or("unknown".to_string(), |(_, v)| v.clone())
    };
    let title = args
        .dir
        .file_name()
        .map_or("study".into(), |n| n.to_string_lossy().into_owned());
    let lines = |text: &str| -> Vec<String> {
        text.lines()
            .filter(|l| !l.trim().is_empty())
            .map(str::to_string)
            .collect()
    };
    // A study with uncertain keys: whether #1 survives them, as `study run` says.
    let plan = autobal::study::plan::config::load(&args.dir.join("study.toml"))?;
    let mut findings = lines(&parts.findings);
    findings.extend(robustness_findings(&plan, &args.dir, &summary)?);
    let report = Report {
        title,
        question: question(&study_text),
        header: parts.header,
        rows: parts.rows,
        legend: lines(&parts.legend),
        findings,
        preformatted: parts.passage,
        causes: autobal::report::causes_table(&args.dir, &summary)?,
        figures,
        provenance: vec![
            ("autobal".into(), value("build")),
            ("git commit".into(), value("git_commit")),
            ("study file SHA-256".into(), value("study_sha256")),
            ("seed".into(), value("seed")),
            ("shard".into(), value("shard")),
            (
                "reproduce".into(),
                // Every flag that changes what the page shows: the ranking
                // the summary was made with (the study file's, or --rank-by).
                format!(
                    "study run {}/study.toml --overwrite --rank-by {} && study report {} --out {} --overwrite{}",
                    args.dir.display(),
                    decision.criterion,
                    args.dir.display(),
                    args.out.display(),
                    if args.leading == DEFAULT_LEADING {
                        String::new()
                    } else {
                        format!(" --leading {}", args.leading)
                    }
                ),
            ),
        ],
    };
    write_text(&args.out, &report.html())
        .map_err(|e| UserError::internal(format!("--out {}: {e}", args.out.display())))?;
    println!("wrote {}", args.out.display());
    Ok(())
}
