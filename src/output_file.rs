//! Where a verb writes one file (`--out`, `--series`, `--report`, a study
//! folder's `tradeoff.parquet`): checked before any work, so that a refusal
//! leaves nothing written and a long computation never ends in an OS error.
//! Every message names the flag and the path.

use std::path::{Path, PathBuf};

/// What to do when the output file already exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WhenExists {
    /// Results: refused unless the user asked to replace them (`--overwrite`).
    Refuse,
    /// Replace it (the user gave `--overwrite`, or the file is a figure).
    Replace,
}

impl WhenExists {
    /// `Replace` when the user gave `--overwrite`, else `Refuse`.
    pub fn from_overwrite(overwrite: bool) -> Self {
        if overwrite {
            WhenExists::Replace
        } else {
            WhenExists::Refuse
        }
    }
}

/// Why a path cannot take the output file.
#[derive(Debug, thiserror::Error)]
pub enum OutputFileError {
    /// The path is a folder.
    #[error("{flag} {path}: names a folder; give a file name")]
    Folder {
        /// The flag (or file role) the path was given for.
        flag: String,
        /// The path.
        path: String,
    },
    /// The folder the file would go in does not exist (or is a file).
    #[error("{flag} {path}: {reason}")]
    NoFolder {
        /// The flag.
        flag: String,
        /// The path.
        path: String,
        /// Its parent folder.
        parent: String,
        /// "folder … does not exist", or "… is a file, not a folder".
        reason: String,
    },
    /// The path is a symbolic link and the user did not ask to replace it.
    #[error(
        "{flag} {path}: is a symbolic link (to {target}); add --overwrite to replace the link with the file"
    )]
    Link {
        /// The flag.
        flag: String,
        /// The path.
        path: String,
        /// Where the link points.
        target: String,
    },
    /// A folder was asked for, and the path (or a folder on its way) is a file.
    #[error("{flag} {path}: {file} is a file, not a folder; give a folder")]
    NotAFolder {
        /// The flag.
        flag: String,
        /// The path.
        path: String,
        /// The file in the way.
        file: String,
    },
    /// The file exists and the user did not ask to replace it.
    #[error("{flag} {path}: exists; add --overwrite to replace it")]
    Exists {
        /// The flag.
        flag: String,
        /// The path.
        path: String,
    },
    /// The folder cannot be written (permissions, read-only file system…).
    #[error("{flag} {path}: cannot write in {parent}: {source}")]
    NotWritable {
        /// The flag.
        flag: String,
        /// The path.
        path: String,
        /// Its parent folder.
        parent: String,
        /// The cause.
        source: std::io::Error,
    },
}

/// Check that `path` can take a new file, before any work: it does not
/// name a folder (an existing one, or a path ending in `/`, `/.` or `/..`),
/// its folder exists and can be written, and an existing file or symbolic
/// link is replaced only under [`WhenExists::Replace`]. Temporary files left
/// beside it by a killed writer are removed.
pub fn prepare(flag: &str, path: &Path, when: WhenExists) -> Result<(), OutputFileError> {
    let shown = path.display().to_string();
    let parent = parent_of(path);
    if path.is_dir() || names_folder(path) {
        return Err(OutputFileError::Folder {
            flag: flag.into(),
            path: shown,
        });
    }
    if !parent.is_dir() {
        let reason = if parent.exists() {
            format!("{} is a file, not a folder", parent.display())
        } else {
            format!("folder {} does not exist", parent.display())
        };
        return Err(OutputFileError::NoFolder {
            flag: flag.into(),
            path: shown,
            parent: parent.display().to_string(),
            reason,
        });
    }
    let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if when == WhenExists::Refuse && link {
        let target =
            std::fs::read_link(path).map_or_else(|_| "?".into(), |t| t.display().to_string());
        return Err(OutputFileError::Link {
            flag: flag.into(),
            path: shown,
            target,
        });
    }
    if when == WhenExists::Refuse && path.exists() {
        return Err(OutputFileError::Exists {
            flag: flag.into(),
            path: shown,
        });
    }
    let not_writable = |source| OutputFileError::NotWritable {
        flag: flag.into(),
        path: path.display().to_string(),
        parent: parent.display().to_string(),
        source,
    };
    // A folder without write permission is refused even for root, whom the
    // probe below would let through: the answer must not depend on who asks.
    if std::fs::metadata(&parent).is_ok_and(|m| m.permissions().readonly()) {
        return Err(not_writable(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "the folder is read-only",
        )));
    }
    probe_writable(&parent).map_err(not_writable)?;
    if path.exists() {
        // An existing file that is read-only would fail only at the end.
        let meta = std::fs::metadata(path).map_err(not_writable)?;
        if meta.permissions().readonly() {
            return Err(not_writable(std::io::Error::new(
                std::io::ErrorKind::PermissionDenied,
                "the file is read-only",
            )));
        }
    }
    remove_stale_temps(&parent, path.file_name().and_then(|n| n.to_str()));
    Ok(())
}

