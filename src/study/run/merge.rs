//! `study merge`: combine shard outputs into exactly what one unsharded run writes.

use crate::study::plan::config::StudyPlan;
use crate::study::results::io::{Provenance, write_parquet};
use crate::study::results::runs_file::{Piece, read_summary_columns, write_runs};
use crate::study::run::aggregate::summarize_table;
use crate::study::run::lock::FolderLock;
use crate::study::run::{RunError, StudyOutput};
use std::path::{Path, PathBuf};

/// Why shard outputs cannot be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// A shard folder has no finished `runs.parquet`.
    #[error("{0}: no runs.parquet (is the shard finished?)")]
    Missing(String),
    /// Shards come from different study files.
    #[error("{0}: comes from a different study file or autobal build than {1}")]
    DifferentStudy(String, String),
    /// A shard's runs recorded another study or seed than its folder's.
    #[error("{0} does not hold the shards' study's runs: {1}")]
    ForeignTable(String, String),
    /// Two shards hold the same run.
    #[error("run {0} appears in more than one shard")]
    Duplicate(u64),
    /// Runs are missing from the union of the shards.
    #[error("{missing} of {total} runs are missing (first: run {first}); merge every shard")]
    Incomplete {
        /// Count of missing runs.
        missing: u64,
        /// Expected total.
        total: u64,
        /// First missing run index.
        first: u64,
    },
    /// The study text stored in the shards cannot be parsed.
    #[error("study stored in {0} is invalid: {1}")]
    BadStudy(String, String),
    /// Reading or writing failed.
    #[error(transparent)]
    Run(#[from] RunError),
}

impl From<polars::prelude::PolarsError> for MergeError {
    fn from(e: polars::prelude::PolarsError) -> Self {
        MergeError::Run(RunError::Polars(e))
    }
}

/// Merge shard folders; the result goes to `out` (default: the shards' parent folder).
/// Results already in the output folder are replaced only with `overwrite`.
pub fn merge(
    dirs: &[PathBuf],
    out: Option<&Path>,
    overwrite: bool,
) -> Result<StudyOutput, MergeError> {
    let (pieces, shard_plan, first_dir) = read_shards(dirs)?;
    let text = shard_plan
        .split_once('\n')
        .map_or(shard_plan.as_str(), |(_, t)| t)
        .to_string();
    let plan: StudyPlan = crate::study::plan::config::StudyFile::parse(&text, &first_dir)
        .and_then(|f| f.plan(&text, &first_dir))
        .map_err(|e| MergeError::BadStudy(first_dir.clone(), e.to_string()))?;
    for dir in dirs {
        let path = dir.join("runs.parquet");
        if let Some(reason) =
            crate::study::results::io::foreign_table(&path, &plan.text, plan.file.seed, None)?
        {
            return Err(MergeError::ForeignTable(path.display().to_string(), reason));
        }
    }
    let total = plan.total_runs();
    check_every_run_once(&pieces, total, &first_dir)?;
    let (dir, _lock) = claim_merged_folder(dirs, out, overwrite)?;
    let mut provenance = Provenance::new(&plan.text, plan.file.seed, "all");
    // The hash the shards recorded (older shards hashed the study file
    // with its `#:schema` line, which their folders' copies leave out).
    if let Some(sha) = crate::study::results::io::read_metadata(&dirs[0].join("runs.parquet"))
        .ok()
        .and_then(|m| m.into_iter().find(|(k, _)| k == "study_sha256"))
    {
        provenance.study_sha256 = sha.1;
    }
    let runs_path = dir.join("runs.parquet");
    let mut runs = write_runs(&pieces, total, &runs_path, &provenance)?;
    drop(pieces);
    // Shards cannot race (each lacks the others' runs): the race is
    // replayed here on every run, and the merged files hold what an
    // unsharded raced study makes.
    let mut departures = None;
    if crate::study::run::racing::races(&plan) {
        let batches = crate::study::run::adaptive::batches(&plan);
        let race = crate::study::run::racing::Race::replay(
            &plan,
            &batches,
            &read_summary_columns(&runs_path)?,
        )?;
        let mut made = race.made(&crate::study::results::io::read_parquet(&runs_path)?)?;
        runs = made.height() as u64;
        write_parquet(&runs_path, &mut made, &provenance)?;
        departures = Some(race.departures());
    }
    let table = read_summary_columns(&runs_path)?;
    let mut summary = summarize_table(&plan, &table)?;
    // The cause experiment, as the unsharded study runs it.
    let found = crate::study::run::causes::test_and_append(&plan, &table, &mut summary)?;
    write_parquet(&dir.join("summary.parquet"), &mut summary, &provenance)?;
    crate::study::run::causes::write_or_remove(
        &dir.join(crate::study::results::causes_file::CAUSES_FILE),
        found.as_ref(),
        &provenance,
    )?;
    crate::study::results::io::write_text(&dir.join("study.toml"), &plan.text)
        .map_err(RunError::Io)?;
    if let Some((plan_id, _)) = shard_plan.split_once('\n')
        && !plan_id.is_empty()
    {
        crate::study::results::io::write_text(&dir.join(crate::study::run::PLAN_ID_FILE), plan_id)
            .map_err(RunError::Io)?;
    }
    Ok(StudyOutput {
        dir,
        runs,
        summary: Some(summary),
        executed: 0,
        adaptive: None,
        race: departures,
        runs_planned: plan.total_runs(),
    })
}

