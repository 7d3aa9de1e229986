//! The two halves of a regression check on a whole study: record a baseline
//! from a run, and compare a fresh run (or a finished runs file) with it.
//!
//! Seeds: by default the fresh run uses the study's own seed, i.e. the
//! baseline's random inputs. Unchanged code then reproduces the baseline
//! (bit-identically on the same platform) and a changed one is compared
//! unit by unit on the same unbalances, which is the most sensitive setting
//! and can never raise a false alarm from sampling noise; the two-sample
//! tests stay valid (conservative) because their samples are only more alike
//! than independent ones. A different seed (`seed`) draws independent
//! inputs: the honest test of the noise model, whose false-alarm rate is α.

use super::baseline::{BaselineError, Manifest, check_same_study, read_baseline, write_baseline};
use super::compare::{CheckReport, CompareError, compare};
use super::samples::design_samples;
use crate::study::plan::config::StudyPlan;
use crate::study::results::io::{read_metadata, read_parquet};
use crate::study::results::results_table::{TableKind, read_table};
use crate::study::run::{Progress, RunError, RunOptions, run_study};
use polars::prelude::PolarsError;
use std::path::{Path, PathBuf};

/// How to obtain and judge the new results.
#[derive(Debug, Clone)]
pub struct CheckOptions {
    /// Seed of the fresh run (default: the study's, i.e. the baseline's inputs).
    pub seed: Option<u64>,
    /// Family-wise false-alarm level of the Holm-corrected tests.
    pub alpha: f64,
    /// Compare this finished `runs.parquet` instead of running the study.
    pub runs: Option<PathBuf>,
    /// Root folder of the fresh run (default `<output>/check`); files go to `<root>/<name>/`.
    pub output_root: Option<PathBuf>,
    /// How to execute the fresh run.
    pub run: RunOptions,
}

/// What a check found.
#[derive(Debug)]
pub struct CheckOutcome {
    /// The verdict table.
    pub report: CheckReport,
    /// The baseline's manifest.
    pub baseline: Manifest,
    /// Seed of the new results.
    pub seed: u64,
    /// The runs file that was compared.
    pub runs_file: PathBuf,
}