/// Check that `dir` can take (or become) an output folder, before any work:
/// it is a folder or can be created in the nearest folder that exists, and
/// that folder can be written. Nothing is created here.
pub fn prepare_folder(flag: &str, dir: &Path) -> Result<(), OutputFileError> {
    let shown = dir.display().to_string();
    // "new/." cannot be created ("." inside a folder that does not exist).
    if !dir.exists() && dir.as_os_str().to_string_lossy().ends_with("/.") {
        return Err(OutputFileError::NoFolder {
            flag: flag.into(),
            path: shown.clone(),
            parent: shown.trim_end_matches('.').into(),
            reason: format!(
                "folder {} does not exist; give it without the trailing /. to have it made",
                shown.trim_end_matches("/.")
            ),
        });
    }
    let mut existing = dir.to_path_buf();
    while !existing.as_os_str().is_empty() && std::fs::symlink_metadata(&existing).is_err() {
        existing = existing
            .parent()
            .map_or_else(PathBuf::new, Path::to_path_buf);
    }
    if existing.as_os_str().is_empty() {
        existing = PathBuf::from(".");
    }
    if !existing.is_dir() {
        return Err(OutputFileError::NotAFolder {
            flag: flag.into(),
            path: shown,
            file: existing.display().to_string(),
        });
    }
    let not_writable = |source| OutputFileError::NotWritable {
        flag: flag.into(),
        path: shown.clone(),
        parent: existing.display().to_string(),
        source,
    };
    if std::fs::metadata(&existing).is_ok_and(|m| m.permissions().readonly()) {
        return Err(not_writable(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "the folder is read-only",
        )));
    }
    probe_writable(&existing).map_err(not_writable)
}

/// Whether the path, as typed, names a folder whatever exists: it ends in a
/// separator, `.` or `..` (`Path` drops a trailing `.`, so that "out.html/."
/// would otherwise pass for the file "out.html" and fail after the work).
pub fn names_folder(path: &Path) -> bool {
    let text = path.as_os_str().to_string_lossy();
    let last = text
        .rsplit(['/', std::path::MAIN_SEPARATOR])
        .next()
        .unwrap_or("");
    matches!(last, "" | "." | "..")
}

/// The folder a file path lives in ("." for a bare name).
pub fn parent_of(path: &Path) -> PathBuf {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// Create and remove a file only this process names, to learn whether
/// `folder` can be written (simultaneous starts never collide on it). A
/// folder whose permissions allow no writing is refused even where the
/// system would let this process write (as root): whoever made it
/// read-only meant its contents to stay.
pub fn probe_writable(folder: &Path) -> std::io::Result<()> {
    if std::fs::metadata(folder)?.permissions().readonly() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "the folder is read-only (its permissions allow no writing)",
        ));
    }
    let probe = folder.join(format!(".write-probe-{}", std::process::id()));
    std::fs::write(&probe, b"")?;
    std::fs::remove_file(&probe)
}

