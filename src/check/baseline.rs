//! A baseline folder: what a study produced when it was last known good.
//!
//! - `manifest.toml`: study name and SHA-256, seed, sizes, autobal version
//!   and git commit (written last, so a folder without it is unfinished);
//! - `study.toml`: the study text, for reviewing a refresh;
//! - `runs.parquet`: one row per run, only the columns a check reads
//!   ([`super::samples::COLUMNS`]), which keeps a committed baseline small;
//! - `summary.parquet`: the study's per-design summary.
//!
//! Both Parquet files carry the usual provenance metadata as well.

use super::samples::{DesignSample, columns_of, design_samples};
use crate::study::plan::config::StudyPlan;
use crate::study::results::io::{Provenance, read_metadata, write_parquet, write_text};
use crate::study::results::record::{RunRecord, to_dataframe};
use crate::study::run::aggregate::summarize;
use polars::prelude::PolarsError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// File name of the manifest.
pub use crate::study::run::study_folder::BASELINE_MANIFEST as MANIFEST;

/// Version of the folder layout; bumped when it changes incompatibly.
pub const FORMAT: u32 = 1;

/// The manifest of a baseline.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Layout version ([`FORMAT`]).
    pub format: u32,
    /// The study's name.
    pub study_name: String,
    /// SHA-256 of the study file's text: a check refuses any other study.
    pub study_sha256: String,
    /// Master seed of the baseline run.
    pub seed: u64,
    /// Runs per design.
    pub samples: u32,
    /// Number of designs.
    pub designs: u32,
    /// Total runs stored.
    pub runs: u64,
    /// autobal version that wrote the baseline.
    pub autobal_version: String,
    /// Git commit of the source tree that wrote it.
    pub git_commit: String,
    /// When it was written (seconds since the Unix epoch, UTC).
    pub created_unix: u64,
}

/// A baseline read back.
#[derive(Debug, Clone)]
pub struct Baseline {
    /// Its folder.
    pub dir: PathBuf,
    /// Its manifest.
    pub manifest: Manifest,
    /// Its runs, per design.
    pub samples: Vec<DesignSample>,
}

/// Why a baseline cannot be written or used.
#[derive(Debug, thiserror::Error)]
pub enum BaselineError {
    /// No manifest in the folder.
    #[error(
        "{0}: no baseline here ({MANIFEST} is missing); write one with `study baseline STUDY.toml`"
    )]
    Missing(String),
    /// The manifest cannot be parsed.
    #[error("{path}: {message}")]
    BadManifest {
        /// The manifest's path.
        path: String,
        /// The parser's message.
        message: String,
    },
    /// The folder's files disagree with each other.
    #[error("{dir}: {message}; refresh the baseline with `study baseline`")]
    Inconsistent {
        /// The folder.
        dir: String,
        /// What disagrees.
        message: String,
    },
    /// The baseline belongs to another study file.
    #[error(
        "baseline {dir} was written from a different study file (its SHA-256 is {baseline}, this study's is {study}); compare against the baseline of this study, or refresh it with `study baseline` if the study was changed on purpose"
    )]
    DifferentStudy {
        /// The folder.
        dir: String,
        /// The baseline's study hash.
        baseline: String,
        /// The study's hash.
        study: String,
    },
    /// Reading or writing Parquet failed.
    #[error("parquet: {0}")]
    Polars(#[from] PolarsError),
    /// Other I/O.
    #[error("i/o: {0}")]
    Io(#[from] std::io::Error),
}

impl BaselineError {
    /// True when the error is the user's (no, bad or foreign baseline): exit code 2.
    pub fn is_user_error(&self) -> bool {
        !matches!(self, BaselineError::Io(_))
    }
}

/// Write a baseline of `plan` from its finished `runs` into `dir`.
pub fn write_baseline(
    dir: &Path,
    plan: &StudyPlan,
    runs: &[RunRecord],
) -> Result<Manifest, BaselineError> {
    std::fs::create_dir_all(dir)?;
    let manifest_path = dir.join(MANIFEST);
    // A refresh interrupted half-way must not leave the old manifest over new data.
    if manifest_path.exists() {
        std::fs::remove_file(&manifest_path)?;
    }
    let provenance = Provenance::new(&plan.text, plan.file.seed, "all");
    let all = to_dataframe(runs)?;
    let mut df = all.select(columns_of(&all))?;
    write_parquet(&dir.join("runs.parquet"), &mut df, &provenance)?;
    let mut summary = summarize(plan, runs)?;
    write_parquet(&dir.join("summary.parquet"), &mut summary, &provenance)?;
    write_text(
        &dir.join("study.toml"),
        &crate::study::results::io::folder_copy(&plan.text),
    )?;
    let manifest = Manifest {
        format: FORMAT,
        study_name: plan.name.clone(),
        study_sha256: provenance.study_sha256.clone(),
        seed: plan.file.seed,
        samples: plan.file.sampling.samples,
        designs: plan.designs.len() as u32,
        runs: runs.len() as u64,
        autobal_version: provenance.version.clone(),
        git_commit: provenance.git_commit.clone(),
        created_unix: std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs()),
    };
    let text = toml::to_string(&manifest).map_err(|e| BaselineError::BadManifest {
        path: manifest_path.display().to_string(),
        message: e.to_string(),
    })?;
    write_text(
        &manifest_path,
        &format!("# Written by `study baseline`.\n{text}"),
    )?;
    Ok(manifest)
}

