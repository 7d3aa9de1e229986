//! A study's output folder as the destination of another verb's files
//! (`study tradeoff`, `study optimize`): the folder must belong to the same
//! study file, must not be a check's scratch folder or a baseline, is locked
//! against other writers, and its existing files are replaced only with
//! `--overwrite`. Everything is checked before the verb's work begins.

use crate::output_file::{OutputFileError, WhenExists, prepare, probe_writable};
use crate::study::plan::config::StudyPlan;
use crate::study::run::lock::{FolderLock, LockError};
use std::path::{Path, PathBuf};

/// Marks a folder as the scratch run of `study check` or `study baseline`:
/// only a folder holding it (or none at all) is rewritten by them.
pub const SCRATCH_MARK: &str = ".check-scratch";

/// Marks a folder as one of `study claims`' variant runs, which it rewrites.
pub const CLAIMS_MARK: &str = ".claims-variant";

/// The manifest naming a baseline folder's contents (`study baseline`).
pub const BASELINE_MANIFEST: &str = "manifest.toml";

/// Why a verb may not write into the study's folder.
#[derive(Debug, thiserror::Error)]
pub enum StudyFolderError {
    /// The folder holds another study file's results.
    #[error(
        "{path} holds results of another study file (its study.toml differs from the one given); nothing was written: rename the study (`name`) or change `output`"
    )]
    OtherStudy {
        /// The folder.
        path: String,
    },
    /// The folder belongs to another verb (a check's scratch run, a baseline).
    #[error("{path} is {what}; nothing was written: rename the study (`name`) or change `output`")]
    OtherVerb {
        /// The folder.
        path: String,
        /// What the folder is.
        what: &'static str,
    },
    /// The folder cannot be created or written.
    #[error("output folder {path} cannot be written: {source}")]
    NotWritable {
        /// The folder.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// Another process writes the folder.
    #[error(transparent)]
    Locked(#[from] LockError),
    /// One of the files cannot be written or exists.
    #[error(transparent)]
    File(#[from] OutputFileError),
}

/// The study's folder, locked for a verb writing `files` into it; the lock
/// is held until the returned guard drops.
#[derive(Debug)]
pub struct ClaimedFolder {
    /// The folder.
    pub dir: PathBuf,
    _lock: FolderLock,
}

/// Claim the study's output folder for `files` (names inside it), before
/// any work: see the module's rules. `role` names the verb in messages.
pub fn claim(
    plan: &StudyPlan,
    role: &str,
    files: &[&str],
    when: WhenExists,
) -> Result<ClaimedFolder, StudyFolderError> {
    let dir = crate::study::run::output_dir(plan, None);
    let shown = dir.display().to_string();
    if let Some(what) = foreign_use(&dir) {
        return Err(StudyFolderError::OtherVerb { path: shown, what });
    }
    let manifest = dir.join("study.toml");
    let copy = crate::study::results::io::folder_copy(&plan.text);
    if manifest.is_file() && std::fs::read_to_string(&manifest).is_ok_and(|text| text != copy) {
        return Err(StudyFolderError::OtherStudy { path: shown });
    }
    let not_writable = |source| StudyFolderError::NotWritable {
        path: dir.display().to_string(),
        source,
    };
    let made = create_dirs(&dir).map_err(not_writable)?;
    if let Err(e) = probe_writable(&dir) {
        remove_made(&made);
        return Err(not_writable(e));
    }
    let lock = FolderLock::acquire(&dir)?;
    for file in files {
        prepare(role, &dir.join(file), when)?;
    }
    if !manifest.exists() {
        // Says which study the folder's files belong to.
        crate::study::results::io::write_text(&manifest, &copy).map_err(not_writable)?;
    }
    Ok(ClaimedFolder { dir, _lock: lock })
}

/// `create_dir_all`, returning the folders it made (deepest last); on
/// failure it removes the ones it made, so that a refusal (a name too long
/// for the file system, a read-only parent) leaves no empty folders behind.
fn create_dirs(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let made: Vec<PathBuf> = dir
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .map(Path::to_path_buf)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    std::fs::create_dir_all(dir).inspect_err(|_| remove_made(&made))?;
    Ok(made)
}

/// Remove the (empty) folders [`create_dirs`] made, deepest first.
fn remove_made(made: &[PathBuf]) {
    for d in made.iter().rev() {
        let _ = std::fs::remove_dir(d);
    }
}

/// What another verb made of `dir`, if anything.
pub fn foreign_use(dir: &Path) -> Option<&'static str> {
    if dir.join(SCRATCH_MARK).exists() {
        Some("the scratch folder of `study check` or `study baseline`")
    } else if dir.join(BASELINE_MANIFEST).exists() {
        Some("a baseline folder (`study baseline`)")
    } else if dir.join(CLAIMS_MARK).exists() {
        Some("a variant run of `study claims`")
    } else {
        None
    }
}