/// Why a check could not reach a verdict.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// The baseline is missing, unreadable or from another study.
    #[error(transparent)]
    Baseline(#[from] BaselineError),
    /// A runs file given for comparison is unusable.
    #[error("{path}: {message}")]
    BadRuns {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
    /// Baseline and new results cannot be compared.
    #[error(transparent)]
    Compare(#[from] CompareError),
    /// The fresh run failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// Reading Parquet failed.
    #[error("parquet: {0}")]
    Polars(#[from] PolarsError),
    /// The folder a check or a baseline would write holds something else.
    #[error("{path}: {reason}")]
    Occupied {
        /// The folder.
        path: String,
        /// What is there and what to do.
        reason: String,
    },
}

pub use crate::study::run::study_folder::SCRATCH_MARK;

/// Whether `dir` may take a check's (or a baseline's) fresh run: it does
/// not exist, is empty, or holds an earlier scratch run.
fn scratch_free(dir: &Path) -> Result<(), CheckError> {
    let occupied = |reason: &str| CheckError::Occupied {
        path: dir.display().to_string(),
        reason: reason.into(),
    };
    match std::fs::read_dir(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(occupied(&format!("cannot be read: {e}"))),
        Ok(mut entries) => {
            if dir.join(SCRATCH_MARK).exists() || entries.next().is_none() {
                Ok(())
            } else {
                Err(occupied(
                    "holds results that no check or baseline wrote (e.g. a study's own runs): they are never replaced by a check; give another --out",
                ))
            }
        }
    }
}

/// Run `fresh` into its scratch folder and mark the folder as scratch. A
/// folder under the default root `<output>/check/` (`owned`) is the check's
/// own; one under a root the user named must be empty or marked.
fn run_scratch(
    fresh: &StudyPlan,
    run: &RunOptions,
    progress: &dyn Progress,
    owned: bool,
) -> Result<crate::study::run::StudyOutput, CheckError> {
    let dir = crate::study::run::output_dir(fresh, run.shard);
    if !owned {
        scratch_free(&dir)?;
    }
    // The scratch folder is rewritten by every check.
    let run = RunOptions {
        overwrite: true,
        ..run.clone()
    };
    let out = run_study(fresh, &run, progress)?;
    std::fs::write(
        dir.join(SCRATCH_MARK),
        "written by study check or study baseline\n",
    )
    .map_err(|e| CheckError::Occupied {
        path: dir.display().to_string(),
        reason: format!("cannot be marked as a check's folder: {e}"),
    })?;
    Ok(out)
}

impl CheckError {
    /// True when the error is the user's (bad baseline, runs file or options): exit code 2.
    pub fn is_user_error(&self) -> bool {
        match self {
            CheckError::Baseline(e) => e.is_user_error(),
            CheckError::BadRuns { .. } | CheckError::Compare(_) | CheckError::Occupied { .. } => {
                true
            }
            CheckError::Run(e) => e.is_user_error(),
            CheckError::Polars(e) => crate::study::results::io::is_not_parquet(e),
        }
    }
}

/// Whether a baseline may be written into `dir`: it does not exist, is
/// empty, or holds a baseline and `overwrite` says to replace it. A folder
/// holding anything else (a study's results) is never written into.
fn baseline_target_free(dir: &Path, overwrite: bool) -> Result<(), CheckError> {
    let occupied = |reason: &str| CheckError::Occupied {
        path: dir.display().to_string(),
        reason: reason.into(),
    };
    if dir.exists() && !dir.is_dir() {
        return Err(occupied("is a file, not a folder: give a folder to --out"));
    }
    let Ok(mut entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    if entries.next().is_none() {
        return Ok(());
    }
    if !dir.join(super::baseline::MANIFEST).exists() {
        return Err(occupied(
            "holds files that are not a baseline (e.g. the results of `study run`): a baseline is never written into it; give another --out",
        ));
    }
    if !overwrite {
        return Err(occupied(
            "holds a baseline already: add --overwrite to replace it",
        ));
    }
    Ok(())
}

/// Run `plan` as `study run` would and record its results as a baseline in
/// `dir` (an existing baseline there is replaced only with `run.overwrite`).
pub fn record_baseline(
    plan: &StudyPlan,
    dir: &Path,
    run: &RunOptions,
    progress: &dyn Progress,
) -> Result<Manifest, CheckError> {
    baseline_target_free(dir, run.overwrite)?;
    // Recording a baseline reruns the study into the check's scratch folder
    // (`<output>/check/<name>/`), never over the study's own results.
    let mut fresh = plan.clone();
    // A baseline holds every sample of every design: a race would drop some.
    fresh.file.sampling.racing = false;
    fresh.file.output = Path::new(&plan.file.output)
        .join("check")
        .display()
        .to_string();
    let output = run_scratch(&fresh, run, progress, true)?;
    Ok(write_baseline(dir, plan, &output.load_runs()?)?)
}

/// Compare new results of `plan` with the baseline in `baseline_dir`.
pub fn check_study(
    plan: &StudyPlan,
    baseline_dir: &Path,
    options: &CheckOptions,
    progress: &dyn Progress,
) -> Result<CheckOutcome, CheckError> {
    let baseline = read_baseline(baseline_dir)?;
    check_same_study(&baseline, plan)?;
    let (samples, seed, runs_file) = match &options.runs {
        Some(path) => {
            let seed = runs_file_seed(path, plan)?;
            (
                design_samples(
                    &read_table(path, TableKind::Runs).map_err(|e| bad_runs(path, &e))?,
                )?,
                seed,
                path.clone(),
            )
        }
        None => {
            let mut fresh = plan.clone();
            // Compared sample by sample with the baseline, which ran them all.
            fresh.file.sampling.racing = false;
            fresh.file.seed = options.seed.unwrap_or(plan.file.seed);
            let root = options
                .output_root
                .clone()
                .unwrap_or_else(|| Path::new(&plan.file.output).join("check"));
            fresh.file.output = root.display().to_string();
            let owned = options.output_root.is_none();
            let out = run_scratch(&fresh, &options.run, progress, owned)?;
            (
                design_samples(&read_parquet(&out.dir.join("runs.parquet"))?)?,
                fresh.file.seed,
                out.dir.join("runs.parquet"),
            )
        }
    };
    let report = compare(&baseline.samples, &samples, options.alpha)?;
    Ok(CheckOutcome {
        report,
        baseline: baseline.manifest,
        seed,
        runs_file,
    })
}

/// A runs file's read error, the file named once (the reader's message
/// begins with it too).
fn bad_runs(path: &Path, e: &polars::prelude::PolarsError) -> CheckError {
    let shown = path.display().to_string();
    let text = e.to_string();
    CheckError::BadRuns {
        message: text
            .strip_prefix(&format!("{shown}: "))
            .unwrap_or(&text)
            .to_string(),
        path: shown,
    }
}

/// The seed of a finished, unsharded runs file of this very study.
fn runs_file_seed(path: &Path, plan: &StudyPlan) -> Result<u64, CheckError> {
    let bad = |message: &str| CheckError::BadRuns {
        path: path.display().to_string(),
        message: message.to_string(),
    };
    if !path.is_file() {
        return Err(bad("no such file"));
    }
    let meta = read_metadata(path).map_err(|e| bad_runs(path, &e))?;
    let get = |k: &str| {
        meta.iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.as_str())
    };
    if !get("study_sha256")
        .is_some_and(|sha| crate::study::results::io::same_study(sha, &plan.text))
    {
        return Err(bad(
            "was not written by this study file (its provenance names another study)",
        ));
    }
    if get("shard") != Some("all") {
        return Err(bad(
            "holds one shard only; merge the shards with `study merge` first",
        ));
    }
    get("seed")
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| bad("has no seed in its provenance"))
}
