//! One writer per results folder: an advisory lock on `<folder>/.lock`,
//! which names its holder (pid and host). The operating system releases the
//! lock when the holder dies, so a lock file left by a killed run is stale
//! and is simply taken over; the file is removed when the holder finishes.

use std::fs::{File, TryLockError};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The held lock; released (and its file removed) on drop.
#[derive(Debug)]
pub struct FolderLock {
    file: File,
    path: PathBuf,
}

/// Why a folder could not be locked.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process holds it.
    #[error(
        "{folder} is in use by another study run ({holder}); wait for it to finish or use another output folder"
    )]
    Held {
        /// The folder.
        folder: String,
        /// Who holds it, as the holder wrote it.
        holder: String,
    },
    /// The lock file could not be created or locked.
    #[error("cannot lock {folder}: {source}")]
    Io {
        /// The folder.
        folder: String,
        /// The cause.
        source: std::io::Error,
    },
}

impl FolderLock {
    /// Take the lock of `folder` (which must exist), or say who holds it.
    pub fn acquire(folder: &Path) -> Result<Self, LockError> {
        // A holder removes the file before it unlocks, so a lock taken on a
        // file that is no longer at the path guards nothing: try again on
        // the new file (bounded: each retry means another process finished).
        for _ in 0..64 {
            if let Some(lock) = Self::try_acquire(folder)? {
                return Ok(lock);
            }
        }
        Err(LockError::Io {
            folder: folder.display().to_string(),
            source: std::io::Error::other("the lock file kept being replaced"),
        })
    }

    /// One attempt: `None` when the locked file was removed meanwhile.
    fn try_acquire(folder: &Path) -> Result<Option<Self>, LockError> {
        let path = folder.join(".lock");
        let io = |source| LockError::Io {
            folder: folder.display().to_string(),
            source,
        };
        let mut file = File::options()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let holder = std::fs::read_to_string(&path)
                    .ok()
                    .filter(|s| !s.trim().is_empty())
                    .unwrap_or_else(|| "holder unknown".into());
                return Err(LockError::Held {
                    folder: folder.display().to_string(),
                    holder: holder.trim().to_string(),
                });
            }
            Err(TryLockError::Error(e)) => return Err(io(e)),
        }
        if !same_file(&file, &path) {
            let _ = file.unlock();
            return Ok(None);
        }
        file.set_len(0).map_err(io)?;
        writeln!(file, "pid {} on {}", std::process::id(), host()).map_err(io)?;
        Ok(Some(FolderLock { file, path }))
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Remove first, then unlock: a waiting process never sees our name.
        let _ = std::fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

/// Whether the open `file` is still the one at `path`.
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether the open `file` is still the one at `path` (no inode numbers here).
#[cfg(not(unix))]
fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
}

/// This machine's name, for the lock file.
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "an unknown host".into())
}