/// Each shard's runs table, and the plan they share ("plan id\nstudy
/// text") with the first shard's folder; refused when a shard is
/// unfinished or another study's or build's.
fn read_shards(dirs: &[PathBuf]) -> Result<(Vec<Piece>, String, String), MergeError> {
    let mut pieces: Vec<Piece> = Vec::new();
    let mut study: Option<(String, String)> = None;
    for dir in dirs {
        let path = dir.join("runs.parquet");
        if !path.exists() {
            return Err(MergeError::Missing(dir.display().to_string()));
        }
        // The shard's plan: its study text and the build that ran it.
        let text = std::fs::read_to_string(dir.join("study.toml"))
            .map_err(|_| MergeError::Missing(dir.join("study.toml").display().to_string()))?;
        let plan_id =
            std::fs::read_to_string(dir.join(crate::study::run::PLAN_ID_FILE)).unwrap_or_default();
        let shard_plan = format!("{plan_id}\n{text}");
        match &study {
            None => study = Some((shard_plan, dir.display().to_string())),
            Some((first, first_dir)) if *first != shard_plan => {
                return Err(MergeError::DifferentStudy(
                    dir.display().to_string(),
                    first_dir.clone(),
                ));
            }
            Some(_) => {}
        }
        pieces.push(Piece::open(&path)?);
    }
    let (shard_plan, first_dir) =
        study.ok_or_else(|| MergeError::Missing("(no shard folders given)".into()))?;
    Ok((pieces, shard_plan, first_dir))
}

/// The shards hold every run of the plan's `total`, each once.
fn check_every_run_once(pieces: &[Piece], total: u64, first_dir: &str) -> Result<(), MergeError> {
    let mut seen = vec![false; total as usize];
    for &id in pieces.iter().flat_map(|p| p.ids()) {
        match seen.get_mut(id as usize) {
            Some(s) if !*s => *s = true,
            Some(_) => return Err(MergeError::Duplicate(id)),
            None => {
                return Err(MergeError::BadStudy(
                    first_dir.to_string(),
                    format!("run {id} is outside the plan's {total} runs"),
                ));
            }
        }
    }
    if let Some(first) = seen.iter().position(|s| !s) {
        let missing = seen.iter().filter(|s| !**s).count() as u64;
        return Err(MergeError::Incomplete {
            missing,
            total,
            first: first as u64,
        });
    }
    Ok(())
}

/// The merged folder (`out`, or the shards' parent), made, writable and
/// locked: a results folder like any other, one writer, its results
/// replaced only with `overwrite`.
fn claim_merged_folder(
    dirs: &[PathBuf],
    out: Option<&Path>,
    overwrite: bool,
) -> Result<(PathBuf, FolderLock), MergeError> {
    let dir = match out {
        Some(o) => o.to_path_buf(),
        None => dirs[0]
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from(".")),
    };
    let not_writable = |source| RunError::NotWritable {
        path: dir.display().to_string(),
        source,
    };
    std::fs::create_dir_all(&dir).map_err(not_writable)?;
    crate::output_file::probe_writable(&dir).map_err(not_writable)?;
    let lock = FolderLock::acquire(&dir).map_err(RunError::from)?;
    if !overwrite && (dir.join("runs.parquet").exists() || dir.join("summary.parquet").exists()) {
        return Err(RunError::ResultsExist {
            path: dir.display().to_string(),
        }
        .into());
    }
    Ok((dir, lock))
}
