//! A full disk is reported as one, naming the file that could not be
//! written (not as a damaged Parquet file, which blamed the user's input),
//! exits 1, and the next `--resume` with room again writes what one
//! uninterrupted run writes. Needs a small tmpfs: run where `mount` works
//! (as root, as CI here does); elsewhere the test says so and stops.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A tmpfs of `size` at `at`, unmounted when dropped.
struct SmallDisk(PathBuf);

impl SmallDisk {
    fn mount(at: &Path, size: &str) -> Option<SmallDisk> {
        std::fs::create_dir_all(at).ok()?;
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(at)
            .output()
            .ok()?
            .status
            .success();
        ok.then(|| SmallDisk(at.to_path_buf()))
    }

    fn grow(&self, size: &str) {
        let out = Command::new("mount")
            .args(["-o", &format!("remount,size={size}")])
            .arg(&self.0)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg("-l").arg(&self.0).output();
    }
}

fn run(study: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", study.to_str().unwrap(), "--quiet"])
        .args(extra)
        .output()
        .unwrap()
}

/// A results table without the runs' wall times, which no two runs share.
fn table_without_wall_time(path: &Path) -> polars::prelude::DataFrame {
    let table = autobal::study::results::io::read_parquet(path).unwrap();
    match table.drop("wall_time_s") {
        Ok(runs) => runs,
        Err(_) => table,
    }
}

#[test]
fn a_full_disk_is_named_as_such_and_a_resume_with_room_completes_identically() {
    let tmp = tempfile::tempdir().unwrap();
    let disk_at = tmp.path().join("disk");
    // Room for the chunk of 200 runs (about 70 kB) but not beside it the
    // runs table (about 50 kB) and the summary.
    let Some(disk) = SmallDisk::mount(&disk_at, "150k") else {
        eprintln!("skipped: cannot mount a tmpfs here (not root?)");
        return;
    };
    let text = |results: &Path| {
        crate::bad_input::study(results).replace("samples = 2\n", "samples = 200\n")
    };
    let on_disk = tmp.path().join("full.toml");
    std::fs::write(&on_disk, text(&disk_at.join("r"))).unwrap();
    let out = run(&on_disk, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("could not be written: no space left on device")
            && err.contains(&disk_at.join("r/corpus").display().to_string())
            && !err.contains("not a readable Parquet"),
        "{err}"
    );
    disk.grow("4m");
    let out = run(&on_disk, &["--resume"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let elsewhere = tmp.path().join("fresh.toml");
    std::fs::write(&elsewhere, text(&tmp.path().join("fresh"))).unwrap();
    assert!(run(&elsewhere, &[]).status.success());
    for name in ["runs.parquet", "summary.parquet"] {
        let (a, b) = (
            table_without_wall_time(&disk_at.join("r/corpus").join(name)),
            table_without_wall_time(&tmp.path().join("fresh/corpus").join(name)),
        );
        assert!(a.equals_missing(&b), "{name} differs after the resume");
    }
}
