//! A study's output folder as a run finds it: claimed (made, writable,
//! locked, its entries of the right kind), then either checked for a
//! resume (same study, same build, its tables this study's) or emptied for
//! a fresh start. Nothing here runs anything; a refusal changes nothing.

use super::{PLAN_ID_FILE, RunError, RunOptions};
use crate::study::plan::config::StudyPlan;
use crate::study::results::io::{Provenance, folder_copy, foreign_table, write_text};
use crate::study::run::lock::FolderLock;
use std::path::{Path, PathBuf};

/// The entries of a study's output folder.
pub(super) struct FolderFiles {
    /// The folder's copy of the study file.
    pub manifest: PathBuf,
    /// The plan id ([`PLAN_ID_FILE`]).
    pub plan_file: PathBuf,
    /// Chunks of finished runs, until the runs table is written.
    pub chunks: PathBuf,
    /// The runs table.
    pub runs: PathBuf,
    /// The summary table.
    pub summary: PathBuf,
    /// The counterfactual re-runs.
    pub causes: PathBuf,
}

impl FolderFiles {
    /// The entries of the folder `dir`.
    pub fn in_folder(dir: &Path) -> Self {
        FolderFiles {
            manifest: dir.join("study.toml"),
            plan_file: dir.join(PLAN_ID_FILE),
            chunks: dir.join("chunks"),
            runs: dir.join("runs.parquet"),
            summary: dir.join("summary.parquet"),
            causes: dir.join(crate::study::results::causes_file::CAUSES_FILE),
        }
    }

    /// Whether the folder holds results: a table or a chunk.
    fn has_results(&self) -> bool {
        self.runs.exists()
            || self.summary.exists()
            || std::fs::read_dir(&self.chunks).is_ok_and(|mut d| d.next().is_some())
    }
}

/// Make `dir`, check that it can be written, take its lock (held while the
/// guard lives) and check its entries' kinds.
pub(super) fn claim(dir: &Path) -> Result<FolderLock, RunError> {
    let not_writable = |source| RunError::NotWritable {
        path: dir.display().to_string(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(not_writable)?;
    crate::output_file::probe_writable(dir).map_err(not_writable)?;
    let lock = FolderLock::acquire(dir)?;
    // A writer killed during an atomic write left its temporary file.
    crate::output_file::remove_stale_temps(dir, None);
    check_entry_kinds(dir)?;
    Ok(lock)
}

/// A `--resume` continues only this study's runs made by this build: the
/// same study text, the same plan id, a runs table of this study, seed and
/// shard.
pub(super) fn check_resume(
    dir: &Path,
    files: &FolderFiles,
    plan: &StudyPlan,
    id: &str,
    provenance: &Provenance,
) -> Result<(), RunError> {
    if std::fs::read_to_string(&files.manifest)? != folder_copy(&plan.text) {
        return Err(RunError::StudyChanged {
            path: dir.display().to_string(),
        });
    }
    check_resumed_plan(dir, &files.plan_file, id, files.has_results())?;
    if files.runs.exists()
        && let Some(reason) = foreign_table(
            &files.runs,
            &plan.text,
            plan.file.seed,
            Some(provenance.shard.as_str()),
        )?
    {
        return Err(RunError::ForeignTable {
            folder: dir.display().to_string(),
            path: files.runs.display().to_string(),
            reason,
        });
    }
    Ok(())
}

/// A fresh run: refused over results unless `--overwrite`, which removes
/// them; then the study text and plan id are recorded.
pub(super) fn start_afresh(
    dir: &Path,
    files: &FolderFiles,
    plan: &StudyPlan,
    options: &RunOptions,
    id: &str,
) -> Result<(), RunError> {
    let has_results = files.has_results();
    if has_results && options.resume && !options.overwrite {
        return Err(RunError::NoPlan {
            path: dir.display().to_string(),
        });
    }
    if has_results && !options.overwrite {
        return Err(RunError::ResultsExist {
            path: dir.display().to_string(),
        });
    }
    for stale in [&files.runs, &files.summary, &files.causes] {
        if stale.exists() {
            std::fs::remove_file(stale)?;
        }
    }
    if files.chunks.exists() {
        std::fs::remove_dir_all(&files.chunks)?;
    }
    write_text(&files.manifest, &folder_copy(&plan.text))?;
    write_text(&files.plan_file, id)?;
    Ok(())
}

/// Refuse a study folder whose own entries are of the wrong kind, before
/// anything in it is touched (before, `--resume` with a file named
/// `chunks` ended on a bare "os error 17").
fn check_entry_kinds(dir: &Path) -> Result<(), RunError> {
    let entries: [(&str, bool, &'static str); 6] = [
        ("chunks", true, "chunks/ folder of finished runs"),
        ("study.toml", false, "copy of the study file (study.toml)"),
        (PLAN_ID_FILE, false, "plan id (plan.sha256)"),
        ("runs.parquet", false, "runs table (runs.parquet)"),
        ("summary.parquet", false, "summary table (summary.parquet)"),
        (
            "causes.parquet",
            false,
            "counterfactual re-runs (causes.parquet)",
        ),
    ];
    for (name, want_dir, want) in entries {
        let path = dir.join(name);
        let Ok(meta) = std::fs::metadata(&path) else {
            continue;
        };
        if meta.is_dir() != want_dir {
            return Err(RunError::Misshapen {
                path: path.display().to_string(),
                found: if meta.is_dir() { "a folder" } else { "a file" },
                want,
            });
        }
    }
    Ok(())
}

/// A resumed folder's runs were made by this build: its plan id says so.
/// Without one (missing, unreadable) nothing says which build made them.
fn check_resumed_plan(
    dir: &Path,
    plan_file: &Path,
    id: &str,
    has_results: bool,
) -> Result<(), RunError> {
    match std::fs::read_to_string(plan_file) {
        Ok(found) if found.trim() != id => Err(RunError::PlanChanged {
            path: dir.display().to_string(),
            found: found.trim().to_string(),
            expected: id.to_string(),
        }),
        Ok(_) => Ok(()),
        Err(_) if has_results => Err(RunError::PlanUnknown {
            path: dir.display().to_string(),
        }),
        // Nothing finished yet: record the plan now.
        Err(_) => Ok(write_text(plan_file, id)?),
    }
}
