//! Reading a user's input file (a study or scene) as text without blocking:
//! a FIFO, a device or a folder given as the file is refused at once, where
//! reading it would wait for a writer that never comes.

use std::io::{Error, ErrorKind};
use std::path::Path;

/// The text of the regular file at `path`; anything else is an
/// `InvalidInput` error saying what the path is.
pub fn read_text(path: &Path) -> std::io::Result<String> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a folder"
        } else {
            "not a regular file (a FIFO, socket or device)"
        };
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{what}, not a text file"),
        ));
    }
    std::fs::read_to_string(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fifo_or_folder_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_text(dir.path()).unwrap_err();
        assert!(err.to_string().contains("a folder"), "{err}");
        let fifo = dir.path().join("study.toml");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let err = read_text(&fifo).unwrap_err();
            assert!(err.to_string().contains("FIFO"), "{err}");
        }
        let file = dir.path().join("ok.toml");
        std::fs::write(&file, "a = 1").unwrap();
        assert_eq!(read_text(&file).unwrap(), "a = 1");
    }
}