/// Remove the temporary files in `folder` (named `<file>.tmp-<pid>…`, as
/// atomic writes name them) whose writer is no longer running: a process
/// killed during a write leaves one behind. With `only_for`, just the
/// temporaries of that file name. Errors are ignored: a leftover that
/// cannot be removed harms nothing but the folder's tidiness.
pub fn remove_stale_temps(folder: &Path, only_for: Option<&str>) {
    let Ok(entries) = std::fs::read_dir(folder) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        let Some(pid) = temp_writer(&name, only_for) else {
            continue;
        };
        if !process_alive(pid) && entry.file_type().is_ok_and(|t| t.is_file()) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The writer's pid of a temporary file's name, if it is one (for `only_for`,
/// one of that file).
fn temp_writer(name: &str, only_for: Option<&str>) -> Option<u32> {
    let at = name.find(".tmp-")?;
    if let Some(file) = only_for {
        let stem = Path::new(file).file_stem().and_then(|s| s.to_str());
        let base = name[..at].trim_start_matches('.');
        if base != file && Some(base) != stem {
            return None;
        }
    }
    let rest = &name[at + 5..];
    let digits = rest
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(rest.len());
    let tail = &rest[digits..];
    if digits == 0 || !(tail.is_empty() || tail.starts_with('.')) {
        return None;
    }
    rest[..digits].parse().ok()
}

/// Whether a process with this pid exists (this process counts as alive).
fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return false;
        };
        // SAFETY: signal 0 only asks whether the process exists.
        let found = unsafe { libc::kill(pid, 0) } == 0;
        found || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_names_are_recognised_with_their_writer() {
        assert_eq!(temp_writer("runs.parquet.tmp-42", None), Some(42));
        assert_eq!(temp_writer(".fig.tmp-7.png", None), Some(7));
        assert_eq!(
            temp_writer("runs.parquet.tmp-42", Some("runs.parquet")),
            Some(42)
        );
        assert_eq!(temp_writer(".fig.tmp-7.png", Some("fig.png")), Some(7));
        assert_eq!(
            temp_writer("runs.parquet.tmp-42", Some("summary.parquet")),
            None
        );
        assert_eq!(temp_writer("runs.parquet", None), None);
        assert_eq!(temp_writer("a.tmp-x", None), None);
        assert_eq!(temp_writer("a.tmp-12x", None), None);
    }

    #[test]
    fn a_dead_writers_temporary_goes_and_a_live_ones_stays() {
        let dir = tempfile::tempdir().unwrap();
        // A child that has exited and been reaped: its pid is free.
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let stale = dir.path().join(format!("out.parquet.tmp-{dead}"));
        let live = dir
            .path()
            .join(format!("out.parquet.tmp-{}", std::process::id()));
        let other = dir.path().join(format!("keep.csv.tmp-{dead}"));
        for p in [&stale, &live, &other] {
            std::fs::write(p, b"x").unwrap();
        }
        prepare("--out", &dir.path().join("out.parquet"), WhenExists::Refuse).unwrap();
        assert!(!stale.exists() || process_alive(dead), "stale temp kept");
        assert!(live.exists(), "a running writer's temp removed");
        assert!(other.exists(), "another file's temp removed");
    }

    #[test]
    fn folders_missing_folders_and_existing_results_are_refused_naming_the_flag() {
        let dir = tempfile::tempdir().unwrap();
        let err = prepare("--out", dir.path(), WhenExists::Replace).unwrap_err();
        assert!(
            err.to_string().starts_with("--out ") && err.to_string().contains("names a folder")
        );
        let slash = dir.path().join("fig.svg/");
        let err = prepare("--out", &slash, WhenExists::Replace).unwrap_err();
        assert!(err.to_string().contains("names a folder"), "{err}");
        let missing = dir.path().join("nope/out.parquet");
        let err = prepare("--series", &missing, WhenExists::Replace).unwrap_err();
        assert!(err.to_string().contains("does not exist"), "{err}");
        let file = dir.path().join("out.parquet");
        std::fs::write(&file, b"x").unwrap();
        let err = prepare("--out", &file, WhenExists::Refuse).unwrap_err();
        assert!(err.to_string().contains("--overwrite"), "{err}");
        prepare("--out", &file, WhenExists::Replace).unwrap();
        assert!(file.exists(), "prepare never removes the file itself");
        assert!(
            std::fs::read_dir(dir.path()).unwrap().count() == 1,
            "the probe was left behind"
        );
    }
}