/// Read the baseline in `dir`, checking that its files agree with its manifest.
pub fn read_baseline(dir: &Path) -> Result<Baseline, BaselineError> {
    let shown = dir.display().to_string();
    let manifest_path = dir.join(MANIFEST);
    if !manifest_path.is_file() {
        return Err(BaselineError::Missing(shown));
    }
    let text = std::fs::read_to_string(&manifest_path)?;
    let bad = |message: String| BaselineError::BadManifest {
        path: manifest_path.display().to_string(),
        message,
    };
    let manifest: Manifest = toml::from_str(&text).map_err(|e| bad(e.to_string()))?;
    if manifest.format != FORMAT {
        return Err(bad(format!(
            "format = {}: this autobal reads format {FORMAT}",
            manifest.format
        )));
    }
    let inconsistent = |message: String| BaselineError::Inconsistent {
        dir: shown.clone(),
        message,
    };
    let runs_path = dir.join("runs.parquet");
    if !runs_path.is_file() {
        return Err(inconsistent("runs.parquet is missing".into()));
    }
    let stored_sha = read_metadata(&runs_path)?
        .into_iter()
        .find(|(k, _)| k == "study_sha256")
        .map(|(_, v)| v)
        .unwrap_or_default();
    if stored_sha != manifest.study_sha256 {
        return Err(inconsistent(
            "runs.parquet comes from another study than the manifest names".into(),
        ));
    }
    let df = crate::study::results::results_table::read_table(
        &runs_path,
        crate::study::results::results_table::TableKind::Runs,
    )?;
    if df.height() as u64 != manifest.runs {
        return Err(inconsistent(format!(
            "runs.parquet holds {} runs, the manifest says {}",
            df.height(),
            manifest.runs
        )));
    }
    Ok(Baseline {
        dir: dir.to_path_buf(),
        manifest,
        samples: design_samples(&df)?,
    })
}

/// Refuse a baseline written from another study text than `plan`'s.
pub fn check_same_study(baseline: &Baseline, plan: &StudyPlan) -> Result<(), BaselineError> {
    let study = crate::study::results::io::study_sha256(&plan.text);
    if !crate::study::results::io::same_study(&baseline.manifest.study_sha256, &plan.text) {
        return Err(BaselineError::DifferentStudy {
            dir: baseline.dir.display().to_string(),
            baseline: baseline.manifest.study_sha256.clone(),
            study,
        });
    }
    Ok(())
}

/// Where `study baseline` writes by default: `<output>/baselines/<name>`.
pub fn default_dir(plan: &StudyPlan) -> PathBuf {
    Path::new(&plan.file.output)
        .join("baselines")
        .join(&plan.name)
}
